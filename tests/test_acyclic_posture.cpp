// acyclic-posture, the scenario author's probe: one posture-generator call on
// a start stance, chained through --out/--from; its witnesses pass the
// independent check (the exit status says so) and it names bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "planner/plan/plan.h"
#include "planner/scene/scenario.h"
#include "test_support.h"

namespace {
acyclic::test::ProcessRun probe(const std::string& args) {
  return acyclic::test::runProcess(acyclic::test::binaryPath("processes/acyclic-posture") + " " +
                                   acyclic::test::sourcePath("models/scenarios/chair_table.yaml") + " " + args);
}
}  // namespace

TEST(AcyclicPosture, AWristOnTheTableAddedThenReleasedChainThroughFiles) {
  acyclic::test::TempDir dir;
  const auto a = probe("--add l_wrist@table_top --out " + dir.path() + "/a.json");
  ASSERT_EQ(a.status, 0) << a.output;
  EXPECT_NE(a.output.find("success"), std::string::npos);
  EXPECT_NE(a.output.find("added l_wrist@table_top"), std::string::npos);
  EXPECT_NE(a.output.find("[ ok ] equilibrium"), std::string::npos) << a.output;
  // From that stance (the wrist now supporting, part of the stance), release it again.
  const auto b = probe("--from " + dir.path() + "/a.json --remove l_wrist");
  EXPECT_EQ(b.status, 0) << b.output;
  // From the start, one thigh released: the other and the feet carry the robot.
  const auto c = probe("--remove r_thigh");
  EXPECT_EQ(c.status, 0) << c.output;
}

TEST(AcyclicPosture, BothThighsOffWithFeetAloneIsFoundAndValid) {
  // Seated with the feet drawn back under the knees, the robot can lean its
  // centre of mass over its feet: both thighs touch the seat without
  // supporting (the first step of getting up), and the check accepts it.
  const auto r = probe("--remove r_thigh --remove l_thigh --iterations 100");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("[ ok ] equilibrium   2 supporting contacts"), std::string::npos) << r.output;
}

TEST(AcyclicPosture, AKneeRestsOnTheFloorWhereALevelShankCannot) {
  // Standing on open floor: the weight to the left foot, then the right knee
  // on the floor. HRP-2's knee pad is the rounded front of the knee, 20
  // degrees up from straight ahead (models/hrp2/hrp2.yaml): the shank rises
  // from the floor and the foot clears it. With a pad straight ahead of the
  // shank (the model of tests/data/hrp2_midthigh.yaml), the shank would lie
  // level and the ankle's range leaves the foot in the floor: no posture.
  acyclic::test::TempDir dir;
  const std::string bin = acyclic::test::binaryPath("processes/acyclic-posture") + " ";
  const std::string standing = acyclic::test::sourcePath("models/scenarios/step_forward.yaml");
  const auto shift = acyclic::test::runProcess(bin + standing + " --remove r_sole --out " + dir.path() + "/a.json");
  ASSERT_EQ(shift.status, 0) << shift.output;
  const auto kneel = acyclic::test::runProcess(bin + standing + " --from " + dir.path() + "/a.json --add r_knee@floor");
  EXPECT_EQ(kneel.status, 0) << kneel.output;
  EXPECT_NE(kneel.output.find("[ ok ] collisions"), std::string::npos) << kneel.output;
  EXPECT_NE(kneel.output.find("[ ok ] equilibrium"), std::string::npos) << kneel.output;
  // The same two calls with the level pad.
  const std::string level = dir.path() + "/level.yaml";
  {
    std::ofstream f(level);
    f << "format: acyclic.scenario/1\nname: level_knee\n"
      << "robot: " << acyclic::test::sourcePath("tests/data/hrp2_midthigh.yaml") << "\n"
      << "scene: " << acyclic::test::sourcePath("models/scenes/open_floor.yaml") << "\n"
      << "start:\n  configuration: {posture: half_sitting}\n  contacts:\n"
      << "    - {spot: r_sole, surface: floor}\n    - {spot: l_sole, surface: floor}\n"
      << "allowed_spots: [r_sole, l_sole, r_knee]\nallowed_surfaces: [floor]\n"
      << "goal: {link: WAIST, axis: x, min: 0.25}\n";
  }
  const auto level_shift = acyclic::test::runProcess(bin + level + " --remove r_sole --out " + dir.path() + "/b.json");
  ASSERT_EQ(level_shift.status, 0) << level_shift.output;
  const auto level_kneel =
      acyclic::test::runProcess(bin + level + " --from " + dir.path() + "/b.json --add r_knee@floor --iterations 1000");
  EXPECT_EQ(level_kneel.status, 1) << level_kneel.output;
}

TEST(AcyclicPosture, ThePapersChairReleasesOneThighOnTheFeetButNotBoth) {
  // models/scenarios/chair_paper.yaml: the table over the thighs keeps the
  // trunk from bringing the centre of mass over the feet. One thigh leaves
  // the seat (the other and the feet carry the robot); both do not, even
  // with ten times the iterations the planner gives a posture call there.
  const std::string bin = acyclic::test::binaryPath("processes/acyclic-posture") + " " +
                          acyclic::test::sourcePath("models/scenarios/chair_paper.yaml");
  const auto one = acyclic::test::runProcess(bin + " --remove r_thigh");
  EXPECT_EQ(one.status, 0) << one.output;
  const auto both = acyclic::test::runProcess(bin + " --remove r_thigh --remove l_thigh --iterations 1000");
  EXPECT_EQ(both.status, 1) << both.output;
}

namespace {
// The status line's outcome and iterations (its milliseconds vary) and the witness line.
std::string outcome(const std::string& output) {
  const auto ms = output.find(" iterations");
  const auto witness = output.find("  witness:");
  if (ms == std::string::npos || witness == std::string::npos) return "no outcome in: " + output;
  return output.substr(0, ms) + output.substr(witness, output.find('\n', witness) - witness);
}
}  // namespace

TEST(AcyclicPosture, StanceReposesAPlansStanceAsThePlanHoldsIt) {
  // A two-stance plan: the start re-posed (all supporting), then the same
  // posture with the right thigh touching but not supporting. --stance 1
  // must be the very call `--from` the first with `--remove r_thigh` makes,
  // and --stance 0 the call on the first stance as it is.
  acyclic::test::TempDir dir;
  const auto a = probe("--out " + dir.path() + "/a.json");
  ASSERT_EQ(a.status, 0) << a.output;
  const acyclic::Scenario sc = acyclic::Scenario::load(acyclic::test::sourcePath("models/scenarios/chair_table.yaml"));
  acyclic::Plan p = acyclic::readPlan(dir.path() + "/a.json", sc);
  acyclic::PlanStance released = p.stances.front();
  int flagged = 0;
  for (auto& c : released.contacts)
    if (sc.robot->spots()[c.spec.spot].name == "r_thigh") c.spec.supporting = false, ++flagged;
  ASSERT_EQ(flagged, 1);
  p.stances.push_back(released);
  acyclic::writePlan(p, sc, dir.path() + "/two.json");

  const auto removed = probe("--from " + dir.path() + "/a.json --remove r_thigh");
  const auto second = probe("--from " + dir.path() + "/two.json --stance 1");
  ASSERT_EQ(removed.status, 0) << removed.output;
  EXPECT_EQ(second.status, 0) << second.output;
  EXPECT_EQ(outcome(second.output), outcome(removed.output));
  const auto first = probe("--from " + dir.path() + "/two.json --stance 0");
  const auto same = probe("--from " + dir.path() + "/a.json");
  EXPECT_EQ(first.status, 0) << first.output;
  EXPECT_EQ(outcome(first.output), outcome(same.output));
  // Without --stance, the last stance with every contact supporting (the
  // planner's node once the change settles): the released thigh supports again.
  const auto last = probe("--from " + dir.path() + "/two.json");
  EXPECT_EQ(outcome(last.output), outcome(same.output));
  EXPECT_NE(outcome(last.output), outcome(removed.output));

  auto bad = probe("--from " + dir.path() + "/two.json --stance 2");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("--stance"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("0 to 1"), std::string::npos) << bad.output;
  bad = probe("--stance 0");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("--from"), std::string::npos) << bad.output;
}

TEST(AcyclicPosture, ASoleOnAPadFacingTheOtherWayIsWrittenAtItsOwnAngle) {
  // Standing on the left foot, the right sole added on a pad whose frame
  // faces against the robot: the solver's angle is half a turn from the
  // sole's (the contact rows fix it modulo pi), so the generator solves it
  // again with the footprint turned (it says so), and the contact written
  // takes the sole's own angle, about pi in the pad's frame, as the
  // planner's nodes do: its frame is the spot's.
  acyclic::test::TempDir dir;
  const std::string scenario = acyclic::test::padScenario(dir, 180, false);  // the start on the left foot alone
  const auto r = acyclic::test::runProcess(acyclic::test::binaryPath("processes/acyclic-posture") + " " + scenario +
                                           " --add r_sole@pad --out " + dir.path() + "/p.json");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("solved again with the added spot's footprint turned half a turn"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("[ ok ] contacts"), std::string::npos) << r.output;
  const acyclic::Scenario sc = acyclic::Scenario::load(scenario);
  const acyclic::Plan plan = acyclic::readPlan(dir.path() + "/p.json", sc);
  bool found = false;
  for (const auto& c : plan.stances.back().contacts)
    if (sc.robot->spots()[c.spec.spot].name == "r_sole") {
      found = true;
      EXPECT_NEAR(std::abs(c.spec.placement.theta), M_PI, 0.2);
    }
  EXPECT_TRUE(found);
}

TEST(AcyclicPosture, BadInputIsNamedAndExitsTwo) {
  auto r = probe("--remove r_hand");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("r_hand"), std::string::npos) << r.output;
  r = probe("--add l_wrist@ceiling");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("ceiling"), std::string::npos) << r.output;
  // A bad option or value on the command line is bad input too, named.
  r = probe("--distance-engine bullet");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--distance-engine"), std::string::npos) << r.output;
  r = probe("--print-level 13");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--print-level"), std::string::npos) << r.output;
  r = probe("--no-such-option");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--no-such-option"), std::string::npos) << r.output;
}

TEST(AcyclicPosture, TheSameStanceWithEitherDistanceEngine) {
  // The planner's distances (FCL) and the generator's default (its own GJK)
  // find the same stance valid.
  for (const char* engine : {"fcl", "convex"}) {
    const auto r = probe(std::string("--remove r_thigh --distance-engine ") + engine);
    EXPECT_EQ(r.status, 0) << engine << "\n" << r.output;
  }
}
