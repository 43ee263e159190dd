#pragma once
// The moving body's path planned with OMPL (docs/design.md section 10's
// "or plan the body's path with OMPL"): the repair for a body that must pass
// through a narrow gap, where every raised or sideways spline either cuts an
// obstacle or leaves the body's orientation to the posture generator, whose
// knots then jump from one side of the gap to the other (a foot between a
// chair's leg and the other foot turns its toes one way, then the other).
//
// The body alone (the moving link's shapes, rigid) is planned from the top of
// its straight part where it leaves to the top of the one where it arrives,
// in (position, a turn about the path's up axis, the fraction of the way from
// one end orientation to the other), clear of the obstacles and of the links
// held on their contacts by a margin; the path is shortcut and returned as
// waypoints with their orientations, which the posture generator then
// follows closely. Seeded: the same transition gives the same path on any
// thread.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "interpolator/body_path.h"
#include "planner/model/robot_model.h"
#include "planner/scene/scene.h"

namespace acyclic {

// A shape at its world pose.
using PlacedShape = std::pair<const CollisionShape*, Eigen::Isometry3d>;

struct BodyPathPlanOptions {
  double clearance = 0.01;        // m: from the obstacles and the held links
  // How far beyond the ends the path may go (m), sideways (and down) and up
  // (world z). The body is planned alone: with more room it finds ways its
  // limb cannot follow (a foot under a chair's seat, its shank through it).
  double room = 0.1;
  double rise = 0.15;
  double max_turn = 0.6;          // rad: largest turn about the up axis, either way
  long max_checks = 20000;        // OMPL's budget, in states checked (not time: the same path under any load)
  unsigned seed = 1;
};

struct BodyPathPlan {
  std::optional<BodyPath> path;  // set on success
  std::string reason;            // why not, otherwise
};

// `path`: the transition's path as designed (its ends and straight parts are
// kept); `spot`: the moving body's spot; `held`: the shapes of the links held
// on their contacts, where they are during the motion.
BodyPathPlan planBodyPath(const BodyPath& path, const RobotModel& robot, const Scene& scene, int spot,
                          const std::vector<PlacedShape>& held, const BodyPathPlanOptions& options = {});

// The least distance from the moving body's link, carried rigidly along the
// path's spline (the straight parts are common to every repair), to any
// obstacle and to the held links.
double sweepClearance(const BodyPath& path, const RobotModel& robot, const Scene& scene, int spot,
                      const std::vector<PlacedShape>& held);

}  // namespace acyclic
