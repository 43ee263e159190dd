#include "interpolator/body_path_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "planner/collision/collision_model.h"
#include "planner/guide/seeded_ompl.h"

namespace acyclic {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

// The least distance from `spot`'s link, its spot at `spot_pose`, to the
// obstacles and the held shapes.
double linkClearance(const Eigen::Isometry3d& spot_pose, const RobotModel& robot, const Scene& scene, int spot,
                     const std::vector<PlacedShape>& held) {
  const ContactSpot& sp = robot.spots()[spot];
  const Eigen::Isometry3d link = spot_pose * sp.frame.inverse();
  double clearance = std::numeric_limits<double>::infinity();
  for (const auto& shape : robot.links()[sp.link].shapes) {
    for (const auto& ob : scene.obstacles())
      clearance = std::min(clearance, shapeDistance(shape, link * shape.pose, ob.shape, ob.shape.pose));
    for (const auto& [other, pose] : held) clearance = std::min(clearance, shapeDistance(shape, link * shape.pose, *other, pose));
  }
  return clearance;
}

// A state: the spot's position, a turn about the path's up axis, and the
// fraction of the way from the start orientation to the end one.
struct BodyStates {
  Eigen::Quaterniond r0, r1;
  Eigen::Vector3d up;
  Eigen::Isometry3d pose(const double* v) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    T.linear() = (Eigen::AngleAxisd(v[3], up) * r0.slerp(std::clamp(v[4], 0.0, 1.0), r1)).toRotationMatrix();
    return T;
  }
};

}  // namespace

double sweepClearance(const BodyPath& path, const RobotModel& robot, const Scene& scene, int spot,
                      const std::vector<PlacedShape>& held) {
  constexpr int kSamples = 32;
  double clearance = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= kSamples; ++i) {
    const double s = static_cast<double>(i) / kSamples;
    if (path.straightAt(s)) continue;
    clearance = std::min(clearance, linkClearance(path.pose(s), robot, scene, spot, held));
  }
  return clearance;
}

BodyPathPlan planBodyPath(const BodyPath& path, const RobotModel& robot, const Scene& scene, int spot,
                          const std::vector<PlacedShape>& held, const BodyPathPlanOptions& o) {
  BodyPathPlan out;
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  const Eigen::Isometry3d a = path.splineStart(), b = path.splineEnd();
  BodyStates states{Eigen::Quaterniond(a.linear()), Eigen::Quaterniond(b.linear()), path.up()};

  // The ends are where the straight parts leave the body: as close to an
  // obstacle or a held link as the plan put them (a heel by a chair's leg, at
  // the posture generator's margin). Near an end the clearance asked for is
  // the end's, rising with the distance from it (half as fast: the body can
  // move away) to the option's.
  const double ca = linkClearance(a, robot, scene, spot, held), cb = linkClearance(b, robot, scene, spot, held);
  if (!(std::min(ca, cb) > 1e-3)) {
    out.reason = "the body's path cannot be planned: an end of its spline is within 1 mm of an obstacle or a held link";
    return out;
  }
  auto required = [&](const Eigen::Vector3d& p) {
    return std::min({o.clearance, 0.9 * ca + 0.5 * (p - a.translation()).norm(),
                     0.9 * cb + 0.5 * (p - b.translation()).norm()});
  };

  auto space = std::make_shared<ob::RealVectorStateSpace>(5);
  ob::RealVectorBounds bounds(5);
  for (int k = 0; k < 3; ++k) {
    bounds.setLow(k, std::min(a.translation()[k], b.translation()[k]) - o.room);
    bounds.setHigh(k, std::max(a.translation()[k], b.translation()[k]) + (k == 2 ? o.rise : o.room));
  }
  bounds.setLow(3, -o.max_turn);
  bounds.setHigh(3, o.max_turn);
  bounds.setLow(4, 0.0);
  bounds.setHigh(4, 1.0);
  space->setBounds(bounds);
  const unsigned seed = o.seed;
  space->setStateSamplerAllocator([seed](const ob::StateSpace* s) { return std::make_shared<SeededSampler>(s, seed); });
  og::SimpleSetup ss(space);
  auto si = ss.getSpaceInformation();
  long checks = 0;
  ss.setStateValidityChecker([&](const ob::State* s) {
    ++checks;
    const double* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
    const Eigen::Isometry3d T = states.pose(v);
    return linkClearance(T, robot, scene, spot, held) >= required(T.translation());
  });
  // A check every 0.5% of the space's largest extent along a motion (under a
  // centimetre of its distance, metres and radians alike, for a foot's step).
  si->setStateValidityCheckingResolution(0.005);
  ob::ScopedState<ob::RealVectorStateSpace> start(space), goal(space);
  for (int k = 0; k < 3; ++k) start[k] = a.translation()[k], goal[k] = b.translation()[k];
  start[3] = goal[3] = 0;
  start[4] = 0;
  goal[4] = 1;
  ss.setStartAndGoalStates(start, goal);
  std::optional<og::PathGeometric> found = solveSeededRRTConnect(ss, seed, checks, o.max_checks);
  if (!found) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "OMPL (RRTConnect) found no path for the body alone, %.0f mm clear, in %ld state checks",
                  o.clearance * 1e3, o.max_checks);
    out.reason = buf;
    return out;
  }
  og::PathGeometric& g = *found;

  // The spline through the waypoints bulges off the planned polyline; where
  // that takes the body nearer than half the clearance asked for, waypoints
  // every 2 cm hold it to the polyline.
  auto waypoints = [&](const og::PathGeometric& p) {
    std::vector<Eigen::Isometry3d> w;
    for (std::size_t i = 1; i + 1 < p.getStateCount(); ++i)
      w.push_back(states.pose(p.getState(i)->as<ob::RealVectorStateSpace::StateType>()->values));
    return path.through(w);
  };
  BodyPath result = waypoints(g);
  if (sweepClearance(result, robot, scene, spot, held) < 0.5 * std::min({o.clearance, ca, cb})) {
    g.interpolate(std::max<unsigned>(g.getStateCount(), static_cast<unsigned>(std::ceil(g.length() / 0.02)) + 1));
    result = waypoints(g);
  }
  out.path = std::move(result);
  return out;
}

}  // namespace acyclic
