// The rough-trajectory author (OMPL): a guide for each scenario that starts at
// the start posture and ends in the goal region; deterministic; its file
// format; a clear failure where no path exists.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <set>

#include "planner/check/plan_check.h"
#include "planner/check/validity.h"
#include "planner/common/format_error.h"
#include "planner/guide/guide_author.h"
#include "planner/guide/guide_postures.h"
#include "planner/search/contact_planner.h"
#include "planner/search/guide_potential.h"
#include "planner/search/planner_parameters.h"
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

// Each contact placed where kin holds its spot, which must lie on its
// surface (within 1 mm).
void placeOnSurfaces(const Scenario& sc, const Kinematics& kin, std::vector<ContactSpec>& contacts) {
  for (auto& c : contacts) {
    const Surface& surf = sc.scene->surfaces()[c.surface];
    c.placement = projectOnSurface(surf, kin.spotPose(c.spot));
    EXPECT_LT(std::abs((surf.frame.inverse() * kin.spotPose(c.spot).translation()).z()), 1e-3) << sc.describe(c);
  }
}

// How many contacts of the plan's last stance support on the named surface.
int supportingOnAtTheEnd(const Plan& plan, const Scenario& sc, const std::string& surface) {
  int n = 0;
  for (const auto& c : plan.stances.back().contacts)
    n += c.spec.supporting && sc.scene->surfaces()[c.spec.surface].name == surface;
  return n;
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
  // Its time is bench_guide's to measure, not a test's.
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
  placeOnSurfaces(sc, kin, carried);
  EXPECT_TRUE(sc.goal.satisfied(kin, carried));
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checker.checkPosture(keys.back(), carried).valid());
  EXPECT_NO_THROW(GuidePotential(keys, 1.0, 0.05));
}

// Sitting down (a goal on the waist's height, supported by both thighs): the
// guide ends seated, thighs on the seat and feet on the floor, a stance the
// independent check accepts with every contact supporting and also with the
// feet alone supporting (the robot can lower itself onto the seat from its
// feet); and the planner sits the robot down with that guide alone.
TEST(GuideAuthor, SitDownEndsSeatedOnTheThighsOverTheFeetAndIsPlannedWithIt) {
  const Scenario base = Scenario::load(test::sourcePath("models/scenarios/sit_down.yaml"));
  GuideResult r;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(base, r));
  EXPECT_FALSE(r.approach) << "in front of the seat already: the straight blend sits down";
  const Configuration& end = r.guide.key_postures.back();
  Kinematics kin(base.robot);
  kin.setConfiguration(end);
  std::vector<ContactSpec> seated = base.start_stance;
  for (const char* thigh : {"r_thigh", "l_thigh"}) {
    ContactSpec c;
    c.spot = base.robot->spotIndex(thigh);
    c.surface = base.scene->surfaceIndex("chair_seat");
    seated.push_back(c);
  }
  placeOnSurfaces(base, kin, seated);
  EXPECT_TRUE(base.goal.satisfied(kin, seated));
  ValidityChecker checker(base.robot, base.scene);
  EXPECT_TRUE(checker.checkPosture(end, seated).valid());
  for (std::size_t k = base.start_stance.size(); k < seated.size(); ++k) seated[k].supporting = false;  // the thighs
  EXPECT_TRUE(checker.checkPosture(end, seated).valid());

  Scenario sc = base;
  sc.key_postures = r.guide.key_postures;  // the OMPL guide only
  PlannerParameters p;
  p.max_nodes = 300;    // solved in 81: a node budget, not the machine's speed, bounds a failing run
  p.max_seconds = 300;
  const PlanningResult plan = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(plan.solved()) << plan.reason;
  EXPECT_TRUE(checkPlan(plan.plan, sc, checker).valid());
}

// The same with the guide's seated posture leaning 2.3 degrees less and 2.2
// more (its waist pitched 0 and 4.5 degrees forward): the planner must not
// hang on the guide's exact lean. Both failed within 100 s while the failure
// memory carried a thigh's failure past a move of that leg's own foot.
TEST(GuideAuthor, SitDownIsPlannedWithTheGuidesSeatedPostureLeaningLessOrMore) {
  Scenario sc = Scenario::load(test::sourcePath("models/scenarios/sit_down.yaml"));
  const GuideResult g = authorGuide(sc, GuideOptions());
  ASSERT_TRUE(g.success()) << g.reason;
  for (double pitch_deg : {0.0, 4.5}) {
    sc.key_postures = g.guide.key_postures;
    sc.key_postures.back().base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitY()));
    PlannerParameters p;
    p.max_nodes = 300;  // solved in 133 and 72
    p.max_seconds = 300;
    const PlanningResult r = ContactPlanner(sc, p).plan();
    EXPECT_TRUE(r.solved()) << "pitch " << pitch_deg << " deg: " << r.reason;
  }
}

// A height goal on supports the start already has (a crouch on the feet):
// the start stance lowered there, nothing to add.
TEST(GuideAuthor, ACrouchOnTheFeetEndsLoweredOnTheStartStance) {
  std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const auto at = text.find("goal:");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, text.find('\n', at) - at, "goal: {link: WAIST, axis: z, max: 0.55, supported_by: [r_sole, l_sole]}");
  test::TempDir dir;
  const Scenario sc = Scenario::load(dir.write("crouch.yaml", text));
  GuideResult r;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(sc, r));
  Kinematics kin(sc.robot);
  kin.setConfiguration(r.guide.key_postures.back());
  std::vector<ContactSpec> feet = sc.start_stance;
  placeOnSurfaces(sc, kin, feet);
  EXPECT_TRUE(sc.goal.satisfied(kin, feet));
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checker.checkPosture(r.guide.key_postures.back(), feet).valid());
}

TEST(GuideAuthor, AGoalBeyondAStepsEdgeEndsStandingOnTheStep) {
  // models/scenes/step_up.yaml: a platform 0.15 m high, its edge 0.35 m
  // ahead; the goal is the waist 0.75 m ahead, over the platform. Standing on
  // the floor there puts the feet inside the platform: the guide ends
  // standing on its top, both feet on it, a stance the check accepts.
  test::TempDir dir;
  const std::string text = "format: acyclic.scenario/1\nname: step_up\nrobot: " +
                           test::sourcePath("models/hrp2/hrp2.yaml") + "\nscene: " +
                           test::sourcePath("models/scenes/step_up.yaml") +
                           "\nstart:\n  configuration: {posture: half_sitting}\n  contacts:\n"
                           "    - {spot: r_sole, surface: floor}\n    - {spot: l_sole, surface: floor}\n"
                           "allowed_spots: [r_sole, l_sole, r_palm]\nallowed_surfaces: [floor, platform_top, wall_face]\n"
                           "goal: {link: WAIST, axis: x, min: 0.75}\n";
  const Scenario sc = Scenario::load(dir.write("step_up.yaml", text));
  GuideResult r;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(sc, r));
  const Configuration& end = r.guide.key_postures.back();
  Kinematics kin(sc.robot);
  kin.setConfiguration(end);
  EXPECT_TRUE(sc.goal.linkWithinBounds(kin));
  std::vector<ContactSpec> feet(2);
  feet[0].spot = sc.robot->spotIndex("r_sole");
  feet[1].spot = sc.robot->spotIndex("l_sole");
  feet[0].surface = feet[1].surface = sc.scene->surfaceIndex("platform_top");
  placeOnSurfaces(sc, kin, feet);
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checker.checkPosture(end, feet).valid());
  EXPECT_NEAR(end.base_position.z(), sc.robot->posture("half_sitting").base_position.z() + 0.15, 0.05);
}

// The guide's contacts (contactsMadeBy: its stable path, its stances) leave
// out a forbidden pair: the right sole on the floor is no contact of it.
TEST(GuidePostures, AForbiddenPairIsNoContactOfTheGuide) {
  test::TempDir dir;
  const std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const Scenario plain = Scenario::load(dir.write("plain.yaml", text));
  const Scenario forbidding =
      Scenario::load(dir.write("forbid.yaml", text + "forbidden_contacts:\n  - {spot: r_sole, surface: floor}\n"));
  Kinematics kin(plain.robot);
  const int r_sole = plain.robot->spotIndex("r_sole"), l_sole = plain.robot->spotIndex("l_sole");
  auto spots = [&](const Scenario& sc) {
    std::set<int> out;
    for (const auto& c : contactsMadeBy(sc, kin, sc.start)) out.insert(c.spot);
    return out;
  };
  EXPECT_EQ(spots(plain), (std::set<int>{r_sole, l_sole}));
  EXPECT_EQ(spots(forbidding), (std::set<int>{l_sole}));
}

TEST(GuideAuthor, AHeightGoalWithoutSupportsIsRefusedWithTheReason) {
  std::string text = test::scenarioText("models/scenarios/sit_down.yaml");
  const std::string supports = ", supported_by: [r_thigh, l_thigh]";
  ASSERT_NE(text.find(supports), std::string::npos);
  text.erase(text.find(supports), supports.size());
  test::TempDir dir;
  const Scenario sc = Scenario::load(dir.write("s.yaml", text));
  const GuideResult r = authorGuide(sc, GuideOptions());
  EXPECT_EQ(r.status, GuideResult::Status::NoGoalPosture) << r.reason;
  EXPECT_NE(r.reason.find("supported_by"), std::string::npos) << r.reason;
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

// GuideOptions::path_tries: one RRTConnect try leaves chair_paper's guide to
// one random tree's luck. Seed 2 finds no path within its 50,000 state checks
// (the fallback bound of a leg that a crouch may follow; path_retries 0, the
// next test lifts that); seed 3's path first
// goes right, behind the chair and round it (x -0.43 m), where the goal is on
// the left. The shortest of four tries finds a path for both and goes left
// between the chair and the table each time, the same guide again for the
// same seed (the tries are bounded by state checks, not time).
TEST(GuideAuthor, TheShortestOfSeveralTriesIsLessOneTreesLuck) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_paper.yaml"));
  GuideOptions one;
  one.max_seconds = 60;  // the check bounds decide, not a loaded machine
  one.path_retries = 0;
  GuideOptions four = one;
  four.path_tries = 4;
  auto lowestY = [](const Guide& g) {
    double y = 1e9;
    for (const auto& q : g.key_postures) y = std::min(y, q.base_position.y());
    return y;
  };
  one.seed = four.seed = 2;
  const GuideResult lost = authorGuide(sc, one);
  EXPECT_EQ(lost.status, GuideResult::Status::NoPath) << lost.reason;
  const GuideResult found = authorGuide(sc, four);
  ASSERT_TRUE(found.success()) << found.reason;
  EXPECT_GT(lowestY(found.guide), -0.05);
  one.seed = four.seed = 3;
  const GuideResult round = authorGuide(sc, one);
  ASSERT_TRUE(round.success()) << round.reason;
  EXPECT_LT(lowestY(round.guide), -0.2);  // the long way, right of the chair
  const GuideResult a = authorGuide(sc, four), b = authorGuide(sc, four);
  ASSERT_TRUE(a.success() && b.success()) << a.reason << " | " << b.reason;
  EXPECT_GT(lowestY(a.guide), -0.05);
  EXPECT_LT(a.guide.key_postures.size(), round.guide.key_postures.size());
  Guide ga = a.guide, gb = b.guide;
  ga.seconds = gb.seconds = 0;
  EXPECT_EQ(guideToJson(ga, sc), guideToJson(gb, sc));
}

// GuideOptions::path_retries: a leg whose try finds no path within its
// state checks is tried again with the next seeds before it is given up.
// chair_paper's seed 2 then has a guide (the retry's tree goes round the
// chair's right, the long way, as seed 3's first try does); seed 1, whose
// first try finds its path, has the same guide as without retries, to the
// bit.
TEST(GuideAuthor, ALegWhoseTryFindsNoPathIsTriedAgainWithTheNextSeeds) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_paper.yaml"));
  GuideOptions none;
  none.max_seconds = 60;  // the check bounds decide, not a loaded machine
  none.path_retries = 0;
  GuideOptions two = none;
  two.path_retries = 2;
  EXPECT_EQ(GuideOptions().path_retries, 1);  // on by default
  none.seed = two.seed = 2;
  const GuideResult lost = authorGuide(sc, none);
  EXPECT_EQ(lost.status, GuideResult::Status::NoPath) << lost.reason;
  const GuideResult found = authorGuide(sc, two);
  ASSERT_TRUE(found.success()) << found.reason;
  EXPECT_GE(found.guide.key_postures.back().base_position.y(), 0.80);  // the waist past the goal's bound
  none.seed = two.seed = 1;
  const GuideResult a = authorGuide(sc, none), b = authorGuide(sc, two);
  ASSERT_TRUE(a.success() && b.success()) << a.reason << " | " << b.reason;
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

// models/scenarios/step_up.yaml, with no key postures: the guide's base stays
// within the standing height (plus the slack) of the ground within a step of
// it, so it rises only where a foot can go up on the platform, and the
// planner climbs it on that guide. A guide that floats up before the edge
// (no ceiling) leaves the planner nowhere to go.
TEST(GuideAuthor, AStepUpIsGuidedUnderTheCeilingAndPlannedOntoThePlatform) {
  Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_up.yaml"));
  ASSERT_TRUE(sc.key_postures.empty());
  const GuideResult g = authorGuide(sc, GuideOptions());
  ASSERT_TRUE(g.success()) << g.reason;
  const double standing = sc.robot->posture("half_sitting").base_position.z();  // soles at z = 0
  for (const auto& q : g.guide.key_postures) {
    if (q.base_position.x() < 0.35 - 0.25 - 1e-6) {  // no platform within a step: the floor's ceiling
      EXPECT_LE(q.base_position.z(), standing + GuideOptions().ceiling_slack + 1e-9) << q.base_position.transpose();
    }
  }
  sc.key_postures = g.guide.key_postures;
  PlannerParameters p = plannerParameters(sc);
  p.max_nodes = 200;  // solved in 24: a node budget, not the machine's speed, bounds a failing run
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checkPlan(r.plan, sc, checker).valid());
  EXPECT_EQ(supportingOnAtTheEnd(r.plan, sc, "platform_top"), 2);

  // Without the ceiling the guide rises before the edge and the search fails.
  GuideOptions free;
  free.ceiling_slack = 10;
  const GuideResult floating = authorGuide(sc, free);
  ASSERT_TRUE(floating.success()) << floating.reason;
  sc.key_postures = floating.guide.key_postures;
  EXPECT_FALSE(ContactPlanner(sc, p).plan().solved());
}

// The contacts a key posture makes, found here from its own spots (within
// 1 mm of an allowed surface's plane, over its polygon, facing it), all
// supporting: independent of the guide author's reach and tolerances.
namespace {
std::vector<ContactSpec> restingWithin1mm(const Scenario& sc, Kinematics& kin, const Configuration& q) {
  kin.setConfiguration(q);
  std::vector<ContactSpec> out;
  for (int spot : sc.allowed_spots)
    for (int si : sc.allowed_surfaces) {
      const Surface& surf = sc.scene->surfaces()[si];
      const Eigen::Isometry3d f = surf.frame.inverse() * kin.spotPose(spot);
      if (std::abs(f.translation().z()) > 1e-3 || f.linear()(2, 2) < 0.95 ||
          !surf.polygon.contains(f.translation().head<2>()))
        continue;
      ContactSpec c;
      c.spot = spot;
      c.surface = si;
      c.placement = projectOnSurface(surf, kin.spotPose(spot));
      out.push_back(c);
      break;
    }
  return out;
}
}  // namespace

// Paths through the statically stable subspace (GuideOptions::stable): on
// step_up every key posture of the guide rests on the scene and the check
// accepts it in equilibrium there, where the plain guide's blend floats up
// toward the platform (some key posture without a stance the check
// accepts); the planner plans on it to both soles on the platform.
TEST(GuideAuthor, AStableGuideRestsEveryKeyPostureOnTheSceneInEquilibrium) {
  Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_up.yaml"));
  ASSERT_TRUE(sc.key_postures.empty());
  Kinematics kin(sc.robot);
  ValidityChecker checker(sc.robot, sc.scene);
  auto inEquilibrium = [&](const Configuration& q) {
    const std::vector<ContactSpec> stance = restingWithin1mm(sc, kin, q);
    return !stance.empty() && checker.checkPosture(q, stance).valid();
  };
  const GuideResult plain = authorGuide(sc, GuideOptions());
  ASSERT_TRUE(plain.success()) << plain.reason;
  int floating = 0;
  for (const auto& q : plain.guide.key_postures) floating += !inEquilibrium(q);
  EXPECT_GT(floating, 0) << "the plain guide's blend is not in equilibrium everywhere";

  GuideOptions o;
  o.stable = true;
  const GuideResult g = authorGuide(sc, o);
  ASSERT_TRUE(g.success()) << g.reason;
  EXPECT_GT(g.stable_projections, 0);
  const auto& k = g.guide.key_postures;
  EXPECT_GT(k.size(), plain.guide.key_postures.size()) << "sampled along the edges, not only at the vertices";
  for (std::size_t i = 0; i < k.size(); ++i) {
    EXPECT_TRUE(inEquilibrium(k[i])) << "key posture " << i << " at " << k[i].base_position.transpose();
    if (i > 0) {
      EXPECT_LT((k[i].base_position - k[i - 1].base_position).head<2>().norm(), 0.25) << i;
    }
  }
  EXPECT_EQ(k.front().joints, sc.start.joints);
  kin.setConfiguration(k.back());
  EXPECT_TRUE(sc.goal.linkWithinBounds(kin));
  EXPECT_EQ(authorGuide(sc, o).guide.key_postures.back().joints, k.back().joints) << "deterministic";

  sc.key_postures = k;
  PlannerParameters p = plannerParameters(sc);
  p.max_nodes = 1000;  // solved in 98: a node budget, not the machine's speed, bounds a failing run
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_TRUE(checkPlan(r.plan, sc, checker).valid());
  EXPECT_EQ(supportingOnAtTheEnd(r.plan, sc, "platform_top"), 2);
}

// Across a gap in the floor 1 m wide that no stance spans (the floor's two
// surfaces, the obstacle under them whole: the rough path is clear), the
// plain guide crosses it; through the statically stable subspace there is
// no path, after replanning around the samples that did not project, and
// the reason says where the subspace ends and on which stance.
TEST(GuideAuthor, AGapNoStanceSpansHasNoPathThroughTheStableSubspaceAndSaysWhere) {
  test::TempDir dir;
  dir.write("gap_floor.yaml",
            "format: acyclic.scene/1\n"
            "name: gap_floor\n"
            "obstacles:\n"
            "  - {name: floor, shape: box, size: [6, 6, 0.1], position: [0, 0, -0.05]}\n"
            "surfaces:\n"
            "  - {name: floor_near, obstacle: floor, position: [0, 0, 0], friction: 0.7,\n"
            "     polygon: [[-3, -3], [0.3, -3], [0.3, 3], [-3, 3]]}\n"
            "  - {name: floor_far, obstacle: floor, position: [0, 0, 0], friction: 0.7,\n"
            "     polygon: [[1.3, -3], [3, -3], [3, 3], [1.3, 3]]}\n");
  std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const auto s = text.find("scene: ");
  text.replace(s, text.find('\n', s) - s, "scene: " + dir.path() + "/gap_floor.yaml");
  for (auto at = text.find("surface: floor}"); at != std::string::npos; at = text.find("surface: floor}", at))
    text.replace(at, 15, "surface: floor_near}");
  text.replace(text.find("allowed_surfaces: [floor]"), 25, "allowed_surfaces: [floor_near, floor_far]");
  text.replace(text.find("min: 0.25"), 9, "min: 1.60");
  text.erase(text.find("key_postures:"));
  const Scenario sc = Scenario::load(dir.write("gap.yaml", text));

  const GuideResult plain = authorGuide(sc, GuideOptions());
  ASSERT_TRUE(plain.success()) << plain.reason;
  GuideOptions o;
  o.stable = true;
  const GuideResult g = authorGuide(sc, o);
  EXPECT_EQ(g.status, GuideResult::Status::NoPath) << toString(g.status) << ": " << g.reason;
  EXPECT_GE(g.stable_replans, o.stable_replans) << "planned again around the samples that did not project";
  EXPECT_NE(g.reason.find("statically stable subspace"), std::string::npos) << g.reason;
  EXPECT_NE(g.reason.find("r_sole@floor_near, l_sole@floor_near"), std::string::npos) << g.reason;
}

// Sitting down at a table: HRP-2 stands beside the chair of
// models/scenes/chair_table.yaml, whose seat is 6 cm from the table's edge.
// Carried toward the seat, the start stance meets the table or the seat's
// side; the seated posture put over the seat, resting on the thighs, then the
// soles floated down to the floor, is a goal posture the check accepts.
TEST(GuideAuthor, SittingDownAtATableEndsOnTheSeatedPostureOverTheSeat) {
  test::TempDir dir;
  const std::string text = "format: acyclic.scenario/1\nname: sit_at_table\nrobot: " +
                           test::sourcePath("models/hrp2/hrp2.yaml") + "\nscene: " +
                           test::sourcePath("models/scenes/chair_table.yaml") +
                           "\nstart:\n  configuration: {posture: half_sitting, base_position: [0.0, 0.85, 0.648702]}\n"
                           "  contacts:\n    - {spot: r_sole, surface: floor}\n    - {spot: l_sole, surface: floor}\n"
                           "allowed_spots: [r_sole, l_sole, r_thigh, l_thigh, r_wrist, l_wrist]\n"
                           "allowed_surfaces: [floor, chair_seat, table_top]\n"
                           "goal: {link: WAIST, axis: z, max: 0.40, supported_by: [r_thigh, l_thigh]}\n";
  const Scenario sc = Scenario::load(dir.write("sit_at_table.yaml", text));
  GuideResult r;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(sc, r));
  const Configuration& end = r.guide.key_postures.back();
  std::vector<ContactSpec> seated(4);
  const char* spots[] = {"r_sole", "l_sole", "r_thigh", "l_thigh"};
  for (int k = 0; k < 4; ++k) {
    seated[k].spot = sc.robot->spotIndex(spots[k]);
    seated[k].surface = sc.scene->surfaceIndex(k < 2 ? "floor" : "chair_seat");
  }
  Kinematics kin(sc.robot);
  kin.setConfiguration(end);
  placeOnSurfaces(sc, kin, seated);
  EXPECT_TRUE(sc.goal.satisfied(kin, seated));
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checker.checkPosture(end, seated).valid());
  // Over the seat (x in [-0.18, 0.16], y in [-0.21, 0.21]), facing the table.
  EXPECT_NEAR(end.base_position.y(), 0.0, 0.21);
  EXPECT_LT(end.base_position.x(), 0.16);
  // The start stance carried toward the seat's nearest point cannot sit on
  // it (the table is in the way), nor carried in front of it (support_attempts
  // stops before those): the seated posture put over the seat does it.
  // Without it too, the author has no goal posture.
  GuideOptions near_only;
  // The placements around each allowed surface's nearest point: 1 on the
  // floor (under the start), 7 toward the seat, 7 toward the table top.
  near_only.support_attempts = 15;
  const GuideResult seated_only = authorGuide(sc, near_only);
  ASSERT_TRUE(seated_only.success()) << seated_only.reason;
  EXPECT_LT(seated_only.guide.key_postures.back().base_position.x(), 0.16);
  near_only.seated_posture = "no such posture";
  const GuideResult without = authorGuide(sc, near_only);
  EXPECT_EQ(without.status, GuideResult::Status::NoGoalPosture) << without.reason;
}

// Sitting down at a table from beside it (models/scenarios/sit_at_table.yaml):
// the straight blend from standing beside the chair into the seated goal
// posture cuts over the seat's corner, so the guide stands in front of the
// seat first (the approach posture: soles on the floor in front of the seat,
// within its width, accepted by the check), then sits; the planner follows
// it to the seat. Without the approach posture (before it was made) no plan
// came within 3,000 nodes.
TEST(GuideAuthor, SittingDownAtATableFromBesideItStandsInFrontOfTheSeatFirstAndIsPlanned) {
  Scenario sc = Scenario::load(test::sourcePath("models/scenarios/sit_at_table.yaml"));
  ASSERT_TRUE(sc.key_postures.empty());
  GuideResult g;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(sc, g));
  ASSERT_TRUE(g.approach);
  ASSERT_GT(g.approach_index, 0);
  ASSERT_LT(g.approach_index + 1, static_cast<int>(g.guide.key_postures.size()));
  const Configuration* approach = &g.guide.key_postures[g.approach_index];
  const double standing = sc.robot->posture("half_sitting").base_position.z();
  EXPECT_GT(approach->base_position.z(), standing - 0.03) << "standing";
  std::vector<ContactSpec> feet(2);
  Kinematics kin(sc.robot);
  kin.setConfiguration(*approach);
  for (int k = 0; k < 2; ++k) {
    feet[k].spot = sc.robot->spotIndex(k == 0 ? "r_sole" : "l_sole");
    feet[k].surface = sc.scene->surfaceIndex("floor");
    const Eigen::Vector3d p = kin.spotPose(feet[k].spot).translation();
    EXPECT_GT(p.x(), 0.16) << "in front of the seat's edge";
    EXPECT_LT(std::abs(p.y()), 0.21) << "within the seat's width";
  }
  placeOnSurfaces(sc, kin, feet);
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checker.checkPosture(*approach, feet).valid());
  EXPECT_LT(g.guide.key_postures.back().base_position.z(), 0.40);  // the seated goal posture

  sc.key_postures = g.guide.key_postures;
  PlannerParameters p = plannerParameters(sc);
  p.max_nodes = 2000;  // solved in 1,119: a node budget, not the machine's speed, bounds a failing run
  p.max_seconds = 600;
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_TRUE(checkPlan(r.plan, sc, checker).valid());
  EXPECT_EQ(supportingOnAtTheEnd(r.plan, sc, "chair_seat"), 2);
}

// Ducking under a low beam (models/scenarios/duck_under_beam.yaml): no path
// of standing postures passes under it, so the guide is planned again with
// the crouch coordinate; its key posture under the beam is crouched, and the
// planner walks under the beam on its feet, crouched, to a valid plan.
TEST(GuideAuthor, ALowBeamIsPassedCrouchedAndPlanned) {
  Scenario sc = Scenario::load(test::sourcePath("models/scenarios/duck_under_beam.yaml"));
  ASSERT_TRUE(sc.key_postures.empty());
  GuideOptions standing_only;  // 4 s of RRTConnect on standing postures alone: no path
  standing_only.crouch = false;
  standing_only.max_seconds = 4;
  const GuideResult refused = authorGuide(sc, standing_only);
  EXPECT_EQ(refused.status, GuideResult::Status::NoPath) << refused.reason;
  EXPECT_FALSE(refused.crouch);

  GuideResult g;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(sc, g));
  EXPECT_TRUE(g.crouch);
  const double standing = sc.start.base_position.z();
  double lowest_under = standing;  // the base's lowest among key postures under the beam (x in [0.5, 1.0])
  for (const auto& q : g.guide.key_postures)
    if (q.base_position.x() > 0.5 && q.base_position.x() < 1.0) lowest_under = std::min(lowest_under, q.base_position.z());
  EXPECT_LT(lowest_under, standing - 0.15);

  sc.key_postures = g.guide.key_postures;
  PlannerParameters p = plannerParameters(sc);
  p.max_nodes = 1000;  // solved in 170: a node budget, not the machine's speed, bounds a failing run
  p.max_seconds = 600;
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  ValidityChecker checker(sc.robot, sc.scene);
  EXPECT_TRUE(checkPlan(r.plan, sc, checker).valid());
  double lowest = standing;
  for (const auto& st : r.plan.stances) lowest = std::min(lowest, st.configuration.base_position.z());
  EXPECT_LT(lowest, standing - 0.15) << "walked under the beam crouched";
}

// Under a low table nothing stands in the goal region: the guide author
// ends on the robot's crawling posture (knees and palms on the floor) and
// gets down onto it where the robot starts, each posture of the way down a
// valid stance on the contacts it makes (the check, on contacts found from
// the posture's own spots): both soles, then one sole and a knee, ..., both
// knees and both palms. Without the crawl it says why.
TEST(GuideAuthor, UnderALowTableTheGuideGetsDownOnAllFoursAndCrawls) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/crawl_under_table_ompl.yaml"));
  ASSERT_TRUE(sc.key_postures.empty());

  GuideOptions no_crawl;
  no_crawl.crawl = false;
  const GuideResult refused = authorGuide(sc, no_crawl);
  EXPECT_EQ(refused.status, GuideResult::Status::NoGoalPosture);

  GuideResult g;
  ASSERT_NO_FATAL_FAILURE(expectGuideFromTheStart(sc, g));
  ASSERT_TRUE(g.crawl);
  const auto& k = g.guide.key_postures;
  ASSERT_GT(g.crawl_index, 2);
  ASSERT_LT(g.crawl_index, static_cast<int>(k.size()) - 1);
  Kinematics kin(sc.robot);
  ValidityChecker checker(sc.robot, sc.scene);
  const int floor = sc.scene->surfaceIndex("floor");
  // The spots of a key posture within 1 mm of the floor, facing it.
  auto onTheFloor = [&](const Configuration& q) {
    kin.setConfiguration(q);
    std::vector<ContactSpec> out;
    for (int spot : sc.allowed_spots) {
      const Eigen::Isometry3d f = sc.scene->surfaces()[floor].frame.inverse() * kin.spotPose(spot);
      if (std::abs(f.translation().z()) > 1e-3 || f.linear()(2, 2) < 0.95) continue;
      ContactSpec c;
      c.spot = spot;
      c.surface = floor;
      out.push_back(c);
    }
    placeOnSurfaces(sc, kin, out);
    return out;
  };
  auto names = [&](const std::vector<ContactSpec>& cs) {
    std::set<std::string> n;
    for (const auto& c : cs) n.insert(sc.robot->spots()[c.spot].name);
    return n;
  };
  for (int i = 1; i <= g.crawl_index; ++i) {
    const std::vector<ContactSpec> stance = onTheFloor(k[i]);
    SCOPED_TRACE("key posture " + std::to_string(i));
    EXPECT_GE(stance.size(), 2u);
    EXPECT_TRUE(checker.checkPosture(k[i], stance).valid());
  }
  EXPECT_EQ(names(onTheFloor(k[1])), (std::set<std::string>{"l_sole", "r_sole"}));  // the squat
  EXPECT_EQ(names(onTheFloor(k[g.crawl_index])), (std::set<std::string>{"l_knee", "l_palm", "r_knee", "r_palm"}));
  EXPECT_EQ(names(onTheFloor(k.back())), (std::set<std::string>{"l_knee", "l_palm", "r_knee", "r_palm"}));
  kin.setConfiguration(k.back());
  EXPECT_TRUE(sc.goal.linkWithinBounds(kin));
  for (std::size_t i = g.crawl_index; i < k.size(); ++i)
    EXPECT_LT(k[i].base_position.z(), 0.45) << "crawls: key posture " << i;
  EXPECT_NO_THROW(GuidePotential(k, 1.0, 0.05));

  // The planner follows the way down: on the guide's key postures up to the
  // crawling posture, the goal on both knees and both palms, supporting.
  Scenario down = sc;
  down.key_postures.assign(k.begin(), k.begin() + g.crawl_index + 1);
  down.goal.min = -1.0;
  down.goal.supporting_spots.clear();
  for (const char* s : {"r_knee", "l_knee", "r_palm", "l_palm"}) down.goal.supporting_spots.push_back(sc.robot->spotIndex(s));
  PlannerParameters p = plannerParameters(sc);
  p.max_nodes = 1000;  // down within 52 nodes: a node budget, not the machine's speed, bounds a failing run
  p.max_seconds = 600;
  const PlanningResult r = ContactPlanner(down, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_TRUE(checkPlan(r.plan, down, checker).valid());
  EXPECT_EQ(supportingOnAtTheEnd(r.plan, down, "floor"), 4);
}
