// Every process that writes a file named on its command line refuses a path
// in a directory that does not exist when it reads the command line (bad
// input, exit 2, the option and the directory named), before any work: a
// search of minutes is not run to be lost at the write (acyclic-planner did
// that, and acyclic-interpolator, acyclic-simulate, acyclic-hrp2-export).
#include <gtest/gtest.h>

#include <filesystem>

#include "test_support.h"

namespace {

struct Case {
  const char* process;
  std::string arguments;  // with real inputs: the same command with a good path does the work
  const char* option;     // the option whose directory is missing
  const char* work;       // a line the process prints only once it has worked
};

}  // namespace

TEST(OutputPaths, AFileInAMissingDirectoryIsBadInputBeforeAnyWork) {
  using acyclic::test::sourcePath;
  acyclic::test::TempDir dir;
  const std::string missing = dir.path() + "/missing";
  const std::string step = sourcePath("models/scenarios/step_forward.yaml");
  const std::string chair = sourcePath("models/scenarios/chair_table.yaml");
  const std::string plan = sourcePath("tests/data/chair.plan.json");
  // A trajectory to simulate and export, made here (and its making shows the good path works).
  const std::string trajectory = dir.path() + "/chair.traj.json";
  const auto made = acyclic::test::runProcess(acyclic::test::binaryPath("processes/acyclic-interpolator") + " --in " +
                                              plan + " --scenario " + chair + " --out " + trajectory + " -q");
  ASSERT_EQ(made.status, 0) << made.output;
  const Case cases[] = {
      {"acyclic-planner", "--in " + step + " --out " + missing + "/p.json", "--out", "solved in"},
      {"acyclic-interpolator", "--in " + plan + " --scenario " + chair + " --out " + missing + "/t.json", "--out",
       "samples ("},
      {"acyclic-guide", "--in " + step + " --out " + missing + "/g.json", "--out", "key postures"},
      {"acyclic-posture", step + " --out " + missing + "/s.json", "--out", "success"},
      {"acyclic-simulate", chair + " --trajectory " + trajectory + " --report " + missing + "/r.json", "--report",
       "verdict"},
      {"acyclic-simulate", chair + " --trajectory " + trajectory + " --trace " + missing + "/t.csv", "--trace",
       "verdict"},
      {"acyclic-hrp2-export", "--in " + trajectory + " --out " + missing + "/chair", "--out", "rows at"},
  };
  for (const Case& c : cases) {
    const auto r = acyclic::test::runProcess(acyclic::test::binaryPath(std::string("processes/") + c.process) + " " +
                                             c.arguments);
    EXPECT_EQ(r.status, 2) << c.process << ": " << r.output;
    EXPECT_NE(r.output.find(std::string(c.option) + ": directory " + missing + " does not exist"), std::string::npos)
        << c.process << ": " << r.output;
    EXPECT_EQ(r.output.find(c.work), std::string::npos) << c.process << " worked first: " << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(missing));
}
