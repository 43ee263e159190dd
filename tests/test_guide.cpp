// The rough-trajectory author (OMPL): a guide for each scenario that starts at
// the start posture and ends in the goal region; deterministic; its file
// format; a clear failure where no path exists.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "planner/check/validity.h"
#include "planner/common/format_error.h"
#include "planner/guide/guide_author.h"
#include "planner/search/contact_planner.h"
#include "planner/search/guide_potential.h"
#include "test_support.h"

using namespace acyclic;

namespace {

// The guide of sc, which must exist and start at the start posture, exactly.
void expectGuideFromTheStart(const Scenario& sc, GuideResult& r) {
  r = authorGuide(sc, GuideOptions());
  ASSERT_TRUE(r.success()) << sc.name << ": " << r.reason;
  ASSERT_GE(r.guide.key_postures.size(), 2u);
  EXPECT_EQ(r.guide.key_postures.front().joints, sc.start.joints);
  EXPECT_EQ(r.guide.key_postures.front().base_position, sc.start.base_position);
}

void expectGuideFor(const std::string& rel) {
  const Scenario sc = Scenario::load(test::sourcePath(rel));
  GuideResult r;
  expectGuideFromTheStart(sc, r);
  if (::testing::Test::HasFatalFailure()) return;
  const auto& keys = r.guide.key_postures;
  // Ends standing in the goal region.
  Kinematics kin(sc.robot);
  kin.setConfiguration(keys.back());
  EXPECT_TRUE(sc.goal.linkWithinBounds(kin)) << rel;
  EXPECT_NEAR(keys.back().base_position.z(), sc.robot->posture("half_sitting").base_position.z(), 0.05);
  // A usable guide: the guide potential accepts it (one-to-one base path).
  EXPECT_NO_THROW(GuidePotential(keys, 1.0, 0.05));
  EXPECT_LT(r.guide.seconds, 10.0);
}

}  // namespace

TEST(GuideAuthor, StepForwardScenario) { expectGuideFor("models/scenarios/step_forward.yaml"); }

TEST(GuideAuthor, ChairScenario) { expectGuideFor("models/scenarios/chair_table.yaml"); }

// On the wet ramp no posture stands on the feet alone: the guide ends on the
// start stance carried up the ramp (feet on the ramp, palms on the bars), a
// posture the independent check accepts with those contacts, in the goal.
TEST(GuideAuthor, WetRampEndsOnTheStartStanceCarriedIntoTheGoal) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/wet_ramp.yaml"));
  GuideResult r;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(sc, r));
  const auto& keys = r.guide.key_postures;
  Kinematics kin(sc.robot);
  kin.setConfiguration(keys.back());
  std::vector<ContactSpec> carried = sc.start_stance;
  for (auto& c : carried) {
    const Surface& surf = sc.scene->surfaces()[c.surface];
    c.placement = projectOnSurface(surf, kin.spotPose(c.spot));
    const Eigen::Vector3d in_surface = surf.frame.inverse() * kin.spotPose(c.spot).translation();
    EXPECT_LT(std::abs(in_surface.z()), 1e-3) << sc.describe(c);  // on its surface
  }
  EXPECT_TRUE(sc.goal.satisfied(kin, carried));
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checker.checkPosture(keys.back(), carried).valid());
  EXPECT_NO_THROW(GuidePotential(keys, 1.0, 0.05));
}

TEST(GuideAuthor, SameScenarioAndSeedSameGuide) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  GuideOptions o;
  const GuideResult a = authorGuide(sc, o), b = authorGuide(sc, o);
  ASSERT_TRUE(a.success() && b.success());
  Guide ga = a.guide, gb = b.guide;
  ga.seconds = gb.seconds = 0;
  EXPECT_EQ(guideToJson(ga, sc), guideToJson(gb, sc));
}

TEST(GuideAuthor, GuidePlansTheSmallScenarioToAValidPlan) {
  const Scenario base = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  const GuideResult g = authorGuide(base, GuideOptions());
  ASSERT_TRUE(g.success()) << g.reason;
  Scenario sc = base;
  sc.key_postures = g.guide.key_postures;  // the OMPL guide only
  const PlanningResult r = ContactPlanner(sc).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_GT(r.plan.stances.size(), 2u);
}

TEST(GuideAuthor, AWalledInRobotGetsAClearFailureWithinItsBudget) {
  // Walls all around the start of step_forward, the goal 0.8 m ahead beyond
  // the front wall: no way to the goal.
  test::TempDir dir;
  std::string scene = test::readFile(test::sourcePath("models/scenes/open_floor.yaml"));
  const auto at = scene.find("obstacles:");
  ASSERT_NE(at, std::string::npos);
  scene.insert(scene.find('\n', at) + 1,
               "  - {name: wall_front, shape: box, size: [0.05, 1.2, 1.8], position: [0.45, 0, 0.9]}\n"
               "  - {name: wall_back, shape: box, size: [0.05, 1.2, 1.8], position: [-0.45, 0, 0.9]}\n"
               "  - {name: wall_left, shape: box, size: [0.95, 0.05, 1.8], position: [0, 0.6, 0.9]}\n"
               "  - {name: wall_right, shape: box, size: [0.95, 0.05, 1.8], position: [0, -0.6, 0.9]}\n");
  dir.write("walled.yaml", scene);
  std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const auto s = text.find("scene: ");
  text.replace(s, text.find('\n', s) - s, "scene: " + dir.path() + "/walled.yaml");
  text.replace(text.find("min: 0.25"), 9, "min: 0.80");
  const Scenario sc = Scenario::load(dir.write("walled_scenario.yaml", text));
  GuideOptions o;
  o.max_seconds = 2;
  const auto t0 = std::chrono::steady_clock::now();
  const GuideResult r = authorGuide(sc, o);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(r.success());
  EXPECT_EQ(r.status, GuideResult::Status::NoPath) << toString(r.status) << ": " << r.reason;
  EXPECT_FALSE(r.reason.empty());
  EXPECT_LT(took, 2 + 5.0);  // the search budget plus the goal posture's attempts
}

TEST(GuideFile, RoundTripAndNamedErrors) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  Guide g;
  g.source = "hand";
  g.key_postures = sc.key_postures;
  test::TempDir dir;
  writeGuide(g, sc, dir.path() + "/g.json");
  const Guide back = readGuide(dir.path() + "/g.json", sc);
  ASSERT_EQ(back.key_postures.size(), g.key_postures.size());
  for (std::size_t i = 0; i < g.key_postures.size(); ++i) {
    EXPECT_EQ(back.key_postures[i].joints, g.key_postures[i].joints);
    EXPECT_EQ(back.key_postures[i].base_position, g.key_postures[i].base_position);
  }
  std::string text = guideToJson(g, sc);
  text.replace(text.find("acyclic.guide/1"), 15, "acyclic.guide/9");
  try {
    guideFromJson(text, "g.json", sc);
    FAIL() << "accepted another format";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "format");
  }
}
