// The contact planner on the small scenario: a valid plan, determinism,
// budgets with reasons, cancellation, bad starts, and each ablation switch.
#include <gtest/gtest.h>

#include <set>
#include <thread>

#include "planner/check/plan_check.h"
#include "planner/common/format_error.h"
#include "planner/search/refused_plans.h"
#include "planner/search/planner_parameters.h"
#include "planner/search/swing_check.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& step() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  return sc;
}

void expectValidPlan(const Scenario& sc, const Plan& plan) {
  ValidityChecker checker(sc.robot, sc.scene);
  const PlanReport rep = checkPlan(plan, sc, checker);
  for (std::size_t i = 0; i < rep.stances.size(); ++i)
    for (const auto& p : rep.stances[i].parts)
      EXPECT_TRUE(p.ok()) << "stance " << i << " " << p.name << ": " << (p.violations.empty() ? "" : p.violations[0]);
  for (const auto& v : rep.sequence_violations) ADD_FAILURE() << v;
}

}  // namespace

TEST(ContactPlanner, SmallScenarioIsSolvedWithAValidPlan) {
  const Scenario& sc = step();
  ContactPlanner planner(sc);
  const PlanningResult r = planner.plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  EXPECT_GE(r.plan.stances.size(), 3u);  // at least one foot moved
  expectValidPlan(sc, r.plan);
  EXPECT_EQ(r.plan.stats.nodes_generated, r.stats.nodes_generated);
  EXPECT_GT(r.stats.posture_calls, 0);
  // Supporting contacts carry the forces of the independent check.
  for (const auto& c : r.plan.stances.back().contacts)
    if (c.spec.supporting) {
      EXPECT_EQ(c.forces.size(), 4u);
    }
  // Every contact's placement is its witness's spot frame, angle included
  // (the contact rows fix the in-plane angle only modulo pi).
  Kinematics kin(sc.robot);
  for (const auto& st : r.plan.stances) {
    kin.setConfiguration(st.configuration);
    for (const auto& c : st.contacts) {
      const ContactSpot& spot = sc.robot->spots()[c.spec.spot];
      const Eigen::Isometry3d f = kin.linkPose(spot.link) * spot.frame;
      const Eigen::Isometry3d g = contactFrame(sc.scene->surfaces()[c.spec.surface], c.spec.placement);
      EXPECT_LT((f.linear().col(0) - g.linear().col(0)).norm(), 0.02) << sc.describe(c.spec);
    }
  }
}

TEST(ContactPlanner, SameScenarioAndSeedSamePlanWhateverTheThreads) {
  const Scenario& sc = step();
  PlannerParameters one;
  one.threads = 1;
  const PlanningResult a = ContactPlanner(sc).plan();
  const PlanningResult b = ContactPlanner(sc).plan();
  const PlanningResult c = ContactPlanner(sc, one).plan();
  ASSERT_TRUE(a.solved() && b.solved() && c.solved());
  Plan pa = a.plan, pb = b.plan, pc = c.plan;
  pa.stats.seconds = pb.stats.seconds = pc.stats.seconds = 0;
  EXPECT_EQ(planToJson(pa, sc), planToJson(pb, sc));
  EXPECT_EQ(planToJson(pa, sc), planToJson(pc, sc));  // two generators at once or one: the same plan
}

TEST(ContactPlanner, BudgetsStopWithAReason) {
  const Scenario& sc = step();
  PlannerParameters p;
  p.max_nodes = 3;
  PlanningResult r = ContactPlanner(sc, p).plan();
  EXPECT_EQ(r.status, PlanningResult::Status::NodeBudget);
  EXPECT_NE(r.reason.find("3 nodes"), std::string::npos) << r.reason;
  p = PlannerParameters();
  p.max_posture_calls = 2;
  r = ContactPlanner(sc, p).plan();
  EXPECT_EQ(r.status, PlanningResult::Status::PostureBudget);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_LE(r.stats.posture_calls, 3);
}

TEST(ContactPlanner, CancelledFromAnotherThread) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  std::atomic<bool> cancel{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    cancel = true;
  });
  const PlanningResult r = ContactPlanner(sc).plan(&cancel);
  stopper.join();
  EXPECT_EQ(r.status, PlanningResult::Status::Cancelled);
  EXPECT_LT(r.stats.seconds, 2.5);  // stops at the next posture call's end, not at the budget
}

// A goal with supported_by ends on a stance where those spots support: the
// feet's last step is followed by the stance where it settles, if the goal is
// met there first.
TEST(ContactPlanner, GoalSupportedByEndsOnTheseSpotsSupporting) {
  test::TempDir dir;
  std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const std::string goal = "goal: {link: WAIST, axis: x, min: 0.25}";
  ASSERT_NE(text.find(goal), std::string::npos);
  text.replace(text.find(goal), goal.size(), "goal: {link: WAIST, axis: x, min: 0.25, supported_by: [r_sole, l_sole]}");
  const Scenario sc = Scenario::load(dir.write("s.yaml", text));
  const PlanningResult r = ContactPlanner(sc).plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  expectValidPlan(sc, r.plan);  // the goal, supports included, is met by the last stance
  int supporting_soles = 0;
  for (const auto& c : r.plan.stances.back().contacts) supporting_soles += c.spec.supporting;
  EXPECT_EQ(supporting_soles, 2);
  EXPECT_EQ(r.plan.stances.back().contacts.size(), 2u);
  // Without supported_by the same search ends one stance earlier, on the
  // last foot touching but not yet supporting.
  const PlanningResult plain = ContactPlanner(step()).plan();
  ASSERT_TRUE(plain.solved());
  ASSERT_EQ(plain.plan.stances.size() + 1, r.plan.stances.size());
  int plain_supporting = 0;
  for (const auto& c : plain.plan.stances.back().contacts) plain_supporting += c.spec.supporting;
  EXPECT_EQ(plain_supporting, 1);
}

// forbidden_contacts: the right sole may never be put back on the floor. The
// start stands on it (allowed); the search may lift that foot but never land
// it again: it steps forward far enough with the left foot alone, where
// unforbidden its plan walks, the right sole landing again.
TEST(ContactPlanner, AForbiddenPairIsNeverMade) {
  test::TempDir dir;
  const std::string text = test::scenarioText("models/scenarios/step_forward.yaml") +
                           "forbidden_contacts:\n  - {spot: r_sole, surface: floor}\n";
  const Scenario sc = Scenario::load(dir.write("s.yaml", text));
  const int r_sole = sc.robot->spotIndex("r_sole");
  auto landsAgain = [&](const Plan& plan) {  // a stance without the right sole, then one with it
    bool lifted = false;
    for (const auto& st : plan.stances) {
      bool on = false;
      for (const auto& c : st.contacts) on = on || c.spec.spot == r_sole;
      if (lifted && on) return true;
      lifted = lifted || !on;
    }
    return false;
  };
  const PlanningResult r = ContactPlanner(sc, plannerParameters(sc)).plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  expectValidPlan(sc, r.plan);
  EXPECT_FALSE(landsAgain(r.plan));
  const PlanningResult plain = ContactPlanner(step(), plannerParameters(step())).plan();
  ASSERT_TRUE(plain.solved()) << plain.reason;
  EXPECT_TRUE(landsAgain(plain.plan));
}

// The small scenario with non-foot contacts: HRP-2 sits down on a chair, the
// goal needing both thighs on the seat and supporting.
TEST(ContactPlanner, SitDownIsPlannedWithBothThighsOnTheSeat) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/sit_down.yaml"));
  const PlanningResult r = ContactPlanner(sc).plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  expectValidPlan(sc, r.plan);
  int thighs = 0;
  for (const auto& c : r.plan.stances.back().contacts) {
    const std::string& name = sc.robot->spots()[c.spec.spot].name;
    if (name == "r_thigh" || name == "l_thigh") {
      EXPECT_EQ(sc.scene->surfaces()[c.spec.surface].name, "chair_seat");
      thighs += c.spec.supporting;
    }
  }
  EXPECT_EQ(thighs, 2);
}

// Two posture generators solve a pair's candidates two at a time, and an
// expansion's calls as one batch; the search takes their results in the
// order of solving them one by one: the same tree, the same plan.
TEST(ContactPlanner, ThePapersChairCannotBeLeftOnTheFeetAlone) {
  // models/scenarios/chair_paper.yaml: the table overhangs the thighs, so
  // the trunk cannot lean far enough to bring the centre of mass over the
  // feet. Restricted to the soles and thighs, the search runs out of stances
  // (every one reachable from the start explored, none with both thighs off
  // the seat) long before its budgets: no solution, not an exhausted budget.
  test::TempDir dir;
  std::string text = test::scenarioText("models/scenarios/chair_paper.yaml");
  const std::string spots = "allowed_spots: [r_sole, l_sole, r_knee, l_knee, r_thigh, l_thigh,\n"
                            "                r_forearm, l_forearm, r_wrist, l_wrist, r_palm, l_palm]";
  ASSERT_NE(text.find(spots), std::string::npos);
  text.replace(text.find(spots), spots.size(), "allowed_spots: [r_sole, l_sole, r_thigh, l_thigh]");
  // The feet allowed on the seat too: no foot placement is held back.
  const std::size_t forbidden = text.find("forbidden_contacts:");
  ASSERT_NE(forbidden, std::string::npos);
  text.replace(forbidden, text.find("\n\n", forbidden) - forbidden, "");
  const Scenario sc = Scenario::load(dir.write("feet_only.yaml", text));
  ASSERT_TRUE(sc.forbidden_contacts.empty());
  PlannerParameters params = plannerParameters(sc);
  params.max_seconds = 600;  // budgets far beyond what the search needs
  // At the planner's default resolution, finer than the scenario's 0.10 m:
  // stances 5 cm apart are distinct, so fewer are merged into one explored.
  params.duplicate_distance = PlannerParameters().duplicate_distance;
  ASSERT_LT(params.duplicate_distance, plannerParameters(sc).duplicate_distance);
  ContactPlanner planner(sc, params);
  const PlanningResult r = planner.plan();
  EXPECT_EQ(r.status, PlanningResult::Status::NoSolution) << toString(r.status) << ": " << r.reason;
  EXPECT_LT(r.stats.nodes_generated, 3000);  // the scenario's node budget, far from reached
}

TEST(SwingCheck, AFootHangingFromItsThighCannotSwingUnderTheKneeButComesDown) {
  // From a plan of the paper's chair made before this check: seated on the
  // left thigh, the right wrist on the table, the left foot goes from the
  // floor behind the knee to the air in front of it. Below the thigh only the
  // knee and ankle move: the foot swings under the knee, 0.40 m up, and
  // through the floor. In the other pair the foot comes down in front of the
  // knee without passing under it.
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_paper.yaml"));
  const CollisionModel collisions(sc.robot, sc.scene);
  Kinematics kin(sc.robot);
  auto held = [&](const Plan& p) {  // the contacts of both stances
    std::vector<ContactSpec> out;
    for (const auto& a : p.stances[0].specs())
      for (const auto& b : p.stances[1].specs())
        if (a.spot == b.spot && a.surface == b.surface && a.supporting && b.supporting) out.push_back(a);
    return out;
  };
  const Plan under = readPlan(test::sourcePath("tests/data/chair_paper_foot_under_knee.plan.json"), sc);
  const std::vector<ContactSpec> h = held(under);
  ASSERT_EQ(h.size(), 2u);  // l_thigh, r_wrist
  const std::string why =
      checkHangingSwings(sc, collisions, kin, h, under.stances[0].configuration, under.stances[1].configuration);
  EXPECT_NE(why.find("LLEG_LINK5/foot"), std::string::npos) << why;  // in the floor, or the other foot when the ankle turns
  EXPECT_NE(why.find("l_thigh"), std::string::npos) << why;
  const Plan down = readPlan(test::sourcePath("tests/data/chair_paper_foot_from_thigh.plan.json"), sc);
  EXPECT_EQ(checkHangingSwings(sc, collisions, kin, held(down), down.stances[0].configuration,
                               down.stances[1].configuration),
            "");
}

TEST(ContactPlanner, CallsSolvedAheadLeaveTheTreeAsItWas) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/sit_down.yaml"));
  PlannerParameters one = plannerParameters(sc), two = one;
  one.threads = 1;
  two.threads = 2;
  const PlanningResult a = ContactPlanner(sc, one).plan();
  const PlanningResult b = ContactPlanner(sc, two).plan();
  ASSERT_TRUE(a.solved() && b.solved()) << a.reason << " / " << b.reason;
  EXPECT_EQ(a.stats.nodes_generated, b.stats.nodes_generated);
  EXPECT_EQ(a.stats.nodes_expanded, b.stats.nodes_expanded);
  EXPECT_EQ(a.stats.posture_calls, b.stats.posture_calls);
  EXPECT_EQ(a.stats.posture_failures, b.stats.posture_failures);
  // Two at a time solves candidates ahead that go back to their pair (one
  // thread too may leave a batch's last results when the goal is met), or
  // stops them once the candidate before them has made its son.
  EXPECT_GT(b.stats.calls_ahead_unused + b.stats.calls_stopped, a.stats.calls_ahead_unused);
  EXPECT_EQ(a.stats.calls_stopped, 0);  // one generator: no candidate runs beside the one before it
  Plan pa = a.plan, pb = b.plan;
  pa.stats.seconds = pb.stats.seconds = 0;
  EXPECT_EQ(planToJson(pa, sc), planToJson(pb, sc));
}

// alternative_step: a pair's second and later sons wait in the open list
// behind other contact changes, so fewer of them are expanded.
TEST(ContactPlanner, APairsLaterSonsWaitInTheOpenList) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/sit_down.yaml"));
  auto expandedAlternatives = [&](double step) {
    PlannerParameters p = plannerParameters(sc);
    p.alternative_step = step;
    int count = 0;
    p.trace = [&](const std::string& line) {
      count += line.rfind("expand", 0) == 0 && line.find("its pair's son") != std::string::npos;
    };
    const PlanningResult r = ContactPlanner(sc, p).plan();
    EXPECT_TRUE(r.solved()) << "alternative_step " << step << ": " << r.reason;
    return count;
  };
  const int paper = expandedAlternatives(0.0), waiting = expandedAlternatives(1.0);
  EXPECT_GT(paper, 0);
  EXPECT_LT(waiting, paper);
}

TEST(ContactPlanner, InvalidStartIsRefused) {
  test::TempDir dir;
  std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  text.replace(text.find("configuration: {posture: half_sitting}"), 38,
               "configuration: {posture: half_sitting, base_position: [0, 0, 0.60]}");  // feet 5 cm into the floor
  const Scenario sc = Scenario::load(dir.write("s.yaml", text));
  const PlanningResult r = ContactPlanner(sc).plan();
  EXPECT_EQ(r.status, PlanningResult::Status::InvalidInput);
  EXPECT_NE(r.reason.find("start stance"), std::string::npos) << r.reason;
}

TEST(ContactPlanner, TheFailureMemorySkipsPairsThatJustFailedFromTheSamePlace) {
  // The chair, 25 nodes: sons of the seated robot keep most spots where
  // their parents held them, and a pair that failed there (a knee on the
  // table) is not tried again. Without the memory every pair is tried at
  // every node: more failed posture calls for the same number of nodes (not
  // always more calls: the calls saved go to other pairs, some of which
  // succeed; 33 failures of 63 calls against 35 of 59 with the LDL^T solver).
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  PlannerParameters with = plannerParameters(sc), without = with;
  with.max_nodes = without.max_nodes = 25;
  without.failure_memory = false;
  const PlanningResult a = ContactPlanner(sc, with).plan();
  const PlanningResult b = ContactPlanner(sc, without).plan();
  EXPECT_EQ(a.status, PlanningResult::Status::NodeBudget) << a.reason;
  EXPECT_EQ(b.status, PlanningResult::Status::NodeBudget) << b.reason;
  EXPECT_GT(a.stats.pairs_remembered, 0);
  EXPECT_EQ(b.stats.pairs_remembered, 0);
  EXPECT_LT(a.stats.posture_failures, b.stats.posture_failures);
  // The memory is part of the search: still deterministic.
  const PlanningResult c = ContactPlanner(sc, with).plan();
  EXPECT_EQ(c.stats.posture_calls, a.stats.posture_calls);
  EXPECT_EQ(c.stats.pairs_remembered, a.stats.pairs_remembered);
}

TEST(ContactPlanner, SonsDroppedAsDuplicatesAreCountedAmongTheNodesGenerated) {
  // Nodes generated count every son whose posture call succeeded, those
  // then dropped as too close to a node with the same contacts included
  // (stats.duplicates, printed by acyclic-planner). Thresholds of nothing
  // drop none; thresholds of a whole surface drop every son that puts a
  // contact set back where the tree has it already.
  const Scenario& sc = step();
  PlannerParameters none, all;
  none.duplicate_distance = 1e-9;  // m
  none.duplicate_angle = 1e-9;     // rad
  all.duplicate_distance = 10.0;
  all.duplicate_angle = 4.0;
  none.max_nodes = all.max_nodes = 60;
  const PlanningResult a = ContactPlanner(sc, none).plan();
  const PlanningResult b = ContactPlanner(sc, all).plan();
  EXPECT_EQ(a.stats.duplicates, 0);
  EXPECT_GT(b.stats.duplicates, 0);
  EXPECT_LT(b.stats.duplicates, b.stats.nodes_generated);
}

TEST(ContactPlanner, AblationsStillPlanValidly) {
  const Scenario& sc = step();
  for (int which = 0; which < 3; ++which) {
    PlannerParameters p;
    p.max_seconds = 60;
    if (which == 0) p.lazy_sons = false;
    if (which == 1) p.optimized_candidates = false;
    if (which == 2) p.guide_potential = false;
    const PlanningResult r = ContactPlanner(sc, p).plan();
    if (r.solved()) {
      expectValidPlan(sc, r.plan);
    } else {
      // the random baseline may fail to find a plan, but says why
      EXPECT_EQ(which, 1) << toString(r.status) << ": " << r.reason;
      EXPECT_FALSE(r.reason.empty());
    }
  }
}

TEST(PlannerParameters, ReadFromTheScenarioWithNamedErrors) {
  test::TempDir dir;
  std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const Scenario plain = Scenario::load(dir.write("a.yaml", text));
  EXPECT_EQ(plannerParameters(plain).max_nodes, PlannerParameters().max_nodes);
  const Scenario tuned =
      Scenario::load(dir.write("b.yaml", text + "planner: {max_nodes: 77, box_half_sizes: [0.1, 0.2, 0.3], guide_joint_weight: 0.1, "
                                             "depth_weight: 0.02, failure_memory: false, failure_memory_distance: 0.1, "
                                             "failure_memory_angle: 0.5, posture_linear_solver: mumps, "
                                             "posture_lbfgs_in_kkt: true, alternative_step: 0.05, "
                                             "posture_stop_at_restoration: false, posture_mu_oracle: probing, "
                                             "posture_distance_engine: convex, posture_pyramid_edges: 8, "
                                             "posture_support_inset: 0.02, posture_friction_share: 0.8, "
                                             "posture_support_inset_y: 0.03, swing_check: false}\n"));
  const PlannerParameters p = plannerParameters(tuned);
  EXPECT_EQ(p.max_nodes, 77);
  EXPECT_DOUBLE_EQ(p.box.y, 0.2);
  EXPECT_DOUBLE_EQ(p.guide_joint_weight, 0.1);
  EXPECT_DOUBLE_EQ(p.depth_weight, 0.02);
  EXPECT_FALSE(p.failure_memory);
  EXPECT_DOUBLE_EQ(p.failure_memory_distance, 0.1);
  EXPECT_DOUBLE_EQ(p.failure_memory_angle, 0.5);
  EXPECT_EQ(p.posture.linear_solver, "mumps");
  EXPECT_EQ(plannerParameters(plain).posture.linear_solver, "ldl");
  EXPECT_TRUE(p.posture.lbfgs_in_kkt);
  EXPECT_FALSE(plannerParameters(plain).posture.lbfgs_in_kkt);  // the planner's default (contact_planner.cpp)
  EXPECT_TRUE(plannerParameters(plain).failure_memory);
  EXPECT_FALSE(p.swing_check);
  EXPECT_TRUE(plannerParameters(plain).swing_check);
  EXPECT_DOUBLE_EQ(p.alternative_step, 0.05);
  EXPECT_FALSE(p.posture.stop_at_restoration);
  EXPECT_TRUE(plannerParameters(plain).posture.stop_at_restoration);  // the planner's default
  EXPECT_EQ(p.posture.mu_oracle, "probing");
  EXPECT_EQ(plannerParameters(plain).posture.mu_oracle, "quality-function");
  EXPECT_EQ(p.posture.distance_engine, DistanceEngine::Convex);
  EXPECT_EQ(plannerParameters(plain).posture.distance_engine, DistanceEngine::Fcl);  // the planner's default
  EXPECT_EQ(p.posture.problem.pyramid_sides, 8);
  EXPECT_EQ(plannerParameters(plain).posture.problem.pyramid_sides, 4);  // the planner's default
  EXPECT_DOUBLE_EQ(p.posture.problem.support_inset, 0.02);
  EXPECT_DOUBLE_EQ(p.posture.problem.friction_share, 0.8);
  EXPECT_DOUBLE_EQ(p.posture.problem.support_inset_y, 0.03);
  EXPECT_LT(plannerParameters(plain).posture.problem.support_inset_y, 0.0);  // as support_inset
  EXPECT_EQ(plannerParameters(plain).posture.problem.support_inset, 0.0);  // no margins unless asked
  EXPECT_EQ(plannerParameters(plain).posture.problem.friction_share, 1.0);
  for (const auto& [bad, field] : std::vector<std::pair<std::string, std::string>>{
           {"planner: {max_nodes: 0}\n", "planner.max_nodes"},
           {"planner: {max_node: 5}\n", "planner.max_node"},
           {"planner: {box_half_sizes: [0.1, -1, 0.3]}\n", "planner.box_half_sizes"},
           {"planner: {depth_weight: -1}\n", "planner.depth_weight"},
           {"planner: {alternative_step: -0.1}\n", "planner.alternative_step"},
           {"planner: {posture_stop_at_restoration: often}\n", "planner.posture_stop_at_restoration"},
           {"planner: {guide_joint_weight: 0}\n", "planner.guide_joint_weight"},
           {"planner: {failure_memory_distance: -0.1}\n", "planner.failure_memory_distance"},
           {"planner: {failure_memory: maybe}\n", "planner.failure_memory"},
           {"planner: {posture_linear_solver: pardiso}\n", "planner.posture_linear_solver"},
           {"planner: {posture_lbfgs_in_kkt: sometimes}\n", "planner.posture_lbfgs_in_kkt"},
           {"planner: {posture_mu_oracle: fast}\n", "planner.posture_mu_oracle"},
           {"planner: {posture_distance_engine: bullet}\n", "planner.posture_distance_engine"},
           {"planner: {posture_pyramid_edges: 6}\n", "planner.posture_pyramid_edges"},
           {"planner: {posture_support_inset: -0.01}\n", "planner.posture_support_inset"},
           {"planner: {zmp_shift_cap: 0.2}\n", "planner.zmp_shift_cap"},
           {"planner: {transition_mu_oracle: fast}\n", "planner.transition_mu_oracle"},
           {"planner: {portfolio: [{transition_mu_oracle: probing}, {}]}\n", "planner.portfolio[0].transition_mu_oracle"},
           {"planner: {posture_friction_share: 1.2}\n", "planner.posture_friction_share"},
           {"planner: {posture_support_inset_y: -0.02}\n", "planner.posture_support_inset_y"},
           {"planner: {posture_friction_share: 0}\n", "planner.posture_friction_share"}}) {
    const Scenario sc = Scenario::load(dir.write("c.yaml", text + bad));
    try {
      plannerParameters(sc);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const FormatError& e) {
      EXPECT_EQ(e.field(), field) << e.what();
    }
  }
}

// --set KEY=VALUE (acyclic-planner, bench_sensitivity): a planner key given
// on the command line acts as the scenario's own, over it; null drops the
// scenario's; a bad one is named as coming from --set, and nothing is set.
TEST(PlannerParameters, CommandLineSettingsActAsTheScenariosKeysAndAreNamedWhenBad) {
  test::TempDir dir;
  const std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const std::string path = dir.write(
      "a.yaml", text + "planner: {max_nodes: 77, portfolio: [{name: a}, {name: b, posture_mu_oracle: probing}]}\n");
  Scenario sc = Scenario::load(path);
  setPlannerKeys(sc, {"duplicate_distance=0.07"});
  PlannerParameters p = plannerParameters(sc);
  EXPECT_DOUBLE_EQ(p.duplicate_distance, 0.07);
  EXPECT_EQ(p.max_nodes, 77);  // the scenario's other keys kept
  EXPECT_EQ(p.portfolio.size(), 2u);
  setPlannerKeys(sc, {"max_nodes=88", "posture_distance_engine=convex", "box_half_sizes=[0.1, 0.2, 0.3]",
                      "portfolio=null", "posture_lbfgs_in_kkt=true"});
  p = plannerParameters(sc);
  EXPECT_EQ(p.max_nodes, 88);
  EXPECT_EQ(p.posture.distance_engine, DistanceEngine::Convex);
  EXPECT_DOUBLE_EQ(p.box.y, 0.2);
  EXPECT_TRUE(p.portfolio.empty());
  EXPECT_TRUE(p.posture.lbfgs_in_kkt);
  EXPECT_DOUBLE_EQ(p.duplicate_distance, 0.07);  // from the first call
  // A scenario without a planner section gets one.
  Scenario plain = Scenario::load(dir.write("b.yaml", text));
  ASSERT_FALSE(plain.planner_section);
  setPlannerKeys(plain, {"max_seconds=5"});
  EXPECT_DOUBLE_EQ(plannerParameters(plain).max_seconds, 5);
  // Bad settings: named as --set's, and none of the list is applied.
  for (const auto& [bad, field] : std::vector<std::pair<std::string, std::string>>{
           {"max_nodes=0", "planner.max_nodes"},
           {"max_node=5", "planner.max_node"},
           {"posture_mu_oracle=fast", "planner.posture_mu_oracle"},
           {"portfolio=[{name: a}]", "planner.portfolio"},
           {"max_nodes=[1", "planner.max_nodes"},
           {"max_nodes", ""},
           {"max_nodes=", "planner.max_nodes"},
           {"=3", ""}}) {
    try {
      setPlannerKeys(sc, {"max_nodes=99", bad});
      ADD_FAILURE() << "accepted " << bad;
    } catch (const FormatError& e) {
      EXPECT_EQ(e.file(), "--set") << e.what();
      EXPECT_EQ(e.field(), field) << e.what();
    }
    EXPECT_EQ(plannerParameters(sc).max_nodes, 88) << bad;
    EXPECT_THROW(checkPlannerSettings({bad}), FormatError) << bad;
  }
  EXPECT_NO_THROW(checkPlannerSettings({"portfolio=null", "max_nodes=5"}));
}

// Lazy verification (PlannerParameters::verify_transitions): a plan whose
// transition the verifier refuses is not returned; the stance that
// transition leads to is dropped with its subtree and the search goes on to
// another plan, which the verifier sees too. Here a verifier that refuses
// the first plan's transition into its second stance.
TEST(ContactPlanner, APlanWhoseTransitionTheVerifierRefusesIsDroppedAndTheSearchGoesOn) {
  const Scenario& sc = step();
  const PlanningResult plain = ContactPlanner(sc).plan();
  ASSERT_TRUE(plain.solved()) << plain.reason;
  ASSERT_GE(plain.plan.stances.size(), 3u);
  const Configuration refused = plain.plan.stances[1].configuration;
  auto same = [](const Configuration& a, const Configuration& b) {
    return a.base_position == b.base_position && a.joints == b.joints;
  };
  PlannerParameters p;
  p.verify_transitions = true;
  std::vector<Plan> seen;
  p.verify_plan = [&](const Plan& plan, const std::atomic<bool>&) {
    seen.push_back(plan);
    PlanVerdict v;
    v.transitions = static_cast<int>(plan.stances.size()) - 1;
    for (std::size_t k = 1; k < plan.stances.size(); ++k)
      if (same(plan.stances[k].configuration, refused)) {
        v.failed_from = static_cast<int>(k) - 1, v.failed_to = static_cast<int>(k);
        v.reason = "refused by the test";
        break;
      }
    return v;
  };
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  expectValidPlan(sc, r.plan);
  ASSERT_GE(seen.size(), 2u);
  EXPECT_EQ(seen.front().stances.size(), plain.plan.stances.size());  // the plain search's plan, first
  EXPECT_EQ(r.stats.plans_verified, static_cast<long>(seen.size()));
  EXPECT_EQ(r.stats.plans_refused, static_cast<long>(seen.size()) - 1);
  // Each refusal reported with its transition and the verifier's reason.
  ASSERT_EQ(r.refusals.size(), seen.size() - 1);
  for (const auto& why : r.refusals) {
    EXPECT_EQ(why.rfind("stances ", 0), 0u) << why;
    EXPECT_NE(why.find("refused by the test"), std::string::npos) << why;
  }
  for (const auto& st : r.plan.stances) EXPECT_FALSE(same(st.configuration, refused));
  EXPECT_GT(r.stats.nodes_generated, plain.stats.nodes_generated);
  EXPECT_TRUE(r.refused_plans.empty());  // kept only when asked
  // Kept when asked (acyclic-planner --keep-refused): each plan as the
  // verifier saw it, written whole and as its failing piece, which reads
  // back as the two stances of the refused transition.
  seen.clear();
  PlannerParameters keep = p;
  keep.keep_refused_plans = true;
  const PlanningResult k = ContactPlanner(sc, keep).plan();
  ASSERT_TRUE(k.solved());
  ASSERT_EQ(k.refused_plans.size(), k.refusals.size());
  ASSERT_FALSE(k.refused_plans.empty());
  const RefusedPlan& first = k.refused_plans.front();
  EXPECT_EQ(first.plan.stances.size(), seen.front().stances.size());
  EXPECT_EQ(first.reason, "refused by the test");
  EXPECT_EQ(first.failed_to, first.failed_from + 1);
  EXPECT_TRUE(same(first.plan.stances[static_cast<std::size_t>(first.failed_to)].configuration, refused));
  test::TempDir dir;
  const std::vector<std::string> files = writeRefusedPlans(k, sc, dir.path());
  ASSERT_EQ(files.size(), 2 * k.refused_plans.size());
  EXPECT_EQ(readPlan(files[0], sc).stances.size(), first.plan.stances.size());
  const Plan piece = readPlan(files[1], sc);
  ASSERT_EQ(piece.stances.size(), 2u);
  EXPECT_NE(files[1].find("_stances_" + std::to_string(first.failed_from) + "-" + std::to_string(first.failed_to)),
            std::string::npos) << files[1];
  EXPECT_TRUE(same(piece.stances[1].configuration, refused));
  EXPECT_NEAR((piece.stances[0].configuration.base_position -
               first.plan.stances[static_cast<std::size_t>(first.failed_from)].configuration.base_position).norm(),
              0.0, 1e-9);
  // The same search again: the same plan (the verifier's verdicts are a function of the plan).
  seen.clear();
  const PlanningResult again = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(again.solved());
  ASSERT_EQ(again.plan.stances.size(), r.plan.stances.size());
  for (std::size_t k = 0; k < r.plan.stances.size(); ++k)
    EXPECT_TRUE(same(again.plan.stances[k].configuration, r.plan.stances[k].configuration)) << k;
}

// Verification on expansion (PlannerParameters::verify_on_expansion): the
// transitions into a node are verified before any son is built on it, so a
// refused stance costs no subtree: with the verifier of the test above
// refusing the plain plan's second stance, the refused node is never
// expanded, no plan reaching the goal is refused, and fewer nodes are
// generated than when the refusal waits for a plan through that stance.
TEST(ContactPlanner, VerificationOnExpansionDropsARefusedStanceBeforeBuildingOnIt) {
  const Scenario& sc = step();
  const PlanningResult plain = ContactPlanner(sc).plan();
  ASSERT_TRUE(plain.solved()) << plain.reason;
  ASSERT_GE(plain.plan.stances.size(), 3u);
  const Configuration refused = plain.plan.stances[1].configuration;
  auto same = [](const Configuration& a, const Configuration& b) {
    return a.base_position == b.base_position && a.joints == b.joints;
  };
  long calls = 0;
  std::size_t longest = 0;
  PlannerParameters p;
  p.verify_transitions = true;
  p.verify_plan = [&](const Plan& plan, const std::atomic<bool>&) {
    ++calls;
    longest = std::max(longest, plan.stances.size());
    PlanVerdict v;
    v.transitions = static_cast<int>(plan.stances.size()) - 1;
    for (std::size_t k = 1; k < plan.stances.size(); ++k)
      if (same(plan.stances[k].configuration, refused)) {
        v.failed_from = static_cast<int>(k) - 1, v.failed_to = static_cast<int>(k);
        v.reason = "refused by the test";
        break;
      }
    return v;
  };
  const PlanningResult lazy = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(lazy.solved()) << lazy.reason;
  ASSERT_GE(lazy.stats.plans_refused, 1);
  EXPECT_EQ(lazy.stats.nodes_verified, 0);

  PlannerParameters e = p;
  e.verify_on_expansion = true;
  calls = 0;
  std::vector<std::string> trace;
  e.trace = [&](const std::string& line) { trace.push_back(line); };
  const PlanningResult r = ContactPlanner(sc, e).plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  expectValidPlan(sc, r.plan);
  for (const auto& st : r.plan.stances) EXPECT_FALSE(same(st.configuration, refused));
  EXPECT_EQ(r.stats.plans_refused, 0);  // the refusal came before any plan through it
  EXPECT_TRUE(r.refusals.empty());
  EXPECT_EQ(r.stats.plans_verified, 1);  // the goal's plan
  EXPECT_GE(r.stats.nodes_refused, 1);
  EXPECT_GE(calls, r.stats.nodes_verified + r.stats.plans_verified);  // and a settled stance's next witnesses
  EXPECT_LT(r.stats.nodes_generated, lazy.stats.nodes_generated);
  // The refused stances' nodes were never expanded: no "expand #N" line of
  // the trace names a node a "verification: ... node N dropped" line names.
  std::vector<std::string> dropped;
  for (const auto& line : trace) {
    const auto at = line.rfind(" node ");
    if (line.rfind("verification: stances", 0) == 0 && at != std::string::npos && line.find(" dropped") != std::string::npos)
      dropped.push_back("expand #" + line.substr(at + 6, line.find(" dropped") - at - 6) + " ");
  }
  EXPECT_EQ(dropped.size(), static_cast<std::size_t>(r.stats.nodes_refused));
  for (const auto& line : trace)
    for (const auto& d : dropped) EXPECT_NE(line.rfind(d, 0), 0u) << line;
}

// A verifier that runs past the time budget is stopped, and the search
// says a plan was found but not verified, instead of returning it.
TEST(ContactPlanner, AVerificationPastTheTimeBudgetIsStoppedWithTheReason) {
  PlannerParameters p;
  p.verify_transitions = true;
  p.max_seconds = 5.0;  // the search alone takes well under a second
  p.verify_plan = [](const Plan&, const std::atomic<bool>& stop) {
    while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    PlanVerdict v;
    v.stopped = true;
    return v;
  };
  const PlanningResult r = ContactPlanner(step(), p).plan();
  EXPECT_EQ(r.status, PlanningResult::Status::TimeLimit) << r.reason;
  EXPECT_NE(r.reason.find("not all verified"), std::string::npos) << r.reason;
  EXPECT_TRUE(r.plan.stances.empty());
  // Asking for verification without a verifier is a misuse.
  PlannerParameters none;
  none.verify_transitions = true;
  EXPECT_THROW(ContactPlanner(step(), none), std::invalid_argument);
}

// A transition refused into a stance where a removal settles before an
// addition (a foot lifted, before it lands) first gets that stance's next
// witness candidate: the same path through the tree, exported again with
// another witness there, and no node dropped.
TEST(ContactPlanner, ARefusedTransitionIntoASettledStanceGetsItsNextWitnessFirst) {
  const Scenario& sc = step();
  const PlanningResult plain = ContactPlanner(sc).plan();
  ASSERT_TRUE(plain.solved()) << plain.reason;
  // step_forward: the start, a foot touching but no longer supporting (a
  // removal), that foot gone (its settled stance, before the foot lands)...
  ASSERT_GE(plain.plan.stances.size(), 4u);
  ASSERT_EQ(plain.plan.stances[1].contacts.size(), 2u);
  ASSERT_EQ(plain.plan.stances[2].contacts.size(), 1u);
  const Configuration first = plain.plan.stances[2].configuration;
  PlannerParameters p;
  p.verify_transitions = true;
  std::vector<Plan> seen;
  p.verify_plan = [&](const Plan& plan, const std::atomic<bool>&) {
    seen.push_back(plan);
    PlanVerdict v;
    if (plan.stances[2].configuration.joints == first.joints) {
      v.failed_from = 1, v.failed_to = 2;
      v.reason = "refused by the test";
    }
    return v;
  };
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  expectValidPlan(sc, r.plan);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(r.stats.plans_refused, 1);
  EXPECT_EQ(r.stats.nodes_generated, plain.stats.nodes_generated);  // nothing dropped, nothing searched anew
  ASSERT_EQ(r.plan.stances.size(), plain.plan.stances.size());
  EXPECT_NE(r.plan.stances[2].configuration.joints, first.joints);
  for (std::size_t k = 0; k < r.plan.stances.size(); ++k) {
    if (k == 2) continue;
    EXPECT_EQ(r.plan.stances[k].configuration.joints, plain.plan.stances[k].configuration.joints) << k;
  }
}

// Getting down on all fours (crawl_under_table's first five key postures,
// the goal: both knees and both palms on the floor, supporting): the
// planner gets HRP-2 from standing onto its knees and palms, every stance
// valid, an added contact that fails from the parent's limb tried again
// from the limb as the key posture with that contact holds it
// (guide_limb_guess), and some are made only so.
TEST(ContactPlanner, HRP2GetsDownOnAllFoursFromStanding) {
  test::TempDir dir;
  std::string text = test::scenarioText("models/scenarios/crawl_under_table.yaml");
  const std::string goal = "goal: {link: WAIST, axis: x, min: 1.0}";
  ASSERT_NE(text.find(goal), std::string::npos);
  text.replace(text.find(goal), goal.size(),
               "goal: {link: WAIST, axis: x, min: -1.0, supported_by: [r_knee, l_knee, r_palm, l_palm]}");
  const std::size_t last_key = text.find("  # 6. on all fours");
  const std::size_t planner = text.find("\nplanner:");
  ASSERT_NE(last_key, std::string::npos);
  ASSERT_NE(planner, std::string::npos);
  text = text.substr(0, last_key) + "\nplanner: {guide_limb_guess: true, max_nodes: 2000}\n";
  const Scenario sc = Scenario::load(dir.write("kneel.yaml", text));
  const PlanningResult r = ContactPlanner(sc, plannerParameters(sc)).plan();
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.reason;
  expectValidPlan(sc, r.plan);
  std::set<std::string> supporting;
  for (const auto& c : r.plan.stances.back().contacts)
    if (c.spec.supporting) supporting.insert(sc.robot->spots()[c.spec.spot].name);
  EXPECT_EQ(supporting, (std::set<std::string>{"l_knee", "l_palm", "r_knee", "r_palm"}));
  EXPECT_GT(r.stats.limb_retry_successes, 0);
  EXPECT_LE(r.stats.limb_retry_successes, r.stats.limb_retries);
}
