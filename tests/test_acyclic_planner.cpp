// acyclic-planner in file mode: by default each plan's transitions are
// verified with the interpolator's solver before the plan is written (the
// summary says so), the flags and the scenario key switch it, and bad input
// is named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace {
using acyclic::test::binaryPath;
using acyclic::test::runProcess;
using acyclic::test::sourcePath;

acyclic::test::ProcessRun plan(const std::string& scenario, const std::string& out, const std::string& args = "") {
  return runProcess(binaryPath("processes/acyclic-planner") + " -q --in " + scenario + " --out " + out + " " + args);
}
}  // namespace

TEST(AcyclicPlanner, VerifiesThePlansTransitionsByDefaultAndNotWhenToldOtherwise) {
  acyclic::test::TempDir dir;
  const std::string s = sourcePath("models/scenarios/step_forward.yaml");
  const auto on = plan(s, dir.path() + "/on.json");
  ASSERT_EQ(on.status, 0) << on.output;
  EXPECT_NE(on.output.find("transitions verified: 1 plans checked, 0 refused"), std::string::npos) << on.output;
  EXPECT_EQ(on.output.find("by member"), std::string::npos) << on.output;  // no portfolio, no member named
  // The summary says how many of the nodes generated were dropped as duplicates.
  EXPECT_NE(on.output.find(" nodes generated ("), std::string::npos) << on.output;
  EXPECT_NE(on.output.find(" dropped as duplicates of a node), "), std::string::npos) << on.output;
  // The plan it wrote interpolates: the interpolator's own run agrees.
  const auto interp = runProcess(binaryPath("processes/acyclic-interpolator") + " --in " + dir.path() +
                                 "/on.json --out " + dir.path() + "/t.json");
  EXPECT_EQ(interp.status, 0) << interp.output;

  const auto off = plan(s, dir.path() + "/off.json", "--no-verify-transitions");
  ASSERT_EQ(off.status, 0) << off.output;
  EXPECT_EQ(off.output.find("transitions verified"), std::string::npos) << off.output;
  // The scenario's key switches it off too.
  std::string text = acyclic::test::scenarioText("models/scenarios/step_forward.yaml");
  ASSERT_EQ(text.find("\nplanner:"), std::string::npos);  // no planner section of its own
  text += "\nplanner:\n  verify_transitions: false\n";
  const auto keyed = plan(dir.write("s.yaml", text), dir.path() + "/keyed.json");
  ASSERT_EQ(keyed.status, 0) << keyed.output;
  EXPECT_EQ(keyed.output.find("transitions verified"), std::string::npos) << keyed.output;
  // ... unless the command line says otherwise.
  const auto forced = plan(dir.path() + "/s.yaml", dir.path() + "/forced.json", "--verify-transitions");
  ASSERT_EQ(forced.status, 0) << forced.output;
  EXPECT_NE(forced.output.find("transitions verified"), std::string::npos) << forced.output;
  EXPECT_EQ(forced.output.find("verified before expansion"), std::string::npos) << forced.output;
  // Verification on expansion: each expanded stance's transitions checked too, and said.
  const auto expanding = plan(s, dir.path() + "/expanding.json", "--verify-on-expansion");
  ASSERT_EQ(expanding.status, 0) << expanding.output;
  EXPECT_NE(expanding.output.find("verified before expansion"), std::string::npos) << expanding.output;
}

TEST(AcyclicPlanner, ContradictoryFlagsAndABadKeyAreBadInput) {
  acyclic::test::TempDir dir;
  const std::string s = sourcePath("models/scenarios/step_forward.yaml");
  const auto both = plan(s, dir.path() + "/p.json", "--verify-transitions --no-verify-transitions");
  EXPECT_EQ(both.status, 2) << both.output;
  std::string text = acyclic::test::scenarioText("models/scenarios/step_forward.yaml");
  text += "\nplanner:\n  verify_transitions: sometimes\n";
  const auto bad = plan(dir.write("bad.yaml", text), dir.path() + "/p.json");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("verify_transitions"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/p.json"));
  const auto both_expansion = plan(s, dir.path() + "/p.json", "--verify-on-expansion --no-verify-on-expansion");
  EXPECT_EQ(both_expansion.status, 2) << both_expansion.output;
  std::string text2 = acyclic::test::scenarioText("models/scenarios/step_forward.yaml");
  text2 += "\nplanner:\n  verify_on_expansion: 3\n";
  const auto bad2 = plan(dir.write("bad2.yaml", text2), dir.path() + "/p.json");
  EXPECT_EQ(bad2.status, 2) << bad2.output;
  EXPECT_NE(bad2.output.find("verify_on_expansion"), std::string::npos) << bad2.output;
}

// --set KEY=VALUE: a planner key from the command line, over the scenario's;
// a bad one is bad input, said before any search (also in LCM mode, before
// serving).
TEST(AcyclicPlanner, SetGivesAPlannerKeyFromTheCommandLine) {
  acyclic::test::TempDir dir;
  const std::string s = sourcePath("models/scenarios/step_forward.yaml");
  const auto cut = plan(s, dir.path() + "/cut.json", "--no-verify-transitions --set max_nodes=3");
  EXPECT_EQ(cut.status, 1) << cut.output;
  EXPECT_NE(cut.output.find("3 nodes generated without reaching the goal"), std::string::npos) << cut.output;
  const auto bad = plan(s, dir.path() + "/bad.json", "--set posture_distance_engine=bullet");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("--set: field 'planner.posture_distance_engine': expected fcl or convex"),
            std::string::npos)
      << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/bad.json"));
  // The plan file records the settings, in order, for the interpolator
  // (InterpolatorProcess.TakesTheScenariosMarginsUnlessTheCommandLineGivesThem).
  const auto recorded = plan(s, dir.path() + "/set.json", "--no-verify-transitions --set max_nodes=500 --set threads=1");
  ASSERT_EQ(recorded.status, 0) << recorded.output;
  auto json = [](const std::string& path) { return nlohmann::json::parse(std::ifstream(path)); };
  EXPECT_EQ(json(dir.path() + "/set.json").at("planner_settings"),
            nlohmann::json::array({"max_nodes=500", "threads=1"}));
  const auto plain = plan(s, dir.path() + "/plain.json", "--no-verify-transitions");
  ASSERT_EQ(plain.status, 0) << plain.output;
  EXPECT_FALSE(json(dir.path() + "/plain.json").contains("planner_settings"));
  const auto served = runProcess("timeout 30 " + binaryPath("processes/acyclic-planner") +
                                 " --lcm --lcm-url memq:// --set no_such_key=1");
  EXPECT_EQ(served.status, 2) << served.output;
  EXPECT_NE(served.output.find("--set: field 'planner.no_such_key'"), std::string::npos) << served.output;
}

// --keep-refused DIR: made before the search (a path that cannot be a
// directory is bad input, said at once), nothing in it when no plan is
// refused; not with --lcm. What it writes: ContactPlanner.APlanWhoseTransition...
TEST(AcyclicPlanner, KeepRefusedMakesItsDirectoryFirstAndRefusesAPathThatCannotBeOne) {
  acyclic::test::TempDir dir;
  const std::string s = sourcePath("models/scenarios/step_forward.yaml");
  const std::string kept = dir.path() + "/refused/here";
  const auto ok = plan(s, dir.path() + "/p.json", "--keep-refused " + kept);
  ASSERT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(std::filesystem::is_directory(kept));
  EXPECT_TRUE(std::filesystem::is_empty(kept));  // step_forward's first plan is not refused
  EXPECT_EQ(ok.output.find("refused plan"), std::string::npos) << ok.output;

  const std::string file = dir.write("a_file", "not a directory\n");
  const auto bad = plan(s, dir.path() + "/q.json", "--keep-refused " + file + "/sub");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("--keep-refused " + file + "/sub"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/q.json"));  // said before any search

  const auto lcm = runProcess(binaryPath("processes/acyclic-planner") + " --lcm --keep-refused " + kept);
  EXPECT_EQ(lcm.status, 2) << lcm.output;
}

// A scenario with a portfolio: the plan written is its winner's, verified
// (each member with its own verifier), the same as that member's alone, and
// the summary names every member's outcome.
TEST(AcyclicPlanner, APortfolioWritesItsWinnersPlanAndSaysEachMembersOutcome) {
  acyclic::test::TempDir dir;
  const std::string text = acyclic::test::scenarioText("models/scenarios/step_forward.yaml");
  const std::string both = dir.write(
      "both.yaml", text + "\nplanner:\n  portfolio:\n    - {name: fine}\n"
                          "    - {name: coarse, duplicate_distance: 0.15, alternative_step: 0.05}\n");
  const auto r = plan(both, dir.path() + "/both.json");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("portfolio member 1 \"fine\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("portfolio member 2 \"coarse\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(its plan)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("nodes generated by the 2 members that ran"), std::string::npos) << r.output;
  // The winner's plan, as that member plans alone.
  const bool fine_won = r.output.find("\"fine\" (its plan)") != std::string::npos;
  // Each member's count of posture calls, which they are compared by: the
  // winner's the fewest, unless the other was outrun.
  auto callsOf = [&](int member) {  // 1: fine, 2: coarse
    const std::size_t line = r.output.find("portfolio member " + std::to_string(member));
    const std::size_t at = r.output.find(" nodes generated, ", line);
    return at == std::string::npos ? -1L : std::stol(r.output.substr(at + 18));
  };
  const long winner_calls = callsOf(fine_won ? 1 : 2), other_calls = callsOf(fine_won ? 2 : 1);
  ASSERT_GT(winner_calls, 0) << r.output;
  EXPECT_GE(other_calls, winner_calls) << r.output;
  // The verification's summary is the winner's, and says so.
  EXPECT_NE(r.output.find(std::string("s by member \"") + (fine_won ? "fine" : "coarse") + "\" (the winner)\n"),
            std::string::npos)
      << r.output;
  const std::string alone =
      dir.write("alone.yaml", text + (fine_won ? "\nplanner: {}\n"
                                               : "\nplanner: {duplicate_distance: 0.15, alternative_step: 0.05}\n"));
  const auto a = plan(alone, dir.path() + "/alone.json");
  ASSERT_EQ(a.status, 0) << a.output;
  auto stances = [](const std::string& path) {
    const std::string s = acyclic::test::readFile(path);
    const std::size_t from = s.find("\"stances\""), to = s.find("\"stats\"");  // the stats hold the time
    return from != std::string::npos && to > from ? s.substr(from, to - from) : std::string();
  };
  EXPECT_FALSE(stances(dir.path() + "/both.json").empty());
  EXPECT_EQ(stances(dir.path() + "/both.json"), stances(dir.path() + "/alone.json"));
  // --member: one member alone, as its own scenario plans.
  const std::string winner = fine_won ? "fine" : "coarse";
  const auto m = plan(both, dir.path() + "/member.json", "--member " + winner);
  ASSERT_EQ(m.status, 0) << m.output;
  EXPECT_EQ(m.output.find("portfolio member"), std::string::npos) << m.output;
  EXPECT_EQ(stances(dir.path() + "/member.json"), stances(dir.path() + "/alone.json"));
  const auto other = plan(both, dir.path() + "/other.json", std::string("--member ") + (fine_won ? "coarse" : "fine"));
  ASSERT_EQ(other.status, 0) << other.output;
  EXPECT_NE(stances(dir.path() + "/other.json"), stances(dir.path() + "/alone.json"));
  const auto none = plan(both, dir.path() + "/none.json", "--member nope");
  EXPECT_EQ(none.status, 2) << none.output;
  EXPECT_NE(none.output.find("its members: fine, coarse"), std::string::npos) << none.output;
  // In sequence: the first member solves on its own, the second never runs
  // (and is not listed); the plan is the first member's alone.
  const auto seq = plan(both, dir.path() + "/seq.json", "--set portfolio_mode=sequence");
  ASSERT_EQ(seq.status, 0) << seq.output;
  EXPECT_NE(seq.output.find("portfolio member 1 \"fine\" (its plan)"), std::string::npos) << seq.output;
  EXPECT_EQ(seq.output.find("portfolio member 2"), std::string::npos) << seq.output;
  EXPECT_NE(seq.output.find("by the 1 member that ran"), std::string::npos) << seq.output;
  const auto fine = plan(both, dir.path() + "/fine.json", "--member fine");
  ASSERT_EQ(fine.status, 0) << fine.output;
  EXPECT_EQ(stances(dir.path() + "/seq.json"), stances(dir.path() + "/fine.json"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/none.json"));
}

// --trajectory: the plan interpolated in the same run, from the transitions
// its verification solved (none solved again), gives the trajectory
// acyclic-interpolator makes from the plan file: the same samples and
// phases, bit for bit (only the stats, which count this run's work, differ).
TEST(AcyclicPlanner, TrajectoryInterpolatesThePlanWithTheTransitionsItsVerificationSolved) {
  acyclic::test::TempDir dir;
  const std::string s = sourcePath("models/scenarios/step_forward.yaml");
  const auto run = plan(s, dir.path() + "/p.json", "--trajectory " + dir.path() + "/t1.json");
  ASSERT_EQ(run.status, 0) << run.output;
  const std::size_t said = run.output.find("of them verified by the search, not solved again");
  ASSERT_NE(said, std::string::npos) << run.output;
  // "N transitions (N of them ...": every one reused, and no posture call made.
  const std::string line = run.output.substr(run.output.rfind("trajectory: ", said));
  int stances = 0, filtered = 0, transitions = 0, reused = 0;
  ASSERT_EQ(std::sscanf(line.c_str(), "trajectory: %d stances (%d filtered), %d transitions (%d of them", &stances,
                        &filtered, &transitions, &reused), 4)
      << line;
  EXPECT_GT(transitions, 0);
  EXPECT_EQ(reused, transitions) << line;
  EXPECT_NE(line.find(" 0 posture calls"), std::string::npos) << line;

  const auto interp = runProcess(binaryPath("processes/acyclic-interpolator") + " -q --in " + dir.path() +
                                 "/p.json --out " + dir.path() + "/t2.json");
  ASSERT_EQ(interp.status, 0) << interp.output;
  auto read = [](const std::string& path) {
    std::ifstream in(path);
    nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_TRUE(j.contains("stats")) << path;
    j.erase("stats");  // this run's work: differs by design
    return j;
  };
  const nlohmann::json a = read(dir.path() + "/t1.json"), b = read(dir.path() + "/t2.json");
  ASSERT_FALSE(a.at("samples").empty());
  EXPECT_TRUE(a == b) << "the planner's trajectory differs from acyclic-interpolator's on the same plan";

  // Without verification nothing is remembered: every transition solved here.
  const auto unverified =
      plan(s, dir.path() + "/p3.json", "--no-verify-transitions --trajectory " + dir.path() + "/t3.json");
  ASSERT_EQ(unverified.status, 0) << unverified.output;
  EXPECT_NE(unverified.output.find("(0 of them verified by the search"), std::string::npos) << unverified.output;
  nlohmann::json c = read(dir.path() + "/t3.json"), b_other_plan = b;
  c.erase("plan");  // the plan file it names: p3.json
  b_other_plan.erase("plan");
  EXPECT_TRUE(c == b_other_plan);

  // Not over the plan file: bad input, said before any search.
  const auto over = plan(s, dir.path() + "/p4.json", "--trajectory " + dir.path() + "/./p4.json");
  EXPECT_EQ(over.status, 2) << over.output;
  EXPECT_NE(over.output.find("is the plan file"), std::string::npos) << over.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/p4.json"));

  // File mode's: with --lcm it is bad input.
  const auto lcm = runProcess(binaryPath("processes/acyclic-planner") + " --lcm --trajectory " + dir.path() + "/t.json");
  EXPECT_EQ(lcm.status, 2) << lcm.output;
}
