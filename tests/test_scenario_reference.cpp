// The one rule for the scenario a file names: absolute as it is, else beside
// the file, else from the current directory; neither: the file and field named.
#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

#include "planner/common/format_error.h"
#include "planner/plan/scenario_reference.h"
#include "test_support.h"

using namespace acyclic;
namespace fs = std::filesystem;

namespace {

// Runs the test from `dir` (the rule's last fallback), then back.
class InDirectory {
 public:
  explicit InDirectory(const std::string& dir) : before_(fs::current_path()) { fs::current_path(dir); }
  ~InDirectory() { fs::current_path(before_); }

 private:
  fs::path before_;
};

}  // namespace

TEST(ScenarioReference, EachFallbackInOrder) {
  test::TempDir root;
  fs::create_directories(root.path() + "/plans");
  fs::create_directories(root.path() + "/run");
  const std::string file = root.write("plans/p.json", R"({"scenario": "s.yaml"})");
  InDirectory here(root.path() + "/run");

  // 1. Absolute: as it is, even where nothing exists.
  EXPECT_EQ(resolveScenarioReference(file, "/elsewhere/s.yaml"), "/elsewhere/s.yaml");
  // 3. Only in the current directory: found there.
  root.write("run/s.yaml", "x");
  EXPECT_EQ(resolveScenarioReference(file, "s.yaml"), "s.yaml");
  EXPECT_EQ(scenarioNamedBy(file), "s.yaml");
  // 2. Beside the file too: beside the file wins.
  root.write("plans/s.yaml", "x");
  EXPECT_EQ(fs::path(resolveScenarioReference(file, "s.yaml")), fs::path(root.path()) / "plans/s.yaml");
  EXPECT_EQ(fs::path(scenarioNamedBy(file)), fs::path(root.path()) / "plans/s.yaml");
  // Neither: the file and the field named.
  try {
    resolveScenarioReference(file, "nowhere.yaml");
    FAIL() << "a scenario found nowhere was accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.field(), "scenario");
    EXPECT_NE(std::string(e.what()).find("nowhere.yaml"), std::string::npos) << e.what();
  }
}

TEST(ScenarioReference, AFileWithoutTheFieldIsRefused) {
  test::TempDir dir;
  EXPECT_THROW(scenarioNamedBy(dir.path() + "/missing.json"), FormatError);
  EXPECT_THROW(scenarioNamedBy(dir.write("a.json", "not json")), FormatError);
  try {
    scenarioNamedBy(dir.write("b.json", R"({"format": "acyclic.plan/1"})"));
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "scenario");
  }
  EXPECT_THROW(scenarioNamedBy(dir.write("c.json", R"({"scenario": ""})")), FormatError);
}
