// The trajectory interpolator: the moving body's path, the time law,
// and whole interpolations of small plans built here with the posture
// generator (a foot step on the floor, a hand reaching the table and leaving
// it, a step over a box that forces a repair), each output checked sample by
// sample by the independent trajectory check.
#include <gtest/gtest.h>

#include <filesystem>

#include <algorithm>

#include <atomic>
#include <cmath>
#include <functional>
#include <utility>

#include "interpolator/body_path.h"
#include "interpolator/body_path_planner.h"
#include "interpolator/interpolator.h"
#include "interpolator/plan_verifier.h"
#include "interpolator/transition_memo.h"
#include "interpolator/limb_path_planner.h"
#include "interpolator/time_law.h"
#include "planner/check/trajectory_check.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& floorScenario() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  return sc;
}
const Scenario& boxScenario() {
  static Scenario sc = Scenario::load(test::sourcePath("tests/data/step_over_box.yaml"));
  return sc;
}
const Scenario& chairScenario() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

const Scenario& paperChairScenario() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_paper.yaml"));
  return sc;
}

// The chair scene as it was before its seat was lowered (seat at knee-pit
// height, thigh spots mid-thigh), kept for the fixture plan made in it.
const Scenario& kneePitChairScenario() {
  static Scenario sc = Scenario::load(test::sourcePath("tests/data/chair_knee_pit.yaml"));
  return sc;
}

PlanStance stance(const std::vector<ContactSpec>& contacts, const Configuration& q) {
  PlanStance s;
  for (const auto& c : contacts) {
    PlanContact pc;
    pc.spec = c;
    s.contacts.push_back(pc);
  }
  s.configuration = q;
  return s;
}

Configuration witness(const Scenario& sc, const std::vector<ContactSpec>& contacts, const Configuration& guess) {
  PostureGenerator pg(sc.robot, sc.scene);
  PostureRequest r;
  r.contacts = contacts;
  r.initial_guess = guess;
  const PostureResult res = pg.solve(r);
  EXPECT_TRUE(res.success()) << res.reason;
  return res.configuration;
}

// A plan of one right-foot step of `length` metres, as the contact planner
// writes one: both feet; the right foot unloaded; the left foot alone (settled);
// the right foot touching ahead; both feet supporting.
Plan stepPlan(const Scenario& sc, double length) {
  const Configuration q0 = sc.start;
  const int ri = sc.start_stance[0].spot == sc.robot->spotIndex("r_sole") ? 0 : 1;
  const ContactSpec r0 = sc.start_stance[ri], l = sc.start_stance[1 - ri];
  ContactSpec r0_free = r0, r1 = r0, r1_free = r0;
  r1.placement.x += length;
  r1_free.placement.x += length;
  r0_free.supporting = r1_free.supporting = false;
  const Configuration q1 = witness(sc, {r0_free, l}, q0);
  Configuration guess = q1;
  guess.base_position.x() += 0.5 * length;
  const Configuration q3 = witness(sc, {l, r1_free}, guess);
  const Configuration q2 = witness(sc, {l}, q3);
  Plan p;
  p.scenario = sc.path;
  p.stances = {stance({r0, l}, q0), stance({r0_free, l}, q1), stance({l}, q2), stance({l, r1_free}, q3),
               stance({l, r1}, q3)};
  return p;
}

// The chair's start stance; the left wrist touching the table; back to the start stance.
Plan handPlan() {
  const Scenario& sc = chairScenario();
  PostureGenerator pg(sc.robot, sc.scene);
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  FloatingContact f;
  f.spot = sc.robot->spotIndex("l_palm");
  f.surface = sc.scene->surfaceIndex("table_top");
  f.volume.polygon = sc.scene->surfaces()[f.surface].polygon;
  r.floating = f;
  const PostureResult res = pg.solve(r);
  EXPECT_TRUE(res.success()) << res.reason;
  std::vector<ContactSpec> touching = sc.start_stance;
  ContactSpec w;
  w.spot = f.spot;
  w.surface = f.surface;
  w.supporting = false;
  w.placement = res.floating;
  touching.push_back(w);
  Plan p;
  p.scenario = sc.path;
  p.stances = {stance(sc.start_stance, sc.start), stance(touching, res.configuration), stance(sc.start_stance, sc.start)};
  return p;
}

void expectValid(const Trajectory& tr, const Scenario& sc) {
  ValidityChecker checker(sc.robot, sc.scene);
  const TrajectoryReport rep = checkTrajectory(tr, sc, checker);
  for (const auto& p : rep.parts)
    EXPECT_TRUE(p.ok()) << p.name << ": " << p.summary << (p.violations.empty() ? "" : " | " + p.violations[0]);
  EXPECT_EQ(rep.invalid_samples, 0);
}

Eigen::Isometry3d spotAt(const Scenario& sc, const Configuration& q, int spot) {
  Kinematics k(sc.robot);
  k.setConfiguration(q);
  return k.spotPose(spot);
}

// The least distance, along a limb's joint path (the rest of the body on
// the witnesses' interpolation at its progress, `samples` points), of the
// pairs the limb's links make with the obstacles and the robot's other links.
double limbClearanceAlong(const Scenario& sc, const CollisionModel& collisions, Kinematics& kin, int root,
                          const LimbJointPath& path, const Configuration& q0, const Configuration& q1, int samples) {
  double worst = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= samples; ++i) {
    const double s = static_cast<double>(i) / samples;
    kin.setConfiguration(path.apply(lerp(q0, q1, s), s));
    for (const auto& d : collisions.distances(kin))
      if (sc.robot->jointMovesLink(root, collisions.pairs()[d.pair].link_a) !=
          (collisions.pairs()[d.pair].kind == CollisionPair::Kind::Self &&
           sc.robot->jointMovesLink(root, collisions.pairs()[d.pair].link_b)))
        worst = std::min(worst, d.distance);
  }
  return worst;
}

}  // namespace

// --- The moving body's path ---------------------------------------------------

TEST(BodyPath, LeavesAndArrivesAlongTheNormalsAndIsC1) {
  BodyPathEnd a, b;
  a.pose.translation() = Eigen::Vector3d(0, 0, 0);
  a.normal = Eigen::Vector3d::UnitZ();
  b.pose.translation() = Eigen::Vector3d(0.3, 0.1, 0.2);
  b.pose.linear() = Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.normal = Eigen::Vector3d(0, 0, 1);
  const BodyPath p(a, b, 0.03);
  EXPECT_LT((p.pose(0).translation() - a.pose.translation()).norm(), 1e-12);
  EXPECT_LT((p.pose(1).translation() - b.pose.translation()).norm(), 1e-12);
  EXPECT_LT(Eigen::AngleAxisd(p.pose(1).linear().transpose() * b.pose.linear()).angle(), 1e-9);
  // Straight up, orientation held, over the first 3 cm of arc length; straight down over the last.
  const double L = p.length();
  for (double d : {0.0, 0.01, 0.029}) {
    const Eigen::Isometry3d T = p.pose(d / L);
    EXPECT_NEAR(T.translation().z(), d, 1e-9);
    EXPECT_NEAR(T.translation().head<2>().norm(), 0, 1e-9);
    EXPECT_LT(Eigen::AngleAxisd(T.linear()).angle(), 1e-12);
    const Eigen::Isometry3d E = p.pose(1 - d / L);
    EXPECT_NEAR((E.translation() - b.pose.translation() - Eigen::Vector3d(0, 0, d)).norm(), 0, 1e-9);
  }
  EXPECT_NEAR(p.leaveParameter(5e-4) * L, 5e-4, 1e-12);
  EXPECT_NEAR((1 - p.arriveParameter(5e-4)) * L, 5e-4, 1e-12);
  // Arc length: equal steps of s move the body equal distances (within the table's resolution).
  const int n = 400;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = p.pose((i + 1.0) / n).translation() - p.pose(static_cast<double>(i) / n).translation();
    EXPECT_NEAR(d.norm(), L / n, 0.03 * L / n) << i;
    sum += d.norm();
  }
  EXPECT_NEAR(sum, L, 1e-3 * L);
  // C1: no corner where the straight parts meet the spline (a corner would turn by about 90 degrees).
  for (double j : {0.03, L - 0.03}) {
    const double e = 1e-5;
    const Eigen::Vector3d before = p.pose(j / L).translation() - p.pose((j - e) / L).translation();
    const Eigen::Vector3d after = p.pose((j + e) / L).translation() - p.pose(j / L).translation();
    EXPECT_GT(before.normalized().dot(after.normalized()), std::cos(0.02)) << "junction at " << j;
  }
}

TEST(BodyPath, RaisedPathPassesHigher) {
  BodyPathEnd a, b;
  a.normal = b.normal = Eigen::Vector3d::UnitZ();
  b.pose.translation() = Eigen::Vector3d(0.25, 0, 0);
  b.pose.translation().z() = 0.1;  // the far end higher
  const BodyPath p(a, b, 0.03), r = p.raised(0.1);
  // The bridge crosses 0.1 m above the higher end's straight part.
  EXPECT_NEAR(r.pose(0.5).translation().z(), 0.23, 0.01);
  EXPECT_LT(p.pose(0.5).translation().z(), 0.13);
  EXPECT_LT((r.pose(1).translation() - b.pose.translation()).norm(), 1e-12);
}

TEST(BodyPath, DetoursPassBeside) {
  BodyPathEnd a, b;
  a.normal = b.normal = Eigen::Vector3d::UnitZ();
  b.pose.translation() = Eigen::Vector3d(0.3, 0, 0);
  const BodyPath p(a, b, 0.03);
  // The chord runs along x: left is +y. Both stay at the straight parts' height.
  const BodyPath left = p.bridged(0, 0.1), right = p.bridged(0, -0.1);
  ASSERT_EQ(left.vias().size(), 2u);
  for (const auto& v : left.vias()) {
    EXPECT_NEAR(v.y(), 0.1, 1e-12);
    EXPECT_NEAR(v.z(), 0.03, 1e-12);
  }
  for (const auto& v : right.vias()) EXPECT_NEAR(v.y(), -0.1, 1e-12);
  EXPECT_GT(left.pose(0.5).translation().y(), 0.09);
  // One via-point a quarter of the way: the body turns aside early, then comes back.
  const BodyPath early = p.detoured(0.25, -0.1);
  ASSERT_EQ(early.vias().size(), 1u);
  EXPECT_LT((early.vias()[0] - Eigen::Vector3d(0.075, -0.1, 0.03)).norm(), 1e-12);
  double y_min = 0, x_at_min = 0;
  for (int i = 0; i <= 200; ++i) {
    const Eigen::Vector3d q = early.pose(i / 200.0).translation();
    if (q.y() < y_min) y_min = q.y(), x_at_min = q.x();
  }
  EXPECT_LT(y_min, -0.095);
  EXPECT_LT(x_at_min, 0.15);
  // The ends are the witnesses' poses, whatever the detour.
  EXPECT_LT((early.pose(1).translation() - b.pose.translation()).norm(), 1e-12);
  EXPECT_LT(early.pose(0).translation().norm(), 1e-12);
}

TEST(BodyPath, ThroughWaypointsPassesEachWithItsOrientation) {
  BodyPathEnd a, b;
  a.normal = b.normal = Eigen::Vector3d::UnitZ();
  b.pose.translation() = Eigen::Vector3d(0.4, 0, 0);
  b.pose.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const BodyPath p(a, b, 0.03);
  std::vector<Eigen::Isometry3d> w(2, Eigen::Isometry3d::Identity());
  w[0].translation() = Eigen::Vector3d(0.1, 0.1, 0.1);
  w[0].linear() = Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  w[1].translation() = Eigen::Vector3d(0.3, 0.1, 0.1);
  w[1].linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const BodyPath t = p.through(w);
  ASSERT_EQ(t.vias().size(), 2u);
  // The straight parts and the ends are the designed path's.
  EXPECT_LT((t.pose(0).translation() - a.pose.translation()).norm(), 1e-12);
  EXPECT_LT((t.pose(1).translation() - b.pose.translation()).norm(), 1e-12);
  EXPECT_LT((t.splineStart().translation() - Eigen::Vector3d(0, 0, 0.03)).norm(), 1e-12);
  EXPECT_LT((t.splineEnd().translation() - Eigen::Vector3d(0.4, 0, 0.03)).norm(), 1e-12);
  // Where the path passes each waypoint, the body has the waypoint's orientation
  // (not the ends' slerp: -0.4 rad lies outside [0, 0.2]); between samples it turns little.
  const int n = 2000;
  std::vector<double> nearest(2, 1e9), angle_there(2, 1e9);
  double largest_turn = 0;
  for (int i = 0; i <= n; ++i) {
    const Eigen::Isometry3d T = t.pose(static_cast<double>(i) / n);
    if (i > 0)
      largest_turn = std::max(largest_turn, Eigen::AngleAxisd(T.linear().transpose() * t.pose((i - 1.0) / n).linear()).angle());
    for (int k = 0; k < 2; ++k) {
      const double d = (T.translation() - w[k].translation()).norm();
      if (d < nearest[k]) nearest[k] = d, angle_there[k] = Eigen::AngleAxisd(T.linear().transpose() * w[k].linear()).angle();
    }
  }
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT(nearest[k], 1e-3) << k;
    EXPECT_LT(angle_there[k], 0.01) << k;
  }
  EXPECT_LT(largest_turn, 0.01);
}

TEST(BodyPathPlanner, PlansAFootOverABoxClearOfItTheSameEachTime) {
  // The right foot stepping 0.28 m forward over the low box: the designed
  // path cuts the box; the planned one clears it by the clearance asked
  // for, and the left foot too. Without room to rise or turn aside there is
  // no path, and the reason says so.
  const Scenario& sc = boxScenario();
  const int r = sc.robot->spotIndex("r_sole"), l = sc.robot->spotIndex("l_sole");
  BodyPathEnd e0, e1;
  e0.pose = spotAt(sc, sc.start, r);
  e1.pose = e0.pose;
  e1.pose.translation().x() += 0.28;
  e0.normal = e1.normal = Eigen::Vector3d::UnitZ();
  const BodyPath designed(e0, e1, 0.03);
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  std::vector<PlacedShape> held;
  const int left_foot = sc.robot->spots()[l].link;
  for (const auto& shape : sc.robot->links()[left_foot].shapes) held.push_back({&shape, k.linkPose(left_foot) * shape.pose});
  EXPECT_LT(sweepClearance(designed, *sc.robot, *sc.scene, r, held), 0.0);
  BodyPathPlanOptions o;
  const BodyPathPlan p = planBodyPath(designed, *sc.robot, *sc.scene, r, held, o);
  ASSERT_TRUE(p.path) << p.reason;
  EXPECT_FALSE(p.path->vias().empty());
  EXPECT_GE(sweepClearance(*p.path, *sc.robot, *sc.scene, r, held), 0.5 * o.clearance);
  EXPECT_LT((p.path->pose(1).translation() - e1.pose.translation()).norm(), 1e-12);
  const BodyPathPlan again = planBodyPath(designed, *sc.robot, *sc.scene, r, held, o);
  ASSERT_TRUE(again.path);
  ASSERT_EQ(again.path->vias().size(), p.path->vias().size());
  for (std::size_t i = 0; i < p.path->vias().size(); ++i) EXPECT_EQ(again.path->vias()[i], p.path->vias()[i]) << i;
  o.room = 0;
  o.rise = 0;
  o.max_checks = 2000;
  const BodyPathPlan none = planBodyPath(designed, *sc.robot, *sc.scene, r, held, o);
  EXPECT_FALSE(none.path);
  EXPECT_NE(none.reason.find("no path"), std::string::npos) << none.reason;
}

namespace {
// The chair plan's free left arm going over the table's edge
// (tests/data/chair_ompl_arm_over_edge.plan.json), with what a limb planner
// needs there: the collision model, a Kinematics and the arm's root joint.
class ArmOverEdge : public ::testing::Test {
 protected:
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_ompl_arm_over_edge.plan.json"), sc);
  const CollisionModel collisions{sc.robot, sc.scene};
  Kinematics kin{sc.robot};
  const int root = sc.robot->spotLimbRootJoint(sc.robot->spotIndex("l_palm"));
};
}  // namespace

TEST_F(ArmOverEdge, TheLimbPlannerTakesTheArmOverTheEdgeWithTheBodysProgressTheSameEachTime) {
  // From a plan of the chair with its OMPL guide: on the left foot, the
  // right foot stepping, the free left hand goes from hanging in front of the
  // table's edge, below its top, to resting over the top. Its joints'
  // interpolation sweeps the forearm through the edge; the planned path,
  // with the body on the witnesses' interpolation at its progress, clears it.
  ASSERT_EQ(plan.stances.size(), 2u);
  const Configuration& q0 = plan.stances[0].configuration;
  const Configuration& q1 = plan.stances[1].configuration;
  const std::vector<int> joints = sc.robot->jointsMovedBy(root);
  ASSERT_EQ(joints.size(), 7u);  // LARM_JOINT0..6
  EXPECT_EQ(sc.robot->joints()[joints.front()].name, "LARM_JOINT0");
  EXPECT_LT(limbSweepClearance(collisions, kin, root, q0, q1, 0.01), -0.05);
  const LimbPathPlan p = planLimbPath(collisions, kin, root, q0, q1);
  ASSERT_TRUE(p.path) << p.reason;
  const LimbJointPath& path = *p.path;
  EXPECT_GT(path.waypoints().size(), 2u);  // not the straight line
  // Its ends are the witnesses'; its progress increases from 0 to 1.
  EXPECT_EQ(path.apply(q0, 0).joints, q0.joints);
  EXPECT_EQ(path.apply(q1, 1).joints, q1.joints);
  for (std::size_t i = 1; i < path.params().size(); ++i) EXPECT_GT(path.params()[i], path.params()[i - 1]) << i;
  // Along it, the arm clears the table and the body, where the body is at that progress.
  EXPECT_GT(limbClearanceAlong(sc, collisions, kin, root, path, q0, q1, 200), 0.0);
  // Seeded: the same path again.
  const LimbPathPlan again = planLimbPath(collisions, kin, root, q0, q1);
  ASSERT_TRUE(again.path);
  ASSERT_EQ(again.path->waypoints().size(), path.waypoints().size());
  for (std::size_t i = 0; i < path.waypoints().size(); ++i) EXPECT_EQ(again.path->waypoints()[i], path.waypoints()[i]) << i;
  // With no budget, no path, and the reason says so.
  LimbPathPlanOptions none;
  none.max_checks = 1;
  const LimbPathPlan n = planLimbPath(collisions, kin, root, q0, q1, none);
  EXPECT_FALSE(n.path);
  EXPECT_NE(n.reason.find("no path"), std::string::npos) << n.reason;
}

// A limb whose straight interpolation is clear gets it, checked before any
// search (RRTConnect grows toward random samples and missed such a path 3 mm
// clear in a narrow passage): two waypoints, the witnesses' values, even with
// no budget for OMPL.
TEST_F(ArmOverEdge, AClearStraightLimbPathIsTakenWithoutSearching) {
  const Configuration& q0 = plan.stances[0].configuration;  // the hand hanging in front of the table
  Configuration q1 = q0;
  for (int j : sc.robot->jointsMovedBy(root)) q1.joints[j] += 0.03;
  ASSERT_GT(limbSweepClearance(collisions, kin, root, q0, q1, 0.05), 0.012);
  LimbPathPlanOptions none;
  none.max_checks = 1;
  const LimbPathPlan p = planLimbPath(collisions, kin, root, q0, q1, none);
  ASSERT_TRUE(p.path) << p.reason;
  ASSERT_EQ(p.path->waypoints().size(), 2u);
  const LimbJointPath straight = straightLimbPath(*sc.robot, root, q0, q1);
  EXPECT_EQ(p.path->waypoints().front(), straight.waypoints().front());
  EXPECT_EQ(p.path->waypoints().back(), straight.waypoints().back());
  EXPECT_EQ(p.path->apply(q0, 0.5).joints, straight.apply(q0, 0.5).joints);
}

TEST(LimbPathPlanner, AForearmOnTheTableIsTouchingAtItsEndOnlyWhenToldSo) {
  // From a plan of the paper's chair: seated on the left thigh, the left
  // forearm leaves the table, and the arm hangs below the table's top in the
  // next witness. The forearm rests on the top at the first end: no path by
  // default (an end within 1 mm of an obstacle); with touching ends, one that
  // rises from the top and clears it, then the table, along the way.
  const Scenario& sc = paperChairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_paper_forearm_off_table.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  const Configuration& q0 = plan.stances[0].configuration;
  const Configuration& q1 = plan.stances[1].configuration;
  const CollisionModel collisions(sc.robot, sc.scene);
  Kinematics kin(sc.robot);
  const int root = sc.robot->spotLimbRootJoint(sc.robot->spotIndex("l_forearm"));
  EXPECT_LT(limbSweepClearance(collisions, kin, root, q0, q1, 0.01), -0.1);  // the interpolation cuts the table
  const LimbPathPlan plain = planLimbPath(collisions, kin, root, q0, q1);
  EXPECT_FALSE(plain.path);
  EXPECT_NE(plain.reason.find("within 1 mm"), std::string::npos) << plain.reason;
  LimbPathPlanOptions touching;
  touching.touching_ends = true;
  const LimbPathPlan p = planLimbPath(collisions, kin, root, q0, q1, touching);
  ASSERT_TRUE(p.path) << p.reason;
  EXPECT_GT(p.path->waypoints().size(), 2u);
  // Between its waypoints, as planned (the body at the path's own progress):
  // never into the table, nor the body, by more than the contact's 0.1 mm.
  EXPECT_GT(limbClearanceAlong(sc, collisions, kin, root, *p.path, q0, q1, 400), -2e-4);
}

TEST(LimbJointPath, InterpolatesBetweenWaypointsAtTheirProgress) {
  const LimbJointPath p({3, 5}, {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 2)}, {0, 0.25, 1});
  EXPECT_TRUE(p.at(-1).isApprox(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(p.at(0.125).isApprox(Eigen::Vector2d(0.5, 0)));
  EXPECT_TRUE(p.at(0.625).isApprox(Eigen::Vector2d(1, 1)));
  EXPECT_TRUE(p.at(2).isApprox(Eigen::Vector2d(1, 2)));
  // Without parameters, by joint-space length: 1 then 2.
  const LimbJointPath q({3, 5}, {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 2)});
  EXPECT_NEAR(q.params()[1], 1.0 / 3.0, 1e-12);
  Configuration c;
  c.joints = Eigen::VectorXd::Zero(6);
  const Configuration d = p.apply(c, 1);
  EXPECT_EQ(d.joints[3], 1);
  EXPECT_EQ(d.joints[5], 2);
  EXPECT_EQ(d.joints[4], 0);
  EXPECT_THROW(LimbJointPath({0}, {}), std::invalid_argument);
  EXPECT_THROW(LimbJointPath({0}, {Eigen::VectorXd::Zero(1)}, {0, 1}), std::invalid_argument);
}

// --- The time law -----------------------------------------------------------

namespace {
// Runs a piece at dt and returns the worst joint speed ratio (stored and
// finite-difference) and the worst link-origin speed; checks rest at both ends.
std::pair<double, double> runPiece(const Scenario& sc, const std::vector<Configuration>& knots, const TimeLawOptions& opt) {
  Kinematics kin(sc.robot);
  const TimedPiece piece(knots, *sc.robot, kin, opt);
  EXPECT_GT(piece.steps(), 0);
  EXPECT_NEAR(piece.duration(), piece.steps() * opt.dt, 1e-12);
  Eigen::VectorXd dq;
  piece.at(0, &dq);
  EXPECT_EQ(dq.norm(), 0.0);
  const Configuration end = piece.at(piece.duration(), &dq);
  EXPECT_EQ(dq.norm(), 0.0);
  EXPECT_LT((end.joints - knots.back().joints).norm() + (end.base_position - knots.back().base_position).norm(), 1e-12);
  double worst_ratio = 0, worst_speed = 0;
  Configuration prev = piece.at(0);
  std::vector<Eigen::Vector3d> prev_origins;
  kin.setConfiguration(prev);
  for (int l = 0; l < sc.robot->numLinks(); ++l) prev_origins.push_back(kin.linkPose(l).translation());
  for (int i = 1; i <= piece.steps(); ++i) {
    const Configuration q = piece.at(i * opt.dt, &dq);
    for (const auto& j : sc.robot->joints()) {
      worst_ratio = std::max(worst_ratio, std::abs(dq[j.index]) / j.velocity);
      worst_ratio = std::max(worst_ratio, std::abs(q.joints[j.index] - prev.joints[j.index]) / opt.dt / j.velocity);
    }
    kin.setConfiguration(q);
    for (int l = 0; l < sc.robot->numLinks(); ++l) {
      worst_speed = std::max(worst_speed, (kin.linkPose(l).translation() - prev_origins[l]).norm() / opt.dt);
      prev_origins[l] = kin.linkPose(l).translation();
    }
    prev = q;
  }
  return {worst_ratio, worst_speed};
}
}  // namespace

TEST(TimeLaw, RestToRestWithinTheJointVelocityLimits) {
  const Scenario& sc = floorScenario();
  Configuration a = sc.start, b = sc.start, c = sc.start;
  b.joints[sc.robot->jointIndex("RARM_JOINT0")] -= 1.2;  // a joint's long move, then another's
  c.joints = b.joints;
  c.joints[sc.robot->jointIndex("LLEG_JOINT3")] += 0.5;
  TimeLawOptions opt;
  opt.speed_cap = 100;              // out of the way
  opt.link_acceleration_cap = 1e4;  // idem
  opt.acceleration_scale = 100;     // idem
  const auto [ratio, speed] = runPiece(sc, {a, b, c}, opt);
  EXPECT_LE(ratio, opt.velocity_share + 1e-9);
  EXPECT_GT(ratio, 0.8 * opt.velocity_share);  // and not needlessly slow: the profile's peak reaches the limit
}

TEST(TimeLaw, LinkSpeedsWithinTheCap) {
  const Scenario& sc = floorScenario();
  Configuration a = sc.start, b = sc.start, c = sc.start;
  b.base_position.x() += 0.1;
  c = b;
  c.joints[sc.robot->jointIndex("RARM_JOINT0")] -= 1.0;  // the hand on an arc
  TimeLawOptions opt;
  opt.speed_cap = 0.05;
  const auto [ratio, speed] = runPiece(sc, {a, b, c}, opt);
  EXPECT_LE(ratio, opt.velocity_share + 1e-9);
  // Links move on arcs between knots (joint space is linear), measured by sub-chords.
  EXPECT_LE(speed, opt.speed_cap * 1.01);
  EXPECT_GT(speed, 0.8 * opt.speed_cap);
}

// Sampled at dt, the positions show each joint's acceleration within its
// limit, at a reversal too, and the stored velocities are their derivative.
TEST(TimeLaw, AccelerationsWithinTheLimitsVelocitiesTheDerivativeOfPositions) {
  const Scenario& sc = floorScenario();
  const int arm = sc.robot->jointIndex("RARM_JOINT0"), knee = sc.robot->jointIndex("LLEG_JOINT3");
  Configuration a = sc.start, b = sc.start, c = sc.start, d = sc.start;
  b.joints[arm] -= 0.6;
  c.joints[arm] -= 0.3;  // back along the same joint: a reversal at b
  c.joints[knee] += 0.2;
  d.joints = c.joints;
  d.joints[knee] += 0.21;  // almost straight on from c: a gentle corner
  Kinematics kin(sc.robot);
  const TimeLawOptions opt;
  const TimedPiece piece({a, b, c, d}, *sc.robot, kin, opt);
  ASSERT_GT(piece.steps(), 2);
  std::vector<Configuration> q;
  std::vector<Eigen::VectorXd> v;
  for (int i = 0; i <= piece.steps(); ++i) {
    Eigen::VectorXd dq;
    q.push_back(piece.at(i * opt.dt, &dq));
    v.push_back(dq);
  }
  double worst_accel = 0, worst_gap = 0;
  for (const auto& j : sc.robot->joints()) {
    const int k = j.index;
    for (int i = 1; i + 1 <= piece.steps(); ++i)
      worst_accel = std::max(worst_accel, std::abs(q[i + 1].joints[k] - 2 * q[i].joints[k] + q[i - 1].joints[k]) /
                                              (opt.dt * opt.dt) / j.acceleration);
    for (int i = 0; i < piece.steps(); ++i)
      worst_gap = std::max(worst_gap, std::abs((q[i + 1].joints[k] - q[i].joints[k]) / opt.dt - 0.5 * (v[i][k] + v[i + 1][k])) /
                                          (j.acceleration * opt.dt));
  }
  EXPECT_LE(worst_accel, 1.0 + 1e-9);
  EXPECT_GT(worst_accel, 0.3);  // and the limit is used, not avoided by crawling
  EXPECT_LE(worst_gap, 0.5);
  // Through the reversal the arm stops: its velocity changes sign only through (near) zero.
  for (int i = 0; i < piece.steps(); ++i)
    if (v[i][arm] * v[i + 1][arm] < 0) {
      EXPECT_LT(std::abs(v[i][arm] - v[i + 1][arm]), sc.robot->joints()[arm].acceleration * opt.dt);
    }
}

// With a ZMP shift cap, a whole-body sway (the base 10 cm sideways, the
// arms swinging) is slowed until the ZMP's shift by the links' accelerations,
// measured from the sampled positions (second differences of every link
// origin, sum_l m_l h_l |a_l| / (M g)), stays about within the cap (4 mm:
// 2.8 s instead of 1.4 s); without the cap the same sway shifts it 16.5 mm.
TEST(TimeLaw, AZmpShiftCapSlowsAWholeBodySwayUntilTheShiftIsWithinIt) {
  const Scenario& sc = floorScenario();
  const RobotModel& m = *sc.robot;
  Configuration a = sc.start, b = sc.start;
  b.base_position.y() += 0.10;
  b.joints[m.jointIndex("RARM_JOINT0")] -= 0.8;
  b.joints[m.jointIndex("LARM_JOINT0")] -= 0.8;
  Kinematics kin(sc.robot);
  auto shift = [&](const TimedPiece& piece, double dt) {
    std::vector<std::vector<Eigen::Vector3d>> o;
    for (int i = 0; i <= piece.steps(); ++i) {
      kin.setConfiguration(piece.at(i * dt));
      std::vector<Eigen::Vector3d> x;
      for (int l = 0; l < m.numLinks(); ++l) x.push_back(kin.linkPose(l).translation());
      o.push_back(x);
    }
    double lowest = std::numeric_limits<double>::infinity(), mass = 0, worst = 0;
    for (const auto& x : o.front()) lowest = std::min(lowest, x.z());
    for (const auto& l : m.links()) mass += l.mass;
    for (std::size_t i = 1; i + 1 < o.size(); ++i) {
      double s = 0;
      for (int l = 0; l < m.numLinks(); ++l)
        s += m.links()[l].mass * (o[i][l].z() - lowest) * (o[i + 1][l] - 2 * o[i][l] + o[i - 1][l]).norm() / (dt * dt);
      worst = std::max(worst, s / (mass * 9.81));
    }
    return worst;
  };
  TimeLawOptions free;
  free.speed_cap = 1.0;  // the accelerations bound it, not the speeds
  TimeLawOptions capped = free;
  capped.zmp_shift_cap = 0.004;
  const TimedPiece fast({a, b}, m, kin, free), slow({a, b}, m, kin, capped);
  const double fast_shift = shift(fast, free.dt), slow_shift = shift(slow, capped.dt);
  EXPECT_GT(slow.duration(), 1.5 * fast.duration());
  EXPECT_GT(fast_shift, 3 * capped.zmp_shift_cap);
  EXPECT_LT(slow_shift, 1.2 * capped.zmp_shift_cap);  // arcs, not chords: a little over
  EXPECT_GT(slow_shift, 0.5 * capped.zmp_shift_cap);  // and not needlessly slow
}

// A move of 2 mrad, as a support flip's, takes the time its acceleration needs:
// several samples, not one.
TEST(TimeLaw, SmallMoveTakesTheTimeItsAccelerationNeeds) {
  const Scenario& sc = floorScenario();
  const int arm = sc.robot->jointIndex("RARM_JOINT3");
  Configuration a = sc.start, b = sc.start;
  b.joints[arm] += 0.002;
  Kinematics kin(sc.robot);
  const TimeLawOptions opt;
  const TimedPiece piece({a, b}, *sc.robot, kin, opt);
  const double amax = 0.5 * sc.robot->joints()[arm].acceleration;  // the time law's share inside a segment
  EXPECT_GE(piece.duration() + 1e-12, 2 * std::sqrt(0.002 / amax));
  EXPECT_GE(piece.steps(), 5);
}

TEST(TimeLaw, MotionlessPieceTakesNoTime) {
  const Scenario& sc = floorScenario();
  Kinematics kin(sc.robot);
  const TimedPiece piece({sc.start, sc.start}, *sc.robot, kin, {});
  EXPECT_EQ(piece.steps(), 0);
}

// --- Whole interpolations ---------------------------------------------------------

TEST(Interpolator, SingleFootStepOnTheFloor) {
  const Scenario& sc = floorScenario();
  const Plan plan = stepPlan(sc, 0.15);
  InterpolatorOptions opt;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  const Trajectory& tr = r.trajectory;
  EXPECT_EQ(tr.stats.stances_in, 5);
  EXPECT_EQ(r.filtered, 0);
  EXPECT_EQ(tr.stats.transitions, 3);  // unload (fixed contacts), step (moving foot), load (no motion)
  EXPECT_EQ(tr.stats.repairs, 0);
  EXPECT_GE(tr.stats.posture_calls, opt.steps + 1);  // the step: touch knots and the n - 1 between
  expectValid(tr, sc);
  // Phases: both feet; right foot unloaded; left foot alone (stance 2); right foot touching ahead.
  ASSERT_EQ(tr.phases.size(), 4u);
  EXPECT_EQ(tr.phases[2].stance, 2);
  EXPECT_EQ(tr.phases[2].contacts.size(), 1u);
  // The foot rises straight, clears the floor by about the lift height, and lands on its new foothold.
  const int r_sole = sc.robot->spotIndex("r_sole");
  const double x0 = spotAt(sc, tr.samples.front().q, r_sole).translation().x();
  double top = 0;
  for (const auto& s : tr.samples) {
    if (s.phase != 2) continue;
    const Eigen::Isometry3d T = spotAt(sc, s.q, r_sole);
    top = std::max(top, T.translation().z());
    if (T.translation().z() < 0.02) {  // on a straight part: above one of the two footholds
      const double dx = std::min(std::abs(T.translation().x() - x0), std::abs(T.translation().x() - x0 - 0.15));
      EXPECT_LT(dx, 2e-3) << "t = " << s.t;
    }
  }
  EXPECT_GT(top, opt.lift);
  EXPECT_LT(top, opt.lift + 0.03);
  const Eigen::Isometry3d end = spotAt(sc, tr.samples.back().q, r_sole);
  EXPECT_NEAR(end.translation().x(), x0 + 0.15, 1e-3);
  EXPECT_NEAR(end.translation().z(), 0.0, 1e-3);
  // Rest at the start, the end and every phase change.
  EXPECT_EQ(tr.samples.front().dq.norm(), 0.0);
  EXPECT_EQ(tr.samples.back().dq.norm(), 0.0);
}

TEST(Interpolator, SameInputSameOutputOnAnyNumberOfThreads) {
  // Transitions are solved on worker threads and used in order: one thread,
  // two threads and a repeat give the same samples bit for bit.
  const Scenario& sc = floorScenario();
  const Plan plan = stepPlan(sc, 0.15);
  InterpolatorOptions opt;
  opt.steps = 8;
  opt.threads = 1;
  const InterpolationResult a = interpolate(plan, sc, opt);
  opt.threads = 2;
  const InterpolationResult b = interpolate(plan, sc, opt), c = interpolate(plan, sc, opt);
  ASSERT_TRUE(a.success() && b.success() && c.success());
  EXPECT_EQ(a.trajectory.stats.posture_calls, b.trajectory.stats.posture_calls);
  for (const InterpolationResult* r : {&b, &c}) {
    ASSERT_EQ(a.trajectory.samples.size(), r->trajectory.samples.size());
    ASSERT_EQ(a.trajectory.phases.size(), r->trajectory.phases.size());
    for (std::size_t i = 0; i < a.trajectory.samples.size(); ++i) {
      ASSERT_EQ(a.trajectory.samples[i].q.joints, r->trajectory.samples[i].q.joints) << i;
      ASSERT_EQ(a.trajectory.samples[i].q.base_position, r->trajectory.samples[i].q.base_position) << i;
    }
  }
}

TEST(Interpolator, HandReachesTheTableAndLeavesIt) {
  const Scenario& sc = chairScenario();
  const Plan plan = handPlan();
  InterpolatorOptions opt;
  opt.filter = false;
  opt.steps = 10;  // the behaviour, not the resolution, is under test: half the posture calls
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  const Trajectory& tr = r.trajectory;
  EXPECT_EQ(tr.stats.transitions, 2);
  // Seated, the plain spline from the hanging hand to the table top meets the table's edge.
  EXPECT_GE(tr.stats.repairs, 1);
  expectValid(tr, sc);
  // The palm touches the table in the middle phase; over the table top and
  // within 2 cm of it, it is straight above its placement, within the
  // straight parts' slack (TransitionOptions::straight_slack, 5 mm: a knot
  // that cannot hold the exact line holds the height along the normal; here
  // 3.4 mm across, measured).
  const ContactSpec& w = plan.stances[1].contacts.back().spec;
  const Surface& table = sc.scene->surfaces()[w.surface];
  int touching_phase = -1;
  for (std::size_t k = 0; k < tr.phases.size(); ++k)
    if (tr.phases[k].contacts.size() == 5) touching_phase = static_cast<int>(k);
  ASSERT_GE(touching_phase, 0);
  EXPECT_EQ(tr.phases[touching_phase].stance, 1);
  bool touched = false;
  int near_samples = 0;
  for (const auto& s : tr.samples) {
    const Eigen::Vector3d p = table.frame.inverse() * spotAt(sc, s.q, w.spot).translation();  // z: height over the top
    const Eigen::Vector2d off = p.head<2>() - Eigen::Vector2d(w.placement.x, w.placement.y);
    if (table.polygon.contains(p.head<2>(), 0) && p.z() < 0.02) {
      ++near_samples;
      EXPECT_LT(off.norm(), TransitionOptions().straight_slack) << "t = " << s.t;
      EXPECT_GT(p.z(), -1e-3) << "t = " << s.t;
    }
    touched = touched || (s.phase == touching_phase && off.norm() < 1e-3 && std::abs(p.z()) < 1e-3);
  }
  EXPECT_GT(near_samples, 10);
  EXPECT_TRUE(touched);
}

TEST(Interpolator, FilteringDropsTheUselessTouchAndKeepsValidity) {
  const Scenario& sc = chairScenario();
  const Plan plan = handPlan();
  const InterpolationResult r = interpolate(plan, sc, {});
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  EXPECT_EQ(r.filtered, 1);
  EXPECT_EQ(r.trajectory.stats.stances_kept, 2);
  for (const auto& ph : r.trajectory.phases) EXPECT_EQ(ph.contacts.size(), 4u);  // the wrist never touches
  expectValid(r.trajectory, sc);
}

TEST(Interpolator, CollidingStepIsRepairedByRaisingThePath) {
  const Scenario& sc = boxScenario();
  const Plan plan = stepPlan(sc, 0.28);
  InterpolatorOptions opt;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  EXPECT_EQ(r.trajectory.stats.repairs, 1);
  expectValid(r.trajectory, sc);
  // Without repairs the same plan is reported with the stances of the failing transition.
  opt.repair_attempts = 0;
  const InterpolationResult u = interpolate(plan, sc, opt);
  EXPECT_EQ(u.status, InterpolationResult::Status::Unrepairable);
  EXPECT_EQ(u.failed_stances, (std::vector<int>{1, 3}));
  EXPECT_NE(u.reason.find("stances 1 -> 3"), std::string::npos) << u.reason;
  EXPECT_TRUE(u.trajectory.samples.empty());
}

TEST(Interpolator, ThighPivotsOffTheSeatWithItsFootPlanted) {
  // tests/data/chair_palm_thigh.plan.json (in tests/data/chair_knee_pit.yaml):
  // seated, the left palm reaches the table and takes weight, then the left
  // thigh is unloaded and leaves the seat. A thigh whose foot stays planted
  // cannot rise straight with its orientation held (its knee moves across the
  // shank only): it pivots.
  const Scenario& sc = kneePitChairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_palm_thigh.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 5u);
  InterpolatorOptions opt;
  opt.filter = false;
  opt.steps = 10;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  expectValid(r.trajectory, sc);
  // The last phase holds no thigh contact on the left, and the thigh is off the seat there.
  const TrajectoryPhase& last = r.trajectory.phases.back();
  const int l_thigh = sc.robot->spotIndex("l_thigh");
  for (const auto& c : last.contacts) EXPECT_NE(c.spot, l_thigh);
  const Surface& seat = sc.scene->surfaces()[sc.scene->surfaceIndex("chair_seat")];
  const double rise = (seat.frame.inverse() * spotAt(sc, r.trajectory.samples.back().q, l_thigh).translation()).z();
  EXPECT_GT(rise, 1e-3);
}

namespace {
// Consecutive stances of the planner's chair plan (tests/data/chair.plan.json,
// models/scenarios/chair_table.yaml: the seat at 0.31 m, the thigh spots near
// the hips), from `first` to `last`: transitions that once failed.
Plan chairPlanStances(const Scenario& sc, std::size_t first, std::size_t last) {
  static const Plan whole = readPlan(test::sourcePath("tests/data/chair.plan.json"), sc);
  Plan p = whole;
  p.stances.assign(whole.stances.begin() + first, whole.stances.begin() + last + 1);
  return p;
}

// The plan (every stance kept) interpolates with one transition repaired and
// every sample valid; without what `disable` turns off, it fails with
// `failed` (a moving body's transition: unrepairable), naming `stances`.
void expectRepairedOnlyWith(const Plan& plan, const Scenario& sc, const std::function<void(InterpolatorOptions&)>& disable,
                            const std::string& stances,
                            InterpolationResult::Status failed = InterpolationResult::Status::Unrepairable) {
  InterpolatorOptions opt;
  opt.filter = false;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  EXPECT_EQ(r.trajectory.stats.repairs, 1);
  expectValid(r.trajectory, sc);
  disable(opt);
  const InterpolationResult u = interpolate(plan, sc, opt);
  EXPECT_EQ(u.status, failed);
  EXPECT_NE(u.reason.find(stances), std::string::npos) << u.reason;
}

}  // namespace

TEST(Interpolator, ThighNearTheHipPivotsOffTheLowSeat) {
  // The posture at the top of the thigh's lift was found neither from the
  // previous step nor from the witnesses' interpolation (the right leg's
  // thigh and foot contacts over-constrain the solver), but from the witness
  // the thigh rises to.
  const Scenario& sc = chairScenario();
  // Seated with both feet drawn back, the left thigh touching without
  // support, then gone: the thigh (its spot near the hip) leaves the seat
  // with its foot planted and the right thigh on the seat.
  const Plan plan = chairPlanStances(sc, 1, 2);
  InterpolatorOptions opt;
  opt.filter = false;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  EXPECT_EQ(r.trajectory.stats.repairs, 0);
  expectValid(r.trajectory, sc);
  const Surface& seat = sc.scene->surfaces()[sc.scene->surfaceIndex("chair_seat")];
  const int l_thigh = sc.robot->spotIndex("l_thigh");
  const double rise = (seat.frame.inverse() * spotAt(sc, r.trajectory.samples.back().q, l_thigh).translation()).z();
  EXPECT_GT(rise, 5e-3);
}

TEST(Interpolator, WeightShiftWithTheTrunkAlongTheTableEdge) {
  // Knots nearest the witnesses' interpolation jumped between two branches
  // (a knee by 0.06 rad) while the abdomen slid along the table's edge, and
  // the linear interpolation between them went 0.7 mm into the table however
  // refined: solved again with each knot also near its neighbour.
  const Scenario& sc = chairScenario();
  // Standing between the chair and the table, the trunk under the table's
  // edge, the left foot unloaded: the witnesses' interpolation goes 9.5 mm
  // into the table, and the knots nearest it slide along the edge.
  const Plan plan = chairPlanStances(sc, 20, 21);
  InterpolatorOptions opt;
  opt.filter = false;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  EXPECT_EQ(r.trajectory.stats.repairs, 1);
  expectValid(r.trajectory, sc);
}

TEST(Interpolator, WeightShiftUnderTheTableTopWithMoreClearance) {
  // From a chair plan (the generator's GJK distances): crouched between the chair and the
  // table, the abdomen 5 mm under the table top in both witnesses, the
  // weight goes from the right foot to the left while the waist moves 13 cm
  // sideways and up. At the collision margin the knots slide along the
  // table's underside on either side of a corner of the box-box distance,
  // and the segments between them dip 4-7 mm into it however refined
  // (nearest the witnesses' interpolation or each near its neighbour); with
  // 3 mm more clearance for the knots they do not.
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_under_table_shift.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  expectRepairedOnlyWith(plan, sc, [](InterpolatorOptions& o) { o.wide_clearance = 0; }, "stances 0 -> 1",
                         InterpolationResult::Status::TransitionFailed);
}

TEST(Interpolator, FootDetoursPastTheChairLegBesideTheOtherFoot) {
  // No bridge clears a chair leg 0.28 m high; the repair whose path carries
  // the foot farthest from the obstacles and from the planted foot steps
  // sideways first (a via-point a quarter of the way), then back.
  const Scenario& sc = chairScenario();
  // The right foot leaves the floor in front of the chair's front left leg
  // and is put down beside the chair, between that leg and the left foot:
  // the spline (or any bridge over it) crosses the leg.
  expectRepairedOnlyWith(chairPlanStances(sc, 61, 63), sc, [](InterpolatorOptions& o) { o.repair_attempts = 0; },
                         "stances 0 -> 2");
}

TEST(Interpolator, FootPassesBetweenTheChairLegAndTheOtherFootOnAPlannedPath) {
  // From a plan made with the OMPL guide: the right foot steps back from
  // beside the chair's front left leg, its heel 5 mm from it, to beside the
  // seat, through a gap 0.165 m wide between that leg and the left foot for a
  // foot 0.138 m wide. Every spline cuts the leg or the other foot, or leaves
  // the foot's turn to the knots, which turn its toes one way and then the
  // other (a hip yaw jump of 0.4 rad between two knots 2 mm apart); the
  // path planned with OMPL turns the foot with the gap. (Without that path,
  // and without planned limb joints, it fails.)
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_ompl_step.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 3u);
  expectRepairedOnlyWith(
      plan, sc, [](InterpolatorOptions& o) { o.plan_body_path = false, o.limb_joint_paths = false; }, "stances 0 -> 2");
  // Without the body's path but with the stages after it (planned limb
  // joints, then the foot free in the air on its leg's joints), it passes too.
  InterpolatorOptions no_body_path;
  no_body_path.filter = false;
  no_body_path.plan_body_path = false;
  const InterpolationResult r = interpolate(plan, sc, no_body_path);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  expectValid(r.trajectory, sc);
}

TEST(Interpolator, FreeFootKeepsToAPathOfItsOwnWhileTheHandReachesTheTable) {
  // From the same plan: standing on the left foot, the right palm reaches
  // the table top from below its edge while the free right foot goes from
  // beside the left foot to behind it. Interpolated in joint space the free
  // foot swings into the chair's back left leg or the left foot, slides along
  // it from knot to knot and jumps past it, whichever path the palm takes;
  // its end on a path of its own (planned around the left foot) it does not.
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_ompl_reach.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  expectRepairedOnlyWith(plan, sc, [](InterpolatorOptions& o) { o.free_limb_paths = false; }, "stances 0 -> 1");
}

TEST(Interpolator, FreeArmGoesOverTheTableEdgeOnPlannedJoints) {
  // tests/data/chair_ompl_arm_over_edge.plan.json (LimbPathPlanner's test):
  // the right foot steps while the free left hand goes from below the table
  // top's level, in front of its edge, to over the top. With its end on a
  // path of its own, the elbow still cuts the edge; with the arm's joints
  // planned with the transition's progress, every sample is valid.
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_ompl_arm_over_edge.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  expectRepairedOnlyWith(plan, sc, [](InterpolatorOptions& o) { o.limb_joint_paths = false; }, "stances 0 -> 1");
}

TEST(Interpolator, WeightShiftWithTheFreeArmBroughtBackOverTheTableEdge) {
  // From a chair plan made with stability margins: on both feet, the weight
  // goes to the right foot while the free right hand comes back from above
  // the table top, over its edge, to hang in front of it. Its joints'
  // interpolation drags the fingers through the edge, by less than a
  // millimetre at the knots' margin, however refined and with more
  // clearance; on the arm's joints planned around the edge, every sample is valid.
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_margins_arm_off_table.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  expectRepairedOnlyWith(plan, sc, [](InterpolatorOptions& o) { o.limb_joint_paths = false; }, "stances 0 -> 1",
                         InterpolationResult::Status::TransitionFailed);
}

TEST(Interpolator, WristLaidBesideTheForearmOnTheTableDoesNotMove) {
  // From the same plan: the right forearm on the table, the right wrist is
  // added where the witness already has it touching the table. No path of
  // zero length for the posture generator to follow: the contact is held
  // touching while the body shifts, as a support flip; the wrist stays put.
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_ompl_wrist_beside_forearm.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  InterpolatorOptions opt;
  opt.filter = false;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  expectValid(r.trajectory, sc);
  const int wrist = sc.robot->spotIndex("r_wrist");
  const Eigen::Vector3d at = spotAt(sc, plan.stances[1].configuration, wrist).translation();
  double drift = 0;
  for (const auto& sample : r.trajectory.samples)
    drift = std::max(drift, (spotAt(sc, sample.q, wrist).translation() - at).norm());
  EXPECT_LT(drift, 1e-3);
}

TEST(Interpolator, AFootHangingFromItsThighOnTheSeatSwingsDownToTheFloor) {
  // From a plan of the paper's chair (tests/data/chair_paper_foot_from_thigh.plan.json):
  // seated on the left thigh, the right foot on the floor and the right
  // wrist on the table, the free left foot comes down to the floor. Its leg
  // is held at the thigh: the foot swings on an arc about the knee and
  // cannot come straight down along the floor's normal; it reaches the
  // floor scuffing less than a millimetre, every sample valid.
  const Scenario& sc = paperChairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_paper_foot_from_thigh.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  InterpolatorOptions opt;
  opt.filter = false;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  expectValid(r.trajectory, sc);
  // The last phase holds the foot's contact: within 1 mm of its placement from its first sample.
  const int foot = sc.robot->spotIndex("l_sole");
  const Eigen::Vector3d at = spotAt(sc, plan.stances[1].configuration, foot).translation();
  const int last = r.trajectory.samples.back().phase;
  for (const auto& sample : r.trajectory.samples) {
    if (sample.phase == last) {
      EXPECT_LT((spotAt(sc, sample.q, foot).translation() - at).norm(), 1e-3);
    }
  }
}

// Interpolates a two- or three-stance plan cut from a chair_paper plan,
// every stance kept, and checks every sample independently.
void expectPaperChairPieceInterpolates(const std::string& file) {
  const Scenario& sc = paperChairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/" + file), sc);
  InterpolatorOptions opt;
  opt.filter = false;
  const InterpolationResult r = interpolate(plan, sc, opt);
  ASSERT_TRUE(r.success()) << toString(r.status) << ": " << r.reason;
  expectValid(r.trajectory, sc);
}

TEST(Interpolator, AFreeArmOnItsPlannedPathDoesNotJumpAcrossTheTableEdge) {
  // The left palm leaves the table; the free right arm goes from under the
  // table's edge to the side, its joints planned around the edge. The knots
  // used to follow that path only halfway (the cost's target halfway to the
  // previous knot): the arm lagged, then jumped across the edge between two
  // knots (0.12 rad), and no refinement closed the gap (the hand 0.1 mm into
  // the top). Now a planned limb's target is its path.
  expectPaperChairPieceInterpolates("chair_paper_arm_around_table_edge.plan.json");
}

TEST(Interpolator, AForearmLiftedOffTheTableLeavesItsPathAndSwingsTheArmAroundTheEdge) {
  // Seated on the left thigh, the left forearm leaves the table for a
  // witness where the arm hangs below its top. No spline for the forearm
  // can be followed (no posture at 0.3 of it, nor with via-points or OMPL's
  // path): the forearm turns about the elbow. Last stage: the body free in
  // the air, its arm's joints planned around the edge from touching.
  expectPaperChairPieceInterpolates("chair_paper_forearm_off_table.plan.json");
}

TEST(Interpolator, AFreeArmThroughANarrowGapIsPlannedNarrower) {
  // The left thigh leaves the seat while the free left arm goes from
  // beside the table's edge to over its top, 5 mm from the edge in both
  // witnesses: no joint path keeps 10 mm clear, one keeps 3 mm; the knots
  // keep the posture generator's 5 mm around it.
  expectPaperChairPieceInterpolates("chair_paper_arm_through_gap.plan.json");
}

TEST(Interpolator, AnArmHangingBehindThePelvisIsSwungUpOntoTheTable) {
  // Standing on the left foot between the chair and the table's edge, the
  // left forearm on the table, the right wrist is put on the table from an
  // arm hanging behind the pelvis (chair_paper with its feet kept off the
  // seat, stances 160 -> 161 of its first plan). No path of the wrist is
  // followed (the hand through the pelvis, the pelvis into the table's
  // edge); last stage, the body free in the air on its arm's joints planned
  // from touching: RRTConnect finds them 5 mm clear in 200,000 state checks,
  // not in 20,000, and the wrist must come down within 1 mm of its contact
  // point on both axes at once (it came down 1.09 mm off on the diagonal).
  expectPaperChairPieceInterpolates("chair_paper_arm_from_behind_onto_table.plan.json");
}

TEST(Interpolator, AJumpBetweenBranchesOfTheInverseKinematicsIsBridged) {
  // chair_paper on its OMPL guide (acyclic-guide), stances 7 -> 8 of the
  // portfolio's 572-node plan: the right thigh leaves the seat while the left
  // palm and the right wrist are held on the table and both soles on the
  // floor. Between two knots 0.006 apart in path parameter the knots'
  // optimum jumps from one branch of the inverse kinematics to another, the
  // palm 1.39 mm into the table between them: no halving shortens the jump,
  // and every via-point and detour fails the same way or finds no posture.
  // That refused the plan. Bridged, the jump gets knots projected from the
  // straight joint-space line between its two knots, and every sample is
  // valid.
  const Scenario& sc = paperChairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_paper_ompl_palm_held_branch_jump.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  InterpolatorOptions opt;
  opt.filter = false;
  opt.bridge_jumps = false;
  const InterpolationResult without = interpolate(plan, sc, opt);
  ASSERT_FALSE(without.success());
  EXPECT_NE(without.reason.find("between two knots"), std::string::npos) << without.reason;
  EXPECT_NE(without.reason.find("table_top"), std::string::npos) << without.reason;
  expectPaperChairPieceInterpolates("chair_paper_ompl_palm_held_branch_jump.plan.json");  // bridged by default
}

TEST(Interpolator, BadInputAndCancellation) {
  const Scenario& sc = floorScenario();
  Plan plan = stepPlan(sc, 0.15);
  InterpolatorOptions opt;
  opt.dt = 0;
  EXPECT_EQ(interpolate(plan, sc, opt).status, InterpolationResult::Status::InvalidInput);
  InterpolatorOptions no_threads;
  no_threads.threads = 0;
  const InterpolationResult t = interpolate(plan, sc, no_threads);
  EXPECT_EQ(t.status, InterpolationResult::Status::InvalidInput);
  EXPECT_NE(t.reason.find("threads"), std::string::npos) << t.reason;
  for (auto bad : {std::function<void(InterpolatorOptions&)>([](InterpolatorOptions& o) { o.pyramid_edges = 6; }),
                   std::function<void(InterpolatorOptions&)>([](InterpolatorOptions& o) { o.link_acceleration_cap = 0; }),
                   std::function<void(InterpolatorOptions&)>([](InterpolatorOptions& o) { o.support_inset = -0.01; }),
                   std::function<void(InterpolatorOptions&)>([](InterpolatorOptions& o) { o.friction_share = 1.5; })}) {
    InterpolatorOptions o;
    bad(o);
    EXPECT_EQ(interpolate(plan, sc, o).status, InterpolationResult::Status::InvalidInput);
  }
  // A witness that breaks the contract: the foot below the floor.
  Plan sunk = plan;
  sunk.stances[2].configuration.base_position.z() -= 0.05;
  const InterpolationResult s = interpolate(sunk, sc, {});
  EXPECT_EQ(s.status, InterpolationResult::Status::InvalidInput);
  EXPECT_NE(s.reason.find("stance 2"), std::string::npos) << s.reason;
  // Two contacts changed in one step.
  Plan jump = plan;
  jump.stances.erase(jump.stances.begin() + 1, jump.stances.begin() + 3);
  const InterpolationResult j = interpolate(jump, sc, {});
  EXPECT_EQ(j.status, InterpolationResult::Status::InvalidInput);
  EXPECT_NE(j.reason.find("stances 0 -> 1"), std::string::npos) << j.reason;
  std::atomic<bool> cancel{true};
  EXPECT_EQ(interpolate(plan, sc, {}, {}, &cancel).status, InterpolationResult::Status::Cancelled);
}

// --- The trajectory check finds what breaks the contract ------------------------------

TEST(TrajectoryCheck, FindsEachKindOfViolation) {
  const Scenario& sc = floorScenario();
  const InterpolationResult r = interpolate(stepPlan(sc, 0.15), sc, {});
  ASSERT_TRUE(r.success()) << r.reason;
  ValidityChecker checker(sc.robot, sc.scene);
  auto failing = [&](const Trajectory& tr) {
    std::vector<std::string> names;
    for (const auto& p : checkTrajectory(tr, sc, checker).parts)
      if (!p.ok()) names.push_back(p.name);
    return names;
  };
  const Trajectory& good = r.trajectory;
  // A contact drifting by 2 mm: the base moved under a held foot.
  Trajectory drift = good;
  const int mid = static_cast<int>(drift.samples.size()) / 2;
  drift.samples[mid].q.base_position.y() += 0.002;
  EXPECT_EQ(failing(drift), (std::vector<std::string>{"samples"}));
  // A stored velocity over a limit, which the positions do not show either.
  Trajectory fast = good;
  fast.samples[mid].dq[0] = 1.5 * sc.robot->joints()[0].velocity;
  EXPECT_EQ(failing(fast), (std::vector<std::string>{"velocity limits", "velocities from positions"}));
  // Stored velocities a third too high through a whole phase: within the limits, not the positions' derivative.
  Trajectory scaled = good;
  for (auto& s : scaled.samples)
    if (s.phase == 2) s.dq *= 1.3;
  EXPECT_EQ(failing(scaled), (std::vector<std::string>{"velocities from positions"}));
  // A 1 mrad jolt of an arm joint at one sample: an acceleration far over the limit.
  Trajectory jolt = good;
  jolt.samples[mid].q.joints[sc.robot->jointIndex("RARM_JOINT0")] += 0.001;
  EXPECT_EQ(failing(jolt), (std::vector<std::string>{"velocities from positions", "acceleration limits"}));
  // Where the foot leaves the floor, the positions move on (by 2 mrad from the
  // next sample on) while the stored velocity says rest.
  Trajectory flip = good;
  const int leaves = static_cast<int>(std::lround(flip.phases[2].t_start / flip.dt));
  for (std::size_t i = leaves + 1; i < flip.samples.size(); ++i)
    flip.samples[i].q.joints[sc.robot->jointIndex("RARM_JOINT0")] += 0.002;
  const std::vector<std::string> flip_fails = failing(flip);
  EXPECT_NE(std::find(flip_fails.begin(), flip_fails.end(), "rest at contact changes"), flip_fails.end());
  // Moving where the foot leaves the floor.
  Trajectory moving = good;
  const int leave = static_cast<int>(std::lround(moving.phases[2].t_start / moving.dt));
  moving.samples[leave].dq[3] = 0.01;
  EXPECT_EQ(failing(moving), (std::vector<std::string>{"rest at contact changes"}));
  // A sample claiming a phase it is not in.
  Trajectory phases = good;
  phases.samples[1].phase = 3;
  EXPECT_FALSE(checkTrajectory(phases, sc, checker).valid());
}

// --- The executables ----------------------------------------------------------------

TEST(InterpolatorProcess, WritesATrajectoryThatAcyclicCheckAccepts) {
  const Scenario& sc = floorScenario();
  test::TempDir dir;
  const std::string plan = dir.path() + "/step.json", traj = dir.path() + "/step.trajectory.json";
  Plan p = stepPlan(sc, 0.15);
  writePlan(p, sc, plan);
  const std::string interp = test::binaryPath("processes/acyclic-interpolator");
  const std::string check = test::binaryPath("processes/acyclic-check");
  const auto run = test::runProcess(interp + " --in " + plan + " --out " + traj + " -n 10");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("samples"), std::string::npos) << run.output;
  const auto ok = test::runProcess(check + " " + sc.path + " --trajectory " + traj);
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_NE(ok.output.find("trajectory: valid"), std::string::npos) << ok.output;
  // The same trajectory with a held foot dragged 3 mm: a violation, exit 1.
  Trajectory tr = readTrajectory(traj, sc);
  for (auto& s : tr.samples) s.q.base_position.y() += s.t > 0.2 && s.t < 0.3 ? 0.003 : 0.0;
  writeTrajectory(tr, sc, dir.path() + "/bad.json");
  const auto bad = test::runProcess(check + " " + sc.path + " --trajectory " + dir.path() + "/bad.json");
  EXPECT_EQ(bad.status, 1) << bad.output;
  EXPECT_NE(bad.output.find("spot origin"), std::string::npos) << bad.output;
}

// The knots keep the stability margins the scenario's stances were planned
// with (its planner section), unless the command line says otherwise: the
// scenario's 6 cm inset gives the trajectory that --support-inset 0.06
// gives, and moves the single supports' centre of mass away from where no
// margin leaves it; --support-inset 0 on the command line wins. The same for
// the time law's ZMP shift cap, and the knots' barrier oracle.
TEST(InterpolatorProcess, TakesTheScenariosMarginsUnlessTheCommandLineGivesThem) {
  const Scenario& sc = floorScenario();
  test::TempDir dir;
  const std::string scenario =
      dir.write("margins.yaml", test::scenarioText("models/scenarios/step_forward.yaml") +
                                    "planner: {posture_support_inset: 0.06, posture_friction_share: 0.5, zmp_shift_cap: 0.004, "
                                    "transition_mu_oracle: probing}\n");
  const Scenario with = Scenario::load(scenario);
  const InterpolatorOptions o = withScenarioMargins(with, {});
  EXPECT_EQ(o.posture_mu_oracle, "probing");
  EXPECT_EQ(withScenarioMargins(sc, {}).posture_mu_oracle, "quality-function");
  EXPECT_EQ(transitionOptions(o).posture.mu_oracle, "probing");
  EXPECT_DOUBLE_EQ(o.zmp_shift_cap, 0.004);
  EXPECT_DOUBLE_EQ(o.support_inset, 0.06);
  EXPECT_DOUBLE_EQ(o.friction_share, 0.5);
  EXPECT_DOUBLE_EQ(o.support_inset_y, -1.0);
  EXPECT_DOUBLE_EQ(withScenarioMargins(sc, {}).support_inset, 0.0);
  const std::string plan = dir.path() + "/step.json";
  writePlan(stepPlan(sc, 0.15), sc, plan);
  auto run = [&](const std::string& out, const std::string& flags) {
    const auto r = test::runProcess(test::binaryPath("processes/acyclic-interpolator") + " -q -n 10 --scenario " +
                                    scenario + " --in " + plan + " --out " + dir.path() + "/" + out + " " + flags);
    EXPECT_EQ(r.status, 0) << r.output;
    return readTrajectory(dir.path() + "/" + out, with);
  };
  const Trajectory by_scenario = run("a.json", ""), given = run("b.json", "--support-inset 0.06 --friction-share 0.5"),
                   none = run("c.json", "--support-inset 0 --friction-share 1");
  ASSERT_EQ(by_scenario.samples.size(), given.samples.size());
  for (std::size_t k = 0; k < given.samples.size(); ++k)
    ASSERT_EQ(by_scenario.samples[k].q.joints, given.samples[k].q.joints) << "sample " << k;
  double apart = 0;
  Kinematics a(sc.robot), b(sc.robot);
  for (std::size_t k = 0; k < std::min(none.samples.size(), given.samples.size()); ++k) {
    a.setConfiguration(given.samples[k].q);
    b.setConfiguration(none.samples[k].q);
    apart = std::max(apart, (a.centerOfMass() - b.centerOfMass()).head<2>().norm());
  }
  EXPECT_GT(apart, 0.005);
  // The scenario's ZMP shift cap slows the weight shifts; 0 on the command line lifts it.
  const Trajectory uncapped = run("d.json", "--zmp-shift-cap 0");
  EXPECT_GT(by_scenario.duration(), uncapped.duration() + 0.1);
  // The scenario's oracle (probing) makes other knots than Ipopt's default,
  // which the command line brings back.
  const Trajectory default_oracle = run("e.json", "--mu-oracle quality-function");
  bool differ = default_oracle.samples.size() != by_scenario.samples.size();
  for (std::size_t k = 0; !differ && k < by_scenario.samples.size(); ++k)
    differ = by_scenario.samples[k].q.joints != default_oracle.samples[k].q.joints;
  EXPECT_TRUE(differ);
  const auto bad = test::runProcess(test::binaryPath("processes/acyclic-interpolator") + " --scenario " + scenario +
                                    " --in " + plan + " --out " + dir.path() + "/f.json --mu-oracle fast");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("--mu-oracle"), std::string::npos) << bad.output;
  // A bad oracle in the scenario is named by its file and field.
  const std::string bad_scenario =
      dir.write("bad_oracle.yaml", test::scenarioText("models/scenarios/step_forward.yaml") +
                                       "planner: {transition_mu_oracle: fast}\n");
  const auto named = test::runProcess(test::binaryPath("processes/acyclic-interpolator") + " --scenario " +
                                      bad_scenario + " --in " + plan + " --out " + dir.path() + "/g.json");
  EXPECT_EQ(named.status, 2) << named.output;
  EXPECT_NE(named.output.find("bad_oracle.yaml"), std::string::npos) << named.output;
  EXPECT_NE(named.output.find("planner.transition_mu_oracle"), std::string::npos) << named.output;
  // --set, as acyclic-planner's: the scenario's keys given on the command
  // line (here the margins and oracle taken off again), its own options first.
  const Trajectory set_none = run("h.json", "--set posture_support_inset=0 --set posture_friction_share=null");
  ASSERT_EQ(set_none.samples.size(), none.samples.size());
  for (std::size_t k = 0; k < none.samples.size(); ++k)
    ASSERT_EQ(set_none.samples[k].q.joints, none.samples[k].q.joints) << "sample " << k;
  const Trajectory set_overridden = run("i.json", "--set posture_support_inset=0 --support-inset 0.06");
  ASSERT_EQ(set_overridden.samples.size(), by_scenario.samples.size());
  for (std::size_t k = 0; k < by_scenario.samples.size(); ++k)
    ASSERT_EQ(set_overridden.samples[k].q.joints, by_scenario.samples[k].q.joints) << "sample " << k;
  const auto bad_set = test::runProcess(test::binaryPath("processes/acyclic-interpolator") + " --scenario " + scenario +
                                        " --in " + plan + " --out " + dir.path() + "/j.json --set transition_mu_oracle=fast");
  EXPECT_EQ(bad_set.status, 2) << bad_set.output;
  EXPECT_NE(bad_set.output.find("--set: field 'planner.transition_mu_oracle'"), std::string::npos) << bad_set.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/j.json"));
  // A plan planned with --set records the settings (planner_settings): they
  // apply without being given again, and the command line's after them.
  Plan recorded = stepPlan(sc, 0.15);
  recorded.planner_settings = {"posture_support_inset=0", "posture_friction_share=null"};
  writePlan(recorded, sc, plan);
  const Trajectory by_plan = run("k.json", "");
  ASSERT_EQ(by_plan.samples.size(), none.samples.size());
  for (std::size_t k = 0; k < none.samples.size(); ++k)
    ASSERT_EQ(by_plan.samples[k].q.joints, none.samples[k].q.joints) << "sample " << k;
  const Trajectory plan_then_set =
      run("l.json", "--set posture_support_inset=0.06 --set posture_friction_share=0.5");
  ASSERT_EQ(plan_then_set.samples.size(), by_scenario.samples.size());
  for (std::size_t k = 0; k < by_scenario.samples.size(); ++k)
    ASSERT_EQ(plan_then_set.samples[k].q.joints, by_scenario.samples[k].q.joints) << "sample " << k;
  // A bad recorded setting is named by the plan file and the field.
  recorded.planner_settings = {"posture_friction_share=2"};
  writePlan(recorded, sc, plan);
  const auto bad_recorded = test::runProcess(test::binaryPath("processes/acyclic-interpolator") + " --scenario " +
                                             scenario + " --in " + plan + " --out " + dir.path() + "/m.json");
  EXPECT_EQ(bad_recorded.status, 2) << bad_recorded.output;
  EXPECT_NE(bad_recorded.output.find(plan + " (planner_settings): field 'planner.posture_friction_share'"),
            std::string::npos)
      << bad_recorded.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/m.json"));
}

TEST(InterpolatorProcess, HelpAndBadInput) {
  const std::string interp = test::binaryPath("processes/acyclic-interpolator");
  const auto help = test::runProcess(interp + " --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("exit status 0 written"), std::string::npos) << help.output;
  test::TempDir dir;
  const auto missing = test::runProcess(interp + " --in " + dir.path() + "/none.json --out " + dir.path() + "/t.json");
  EXPECT_EQ(missing.status, 2) << missing.output;
  EXPECT_NE(missing.output.find("none.json"), std::string::npos) << missing.output;
  // A plan whose scenario field names no file: the file and the field are named.
  const std::string plan = dir.write("p.json", R"({"format": "acyclic.plan/1", "scenario": "nowhere.yaml", "stances": []})");
  const auto noscen = test::runProcess(interp + " --in " + plan + " --out " + dir.path() + "/t.json");
  EXPECT_EQ(noscen.status, 2) << noscen.output;
  EXPECT_NE(noscen.output.find("field 'scenario'"), std::string::npos) << noscen.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/t.json"));
}

// The verifier solves the plan as its file will hold it: a plan in memory
// whose base quaternions are off unit norm in their last bits (as a
// posture generator's are), once written and read back, is the plan the
// verifier already solved, transition for transition (remembered, none
// solved again). Verified as it was in memory, a transition at the margins
// was accepted that the interpolator then could not make from the file.
TEST(PlanVerifier, VerifiesThePlanAsItsFileHoldsIt) {
  const Scenario& sc = chairScenario();
  const Plan read = readPlan(test::sourcePath("tests/data/chair_ompl_arm_over_edge.plan.json"), sc);
  Plan in_memory = read;
  for (PlanStance& st : in_memory.stances) st.configuration.base_orientation.coeffs() *= 1 + 1e-13;
  const Plan from_file = planFromJson(planToJson(in_memory, sc), "round trip", sc);
  ASSERT_TRUE(from_file.stances[0].configuration.base_orientation.coeffs() !=
              in_memory.stances[0].configuration.base_orientation.coeffs())
      << "the file must not keep the change, or this tests nothing";
  std::atomic<bool> stop{false};
  TransitionVerifier verifier(sc, InterpolatorOptions{});
  const PlanVerdict first = verifier.verify(in_memory, stop);
  EXPECT_TRUE(first.ok()) << first.reason;
  EXPECT_EQ(first.solved, 1);
  const PlanVerdict again = verifier.verify(from_file, stop);
  EXPECT_TRUE(again.ok()) << again.reason;
  EXPECT_EQ(again.solved, 0);  // the same transition: what was solved is what the file holds
}

// The planner's lazy verification (interpolator/plan_verifier.h) says what
// the interpolator will do: tests/data/chair_ompl_arm_over_edge.plan.json
// cannot be interpolated without the free arm's joints planned, and can with
// them; a transition once solved is remembered, not solved again.
TEST(PlanVerifier, RefusesWhatTheInterpolatorCannotDoAndRemembersWhatItSolved) {
  const Scenario& sc = chairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_ompl_arm_over_edge.plan.json"), sc);
  ASSERT_EQ(plan.stances.size(), 2u);
  std::atomic<bool> stop{false};
  InterpolatorOptions without;
  without.limb_joint_paths = false;
  TransitionVerifier weak(sc, without);
  const PlanVerdict refused = weak.verify(plan, stop);
  EXPECT_FALSE(refused.ok());
  EXPECT_FALSE(refused.stopped);
  EXPECT_EQ(refused.failed_from, 0);
  EXPECT_EQ(refused.failed_to, 1);
  EXPECT_FALSE(refused.reason.empty());
  EXPECT_FALSE(interpolate(plan, sc, without).success());  // the interpolator agrees

  TransitionVerifier full(sc, InterpolatorOptions{});
  const PlanVerdict ok = full.verify(plan, stop);
  EXPECT_TRUE(ok.ok()) << ok.reason;
  EXPECT_EQ(ok.transitions, 1);
  EXPECT_EQ(ok.solved, 1);
  const PlanVerdict again = full.verify(plan, stop);
  EXPECT_TRUE(again.ok());
  EXPECT_EQ(again.solved, 0);  // remembered
  EXPECT_EQ(full.remembered(), 1u);
  // A raised stop flag: nothing solved, the verdict says so.
  TransitionVerifier fresh(sc, InterpolatorOptions{});
  stop = true;
  const PlanVerdict stopped = fresh.verify(plan, stop);
  EXPECT_TRUE(stopped.stopped);
  EXPECT_FALSE(stopped.ok());
}

namespace {
// The same samples and phases, bit for bit.
void expectSameTrajectory(const Trajectory& a, const Trajectory& b) {
  ASSERT_EQ(a.samples.size(), b.samples.size());
  ASSERT_EQ(a.phases.size(), b.phases.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    ASSERT_EQ(a.samples[i].q.joints, b.samples[i].q.joints) << i;
    ASSERT_EQ(a.samples[i].q.base_position, b.samples[i].q.base_position) << i;
    ASSERT_EQ(a.samples[i].q.base_orientation.coeffs(), b.samples[i].q.base_orientation.coeffs()) << i;
    ASSERT_EQ(a.samples[i].dq, b.samples[i].dq) << i;
  }
  for (std::size_t k = 0; k < a.phases.size(); ++k) {
    EXPECT_EQ(a.phases[k].t_start, b.phases[k].t_start) << k;
    ASSERT_EQ(a.phases[k].contacts.size(), b.phases[k].contacts.size()) << k;
    for (std::size_t c = 0; c < a.phases[k].contacts.size(); ++c) {
      const ContactSpec &x = a.phases[k].contacts[c], &y = b.phases[k].contacts[c];
      EXPECT_TRUE(x.spot == y.spot && x.surface == y.surface && x.supporting == y.supporting &&
                  x.placement.x == y.placement.x && x.placement.y == y.placement.y &&
                  x.placement.theta == y.placement.theta)
          << "phase " << k << ", contact " << c;
    }
  }
}
}  // namespace

namespace {
// The memo tests' case: a step on the floor as the planner's file holds it
// (the plan the verifier solves), and its interpolation at 8 steps from
// scratch, made once.
struct MemoCase {
  InterpolatorOptions opt;
  Plan plan;
  InterpolationResult fresh;
};
const MemoCase& memoCase() {
  static const MemoCase c = [] {
    const Scenario& sc = floorScenario();
    MemoCase m;
    m.opt.steps = 8;
    m.plan = planFromJson(planToJson(stepPlan(sc, 0.15), sc), "round trip", sc);
    m.fresh = interpolate(m.plan, sc, m.opt);
    return m;
  }();
  return c;
}
}  // namespace

// A memo shared by the verifier and the interpolator (transition_memo.h):
// what the verifier solved is taken from it, none solved again, and the
// trajectory is the one interpolating from scratch gives, bit for bit. An
// empty memo is filled by the interpolation itself; one that keeps no
// motion (a verifier's own) cannot be interpolated with.
TEST(TransitionMemo, AVerifiedPlanIsInterpolatedWithoutSolvingItsTransitionsAgain) {
  const Scenario& sc = floorScenario();
  const auto& [opt, plan, fresh] = memoCase();
  ASSERT_TRUE(fresh.success()) << fresh.reason;
  ASSERT_GT(fresh.trajectory.stats.posture_calls, 0);
  EXPECT_EQ(fresh.reused, 0);
  auto same = [&](const InterpolationResult& r) { expectSameTrajectory(r.trajectory, fresh.trajectory); };

  auto memo = std::make_shared<TransitionMemo>(opt);
  TransitionVerifier verifier(sc, memo);
  std::atomic<bool> stop{false};
  const PlanVerdict v = verifier.verify(plan, stop);
  ASSERT_TRUE(v.ok()) << v.reason;
  EXPECT_EQ(v.solved, fresh.trajectory.stats.transitions);
  EXPECT_EQ(memo->size(), static_cast<std::size_t>(v.solved));
  const InterpolationResult reused = interpolate(plan, sc, *memo);
  ASSERT_TRUE(reused.success()) << reused.reason;
  EXPECT_EQ(reused.reused, reused.trajectory.stats.transitions);
  EXPECT_EQ(reused.trajectory.stats.posture_calls, 0);
  same(reused);

  // An empty memo: solved here, kept, then taken.
  TransitionMemo empty(opt);
  const InterpolationResult first = interpolate(plan, sc, empty);
  ASSERT_TRUE(first.success()) << first.reason;
  EXPECT_EQ(first.reused, 0);
  EXPECT_EQ(first.trajectory.stats.posture_calls, fresh.trajectory.stats.posture_calls);
  EXPECT_EQ(empty.size(), static_cast<std::size_t>(first.trajectory.stats.transitions));
  const InterpolationResult second = interpolate(plan, sc, empty);
  EXPECT_EQ(second.reused, second.trajectory.stats.transitions);
  same(first);
  same(second);

  // A verifier's own memo keeps verdicts, not motion.
  TransitionMemo lean(opt, false);
  EXPECT_THROW(interpolate(plan, sc, lean), std::invalid_argument);
}

// Transitions solved elsewhere (the planner's, sent on ACYCLIC_TRANSITIONS)
// in a memo that checks them before use: taken when they stand, the
// trajectory the same as solving them here; one whose knots leave its
// witness or its surface is refused with the reason and solved here, to the
// same trajectory.
TEST(TransitionMemo, TransitionsFromElsewhereAreCheckedAndABadOneIsSolvedHereInstead) {
  const Scenario& sc = floorScenario();
  const auto& [opt, plan, fresh] = memoCase();
  ASSERT_TRUE(fresh.success()) << fresh.reason;

  TransitionMemo solved(opt);
  ASSERT_TRUE(interpolate(plan, sc, solved).success());
  const std::vector<RememberedTransition> sent = rememberedTransitions(plan, solved);
  ASSERT_EQ(static_cast<int>(sent.size()), fresh.trajectory.stats.transitions);
  ASSERT_GE(sent.size(), 2u);

  auto receive = [&](const std::vector<RememberedTransition>& ts) {
    auto memo = std::make_shared<TransitionMemo>(opt, true, /*check_on_use=*/true);
    for (const RememberedTransition& t : ts) memo->store(transitionKey(plan, t.design), t.outcome);
    return memo;
  };
  const InterpolationResult taken = interpolate(plan, sc, *receive(sent));
  ASSERT_TRUE(taken.success()) << taken.reason;
  EXPECT_EQ(taken.reused, taken.trajectory.stats.transitions);
  EXPECT_EQ(taken.refused, 0) << taken.refused_reason;
  EXPECT_EQ(taken.trajectory.stats.posture_calls, 0);
  expectSameTrajectory(taken.trajectory, fresh.trajectory);

  // The first transition starts off its witness; the last one that moves
  // has its middle knot lifted 5 cm, its soles off the floor.
  std::vector<RememberedTransition> bad = sent;
  ASSERT_EQ(bad.front().design.from, 0);
  ASSERT_FALSE(bad.front().outcome.pieces.empty());
  bad.front().outcome.pieces.front().knots.front().joints[0] += 0.01;
  auto last = std::find_if(bad.rbegin(), bad.rend(), [](const auto& t) { return !t.outcome.pieces.empty(); });
  ASSERT_TRUE(last != bad.rend() && last != std::prev(bad.rend()));
  auto& pieces = last->outcome.pieces;
  MotionPiece& piece = *std::max_element(pieces.begin(), pieces.end(), [](const auto& a, const auto& b) {
    return a.knots.size() < b.knots.size();
  });
  ASSERT_GE(piece.knots.size(), 3u);
  piece.knots[piece.knots.size() / 2].base_position.z() += 0.05;
  const InterpolationResult mended = interpolate(plan, sc, *receive(bad));
  ASSERT_TRUE(mended.success()) << mended.reason;
  EXPECT_EQ(mended.refused, 2);
  EXPECT_EQ(mended.reused, mended.trajectory.stats.transitions - 2);
  EXPECT_NE(mended.refused_reason.find("does not start at stance 0's witness"), std::string::npos)
      << mended.refused_reason;
  EXPECT_GT(mended.trajectory.stats.posture_calls, 0);
  expectSameTrajectory(mended.trajectory, fresh.trajectory);

  // A memo of this process's own (no check on use) takes them as they are.
  auto trusting = std::make_shared<TransitionMemo>(opt);
  for (const RememberedTransition& t : bad) trusting->store(transitionKey(plan, t.design), t.outcome);
  const InterpolationResult unchecked = interpolate(plan, sc, *trusting);
  EXPECT_EQ(unchecked.refused, 0);
  EXPECT_EQ(unchecked.reused, unchecked.trajectory.stats.transitions);
}

// The options' text (what decides whether transitions solved elsewhere are
// used) changes with every option that decides a transition's outcome, and
// not with the thread count or the stance filter.
TEST(TransitionMemo, TheOptionsTextChangesWithEveryOptionThatDecidesAnOutcome) {
  const InterpolatorOptions base;
  const std::string text = outcomeOptionsText(base);
  std::vector<std::pair<const char*, std::function<void(InterpolatorOptions&)>>> changes = {
      {"steps", [](auto& o) { o.steps += 1; }},
      {"fixed_step", [](auto& o) { o.fixed_step = std::nextafter(o.fixed_step, 1.0); }},
      {"dt", [](auto& o) { o.dt *= 2; }},
      {"speed_cap", [](auto& o) { o.speed_cap *= 2; }},
      {"velocity_share", [](auto& o) { o.velocity_share /= 2; }},
      {"link_acceleration_cap", [](auto& o) { o.link_acceleration_cap *= 2; }},
      {"zmp_shift_cap", [](auto& o) { o.zmp_shift_cap = 0.01; }},
      {"lift", [](auto& o) { o.lift *= 2; }},
      {"touch_clearance", [](auto& o) { o.touch_clearance *= 2; }},
      {"air_orientation_tolerance", [](auto& o) { o.air_orientation_tolerance /= 2; }},
      {"repair_attempts", [](auto& o) { o.repair_attempts += 1; }},
      {"repair_step", [](auto& o) { o.repair_step *= 2; }},
      {"plan_body_path", [](auto& o) { o.plan_body_path = !o.plan_body_path; }},
      {"free_limb_paths", [](auto& o) { o.free_limb_paths = !o.free_limb_paths; }},
      {"limb_joint_paths", [](auto& o) { o.limb_joint_paths = !o.limb_joint_paths; }},
      {"wide_clearance", [](auto& o) { o.wide_clearance *= 2; }},
      {"refine_depth", [](auto& o) { o.refine_depth += 1; }},
      {"bridge_jumps", [](auto& o) { o.bridge_jumps = !o.bridge_jumps; }},
      {"order_by_failure", [](auto& o) { o.order_by_failure = !o.order_by_failure; }},
      {"verify_samples", [](auto& o) { o.verify_samples = !o.verify_samples; }},
      {"pyramid_edges", [](auto& o) { o.pyramid_edges = 8; }},
      {"support_inset", [](auto& o) { o.support_inset = 0.01; }},
      {"support_inset_y", [](auto& o) { o.support_inset_y = 0.01; }},
      {"friction_share", [](auto& o) { o.friction_share = 0.8; }},
      {"posture_iterations", [](auto& o) { o.posture_iterations += 1; }},
      {"collision_cutoff", [](auto& o) { o.collision_cutoff *= 2; }},
      {"posture_ipopt_options", [](auto& o) { o.posture_ipopt_options.push_back("tol=1e-9"); }},
      {"posture_lbfgs_in_kkt", [](auto& o) { o.posture_lbfgs_in_kkt = !o.posture_lbfgs_in_kkt; }},
      {"posture_mu_oracle", [](auto& o) { o.posture_mu_oracle = "probing"; }},
  };
  for (const auto& [name, change] : changes) {
    InterpolatorOptions o = base;
    change(o);
    EXPECT_NE(outcomeOptionsText(o), text) << name;
  }
  InterpolatorOptions o = base;
  o.threads = 1;
  o.filter = !o.filter;
  EXPECT_EQ(outcomeOptionsText(o), text);
}

namespace {
// Solves the one transition of a plan cut from chair_paper's plan on its
// OMPL guide twice, the repair the first failure asks for first (the
// default) and in the fixed order: both must solve it the same way, the
// knots equal to the bit; returns both outcomes.
std::pair<TransitionOutcome, TransitionOutcome> solveInBothOrders(const std::string& file) {
  const Scenario& sc = paperChairScenario();
  const Plan plan = readPlan(test::sourcePath("tests/data/" + file), sc);
  std::vector<int> kept(plan.stances.size());
  for (std::size_t i = 0; i < kept.size(); ++i) kept[i] = static_cast<int>(i);
  std::vector<TransitionDesign> designs;
  EXPECT_EQ(designTransitions(plan, kept, designs), "");
  EXPECT_EQ(designs.size(), 1u);
  if (designs.size() != 1) return {};
  InterpolatorOptions io;
  io.filter = false;
  InterpolatorOptions with_margins = withScenarioMargins(sc, io);
  // These transitions were recorded where Ipopt's default barrier oracle
  // needs the repairs tested; chair_paper's own (transition_mu_oracle:
  // probing) makes some of them as planned.
  with_margins.posture_mu_oracle = "quality-function";
  TransitionOptions free_first = transitionOptions(with_margins);
  TransitionOptions body_first = free_first;
  EXPECT_TRUE(free_first.order_by_failure);  // the default
  body_first.order_by_failure = false;
  TransitionSolver a(sc, free_first), b(sc, body_first);
  std::pair<TransitionOutcome, TransitionOutcome> r{a.solve(plan, designs[0]), b.solve(plan, designs[0])};
  const TransitionOutcome& fa = r.first;
  const TransitionOutcome& fb = r.second;
  EXPECT_TRUE(fa.ok) << fa.reason;
  EXPECT_TRUE(fb.ok) << fb.reason;
  EXPECT_EQ(fa.how, fb.how);
  EXPECT_EQ(fa.pieces.size(), fb.pieces.size());
  for (std::size_t p = 0; p < std::min(fa.pieces.size(), fb.pieces.size()); ++p) {
    EXPECT_EQ(fa.pieces[p].knots.size(), fb.pieces[p].knots.size()) << p;
    for (std::size_t k = 0; k < std::min(fa.pieces[p].knots.size(), fb.pieces[p].knots.size()); ++k) {
      EXPECT_EQ(fa.pieces[p].knots[k].joints, fb.pieces[p].knots[k].joints) << p << " " << k;
      EXPECT_EQ(fa.pieces[p].knots[k].base_position, fb.pieces[p].knots[k].base_position) << p << " " << k;
      EXPECT_EQ(fa.pieces[p].knots[k].base_orientation.coeffs(), fb.pieces[p].knots[k].base_orientation.coeffs())
          << p << " " << k;
    }
  }
  return r;
}

// solveInBothOrders, and the repair the first failure names made it on the
// second attempt (`how`), the fixed order on its `fixed_attempts`-th.
std::pair<TransitionOutcome, TransitionOutcome> expectMadeSecond(const std::string& file, const std::string& how,
                                                                 int fixed_attempts) {
  auto r = solveInBothOrders(file);
  EXPECT_EQ(r.first.how, how);
  EXPECT_EQ(r.first.attempts, 2);
  EXPECT_EQ(r.second.attempts, fixed_attempts);
  return r;
}
}  // namespace

TEST(TransitionSolver, AStepWhoseFreeHandGrazesTheChairsBackTriesTheFreeLimbsStageSecond) {
  // On the left palm and the right sole, the left foot steps while the free
  // right hand passes the chair's back. As planned, the hand grazes the back
  // (the failed check names only the right arm's links); raising or
  // detouring the foot's path leaves the hand where it was, and the stage
  // with the free limbs on paths of their own solves it. Free limbs first,
  // that is the second attempt; the body's path first, after its four
  // repairs and OMPL's path for the foot. The same attempt, the same knots.
  const auto [free_first, body_first] = expectMadeSecond("chair_paper_ompl_step_hand_by_chair_back.plan.json",
                                                         "with the free limbs on their own paths, as planned", 7);
  EXPECT_LT(free_first.posture_calls, body_first.posture_calls);
}

TEST(TransitionSolver, AWeightShiftWhoseFreeArmCutsTheTablePlansItsJointsSecond) {
  // On both soles, the weight leaves the right wrist on the table while the
  // free left arm comes over the table's top: its joints' interpolation
  // takes the hand into the top (the failed check names only the left arm's
  // links). Free limbs first, the arm's joints are planned on the second
  // attempt; whole body first, after the knots near their neighbours and with
  // more clearance (three attempts more). The same attempt, the same knots.
  expectMadeSecond("chair_paper_ompl_wrist_unloaded_arm_over_table.plan.json", "with the free limbs' joints planned", 5);
}

TEST(InterpolatorProcess, VerboseSaysHowEachTransitionWasMadeAndWhatItCost) {
  // The step of chair_paper's OMPL plan whose free hand grazes the chair's
  // back (above): --verbose names the repair that made it, after how many
  // attempts; without it, no such line.
  const std::string interp = test::binaryPath("processes/acyclic-interpolator");
  test::TempDir dir;
  const std::string cmd = interp + " -q --no-filter --threads 1 --scenario " +
                          test::sourcePath("models/scenarios/chair_paper.yaml") + " --in " +
                          test::sourcePath("tests/data/chair_paper_ompl_step_hand_by_chair_back.plan.json") +
                          " --out " + dir.path() + "/t.json";
  const auto run = test::runProcess(cmd + " -v");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("transition 0 -> 2 (a body moves): with the free limbs on their own paths, as planned; "
                            "2 attempts, "),
            std::string::npos)
      << run.output;
  std::size_t lines = 0;
  for (std::size_t at = run.output.find("acyclic-interpolator: transition "); at != std::string::npos;
       at = run.output.find("acyclic-interpolator: transition ", at + 1))
    ++lines;
  EXPECT_EQ(lines, 1u) << run.output;  // one transition in that plan
  const auto quiet = test::runProcess(cmd);
  ASSERT_EQ(quiet.status, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find("acyclic-interpolator: transition "), std::string::npos) << quiet.output;
  // A wrist laid beside the forearm already on the table does not move: it
  // is said so, made as a fixed-contact transition.
  const auto still = test::runProcess(interp + " -q -v --no-filter --scenario " +
                                      test::sourcePath("models/scenarios/chair_table.yaml") + " --in " +
                                      test::sourcePath("tests/data/chair_ompl_wrist_beside_forearm.plan.json") +
                                      " --out " + dir.path() + "/still.json");
  ASSERT_EQ(still.status, 0) << still.output;
  EXPECT_NE(still.output.find("transition 0 -> 1 (a body already touching where it goes, its contacts fixed): as "
                              "planned; 1 attempt, "),
            std::string::npos)
      << still.output;
}

TEST(TransitionSolver, AJumpBetweenBranchesIsBridgedOnTheSecondAttempt) {
  // The right thigh leaves the seat while the left palm and the right wrist
  // are held on the table (the cut above): as planned, two knots 0.006 apart
  // in path parameter lie on two branches of the inverse kinematics, and no
  // halving shortens the segment between them (the held palm 1.39 mm into
  // the table in its middle). Bridged, it is made; the fixed order bridges
  // it on its sixth attempt, after the four repairs of the thigh's path.
  const auto [jump_first, fixed_order] = expectMadeSecond("chair_paper_ompl_palm_held_branch_jump.plan.json",
                                                          "as planned, with bridges across branch jumps", 6);
  EXPECT_LT(jump_first.posture_calls, fixed_order.posture_calls);
}

TEST(TransitionSolver, AWeightShiftWithAJumpBetweenBranchesIsBridgedOnTheSecondAttempt) {
  // A weight shift on the soles and the right palm whose knots jump between
  // two branches, the held palm 3 mm off its point between two of them: the
  // same, for a fixed-contact transition (the fixed order bridges it after
  // the knots near their neighbours and the two with more clearance).
  expectMadeSecond("chair_paper_ompl_fixed_branch_jump.plan.json", "with bridges across branch jumps", 5);
}
