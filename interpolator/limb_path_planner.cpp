#include "interpolator/limb_path_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "interpolator/time_law.h"
#include "planner/guide/seeded_ompl.h"

namespace acyclic {

namespace ob = ompl::base;
namespace og = ompl::geometric;

LimbJointPath::LimbJointPath(std::vector<int> joints, std::vector<Eigen::VectorXd> waypoints, std::vector<double> params)
    : joints_(std::move(joints)), waypoints_(std::move(waypoints)), params_(std::move(params)) {
  if (waypoints_.empty()) throw std::invalid_argument("a limb path needs at least one waypoint");
  if (params_.empty()) {
    params_.push_back(0);
    for (std::size_t i = 1; i < waypoints_.size(); ++i)
      params_.push_back(params_.back() + (waypoints_[i] - waypoints_[i - 1]).norm());
    for (double& p : params_) p = params_.back() > 0 ? p / params_.back() : 0.0;
  }
  if (params_.size() != waypoints_.size()) throw std::invalid_argument("a limb path needs one parameter per waypoint");
}

Eigen::VectorXd LimbJointPath::at(double s) const {
  if (s <= params_.front()) return waypoints_.front();
  if (s >= params_.back()) return waypoints_.back();
  const auto it = std::upper_bound(params_.begin(), params_.end(), s);
  const std::size_t i = it - params_.begin();  // params_[i - 1] <= s < params_[i]
  const double seg = params_[i] - params_[i - 1];
  const double f = seg > 0 ? (s - params_[i - 1]) / seg : 1.0;
  return waypoints_[i - 1] + f * (waypoints_[i] - waypoints_[i - 1]);
}

Configuration LimbJointPath::apply(const Configuration& q, double s) const {
  Configuration out = q;
  const Eigen::VectorXd v = at(s);
  for (std::size_t k = 0; k < joints_.size(); ++k) out.joints[joints_[k]] = v[k];
  return out;
}

namespace {

// The pairs that have a link of the limb on one side (and not on both: the
// limb's own links are held apart by its joint limits, as the posture
// generator's self-collision pairs say).
std::vector<int> limbPairs(const CollisionModel& collisions, const RobotModel& robot, int root_joint) {
  std::vector<int> out;
  for (std::size_t i = 0; i < collisions.pairs().size(); ++i) {
    const CollisionPair& p = collisions.pairs()[i];
    const bool a = robot.jointMovesLink(root_joint, p.link_a);
    const bool b = p.kind == CollisionPair::Kind::Self && robot.jointMovesLink(root_joint, p.link_b);
    if (a != b) out.push_back(static_cast<int>(i));
  }
  return out;
}

// The least distance of those pairs at q, `cap` at most: pairs that bounding
// volumes put farther than `cap` are not measured.
double clearanceAt(const CollisionModel& collisions, Kinematics& kin, const std::vector<int>& pairs,
                   const Configuration& q, double cap) {
  // Poses only (Kinematics::setPoses): Simbody's whole position stage was
  // three quarters of the time of a check (perf, chair_paper), the bounds
  // of the pairs outside the limb most of the rest.
  kin.setPoses(q);
  double c = cap;
  for (int i : pairs)
    if (collisions.mayBeWithin(kin, i, cap)) c = std::min(c, collisions.pairDistance(kin, i, false).distance);
  return c;
}

Eigen::VectorXd limbValues(const Configuration& q, const std::vector<int>& joints) {
  Eigen::VectorXd v(joints.size());
  for (std::size_t k = 0; k < joints.size(); ++k) v[k] = q.joints[joints[k]];
  return v;
}

}  // namespace

double limbSweepClearance(const CollisionModel& collisions, Kinematics& kin, int root_joint, const Configuration& q0,
                          const Configuration& q1, double cap, int samples) {
  // The witnesses' interpolation moves the limb's joints straight already.
  const std::vector<int> pairs = limbPairs(collisions, kin.model(), root_joint);
  double c = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= samples; ++i)
    c = std::min(c, clearanceAt(collisions, kin, pairs, lerp(q0, q1, static_cast<double>(i) / samples), cap));
  return c;
}

LimbJointPath straightLimbPath(const RobotModel& robot, int root_joint, const Configuration& q0,
                               const Configuration& q1) {
  std::vector<int> joints = robot.jointsMovedBy(root_joint);
  std::vector<Eigen::VectorXd> ends{limbValues(q0, joints), limbValues(q1, joints)};
  return LimbJointPath(std::move(joints), std::move(ends), {0.0, 1.0});
}

LimbPathPlan planLimbPath(const CollisionModel& collisions, Kinematics& kin, int root_joint, const Configuration& q0,
                          const Configuration& q1, const LimbPathPlanOptions& o) {
  LimbPathPlan out;
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  const RobotModel& robot = kin.model();
  const std::vector<int> joints = robot.jointsMovedBy(root_joint);
  const std::vector<int> pairs = limbPairs(collisions, robot, root_joint);
  const int n = static_cast<int>(joints.size());
  if (n == 0) {
    out.reason = "the limb has no joints";
    return out;
  }
  const Eigen::VectorXd a0 = limbValues(q0, joints), a1 = limbValues(q1, joints);
  // At progress s, the body where the witnesses' interpolation has it.
  auto clearance = [&](const Eigen::VectorXd& a, double s) {
    Configuration q = lerp(q0, q1, s);
    for (int k = 0; k < n; ++k) q.joints[joints[k]] = a[k];
    return clearanceAt(collisions, kin, pairs, q, o.clearance);
  };
  // Each end as close as its witness has it.
  // With touching ends, an end within 1 mm but not deeper in than the
  // contact's 0.1 mm counts as touching: clearance -0.1 mm.
  constexpr double kTouch = -1e-4;
  double c0 = clearance(a0, 0), c1 = clearance(a1, 1);
  for (double* c : {&c0, &c1})
    if (o.touching_ends && *c <= 1e-3 && *c >= kTouch) *c = kTouch;
  auto close = [&](double c) { return !(c > 1e-3) && c != kTouch; };
  if (close(c0) || close(c1)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "the limb's path cannot be planned: its %s witness has it within 1 mm of an obstacle or another link",
                  close(c0) ? "first" : "last");
    out.reason = buf;
    return out;
  }
  auto required = [&](const Eigen::VectorXd& a, double s) {
    return std::min({o.clearance, 0.9 * c0 + o.clearance_per_rad * std::max((a - a0).cwiseAbs().maxCoeff(), s),
                     0.9 * c1 + o.clearance_per_rad * std::max((a - a1).cwiseAbs().maxCoeff(), 1 - s)});
  };

  // States: the limb's joints, then the progress s.
  auto space = std::make_shared<ob::RealVectorStateSpace>(n + 1);
  ob::RealVectorBounds bounds(n + 1);
  for (int k = 0; k < n; ++k) {
    const JointInfo& j = robot.joints()[joints[k]];
    bounds.setLow(k, std::min({j.lower, a0[k], a1[k]}));
    bounds.setHigh(k, std::max({j.upper, a0[k], a1[k]}));
  }
  bounds.setLow(n, 0.0);
  bounds.setHigh(n, 1.0);
  space->setBounds(bounds);
  const unsigned seed = o.seed;
  space->setStateSamplerAllocator([seed](const ob::StateSpace* s) { return std::make_shared<SeededSampler>(s, seed); });
  og::SimpleSetup ss(space);
  auto si = ss.getSpaceInformation();
  long checks = 0;
  auto values = [n](const ob::State* s) {
    return Eigen::Map<const Eigen::VectorXd>(s->as<ob::RealVectorStateSpace::StateType>()->values, n + 1);
  };
  ss.setStateValidityChecker([&](const ob::State* st) {
    ++checks;
    const Eigen::VectorXd v = values(st);
    const Eigen::VectorXd a = v.head(n);
    return clearance(a, v[n]) >= required(a, v[n]);
  });
  // A check every 0.02 (radians and progress alike) along a motion: about
  // 1 cm at an arm's length; the knots' collision constraints take the rest.
  si->setStateValidityCheckingResolution(0.02 / space->getMaximumExtent());
  ob::ScopedState<ob::RealVectorStateSpace> start(space), goal(space);
  for (int k = 0; k < n; ++k) start[k] = a0[k], goal[k] = a1[k];
  start[n] = 0;
  goal[n] = 1;
  ss.setStartAndGoalStates(start, goal);
  // The straight path first (every joint linear in the progress): RRTConnect
  // grows its trees toward random samples and, in a narrow passage, can miss
  // a straight path that is clear (chair_paper's stances 60 -> 61, 3 mm).
  si->setup();
  if (si->isValid(start.get()) && si->isValid(goal.get()) && si->checkMotion(start.get(), goal.get())) {
    out.path = LimbJointPath(joints, {a0, a1}, {0.0, 1.0});
    return out;
  }
  const std::optional<og::PathGeometric> found = solveSeededRRTConnect(ss, seed, checks, o.max_checks);
  if (!found) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "OMPL (RRTConnect) found no path for the limb's %d joints, %.0f mm clear, in %ld state checks", n,
                  o.clearance * 1e3, o.max_checks);
    out.reason = buf;
    return out;
  }
  const og::PathGeometric& g = *found;
  // The progress made increasing: its running maximum, blended half and
  // half with the limb's share of its own joint-space length (strictly
  // increasing wherever the limb moves).
  std::vector<Eigen::VectorXd> waypoints;
  std::vector<double> progress, length{0.0};
  for (std::size_t i = 0; i < g.getStateCount(); ++i) {
    const Eigen::VectorXd v = values(g.getState(i));
    waypoints.push_back(v.head(n));
    progress.push_back(std::clamp(i == 0 ? 0.0 : std::max(progress.back(), v[n]), 0.0, 1.0));
    if (i > 0) length.push_back(length.back() + (waypoints[i] - waypoints[i - 1]).norm());
  }
  waypoints.front() = a0;  // exactly the witnesses' values at the ends
  waypoints.back() = a1;
  progress.back() = 1.0;
  std::vector<double> params;
  for (std::size_t i = 0; i < waypoints.size(); ++i)
    params.push_back(0.5 * progress[i] + 0.5 * (length.back() > 0 ? length[i] / length.back() : progress[i]));
  params.front() = 0.0;
  params.back() = 1.0;
  out.path = LimbJointPath(joints, std::move(waypoints), std::move(params));
  return out;
}

}  // namespace acyclic
