#pragma once
// A free limb's joint path planned with OMPL (docs/design.md section 10): the
// repair for an arm or a leg with no contact whose joints, interpolated
// between the two witnesses, sweep it through an obstacle, as a hand hanging
// in front of a table's edge in one witness and resting over the table top in
// the next, where every knot keeps the forearm on the near side of the edge
// until it must jump across. Pulling the limb's end along a path of its own
// does not help: the elbow still cuts the edge.
//
// The limb's joints are planned together with the transition's progress s
// (the rest of the body on the witnesses' interpolation at s: a hand may have
// to rise before the trunk comes near the table, or after), clear of the
// obstacles and of the robot's other links by a margin that the ends may
// relax (an end as close to an obstacle as its witness has it). The path is
// shortcut, its progress made increasing (the running maximum, blended with
// the limb's own share of its joint-space length, so that the limb never
// waits for nor jumps ahead of the body), and the knots take the limb's
// joints from it as their reference; every knot and sample is checked
// afterwards as any other. Seeded: the same transition gives the same path on
// any thread.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "planner/collision/collision_model.h"
#include "planner/model/configuration.h"
#include "planner/model/kinematics.h"

namespace acyclic {

// The joints of a limb along a path, s in [0, 1] (the transition's progress).
class LimbJointPath {
 public:
  // `params`: each waypoint's s, increasing from 0 to 1; none: by joint-space length.
  LimbJointPath(std::vector<int> joints, std::vector<Eigen::VectorXd> waypoints, std::vector<double> params = {});
  const std::vector<int>& joints() const { return joints_; }   // controller indices
  const std::vector<Eigen::VectorXd>& waypoints() const { return waypoints_; }
  const std::vector<double>& params() const { return params_; }
  Eigen::VectorXd at(double s) const;      // linear between waypoints
  // q with the limb's joints replaced by the path's at s.
  Configuration apply(const Configuration& q, double s) const;

 private:
  std::vector<int> joints_;
  std::vector<Eigen::VectorXd> waypoints_;
  std::vector<double> params_;
};

struct LimbPathPlanOptions {
  double clearance = 0.01;     // m: from the obstacles and the robot's other links
  // Near an end the clearance asked for is that end's (times 0.9), rising by
  // this much per radian of the largest joint change from it.
  double clearance_per_rad = 0.1;
  long max_checks = 20000;     // OMPL's budget, in states checked (not time: the same path under any load)
  // The limb's own body rests on a surface at the ends (a forearm lifted off
  // a table, then swung around its edge): an end within 1 mm of an obstacle
  // is then taken as touching (clearance 0, less 0.1 mm of the contact's
  // tolerance), and the clearance asked for rises from there as the limb
  // moves away. Otherwise such an end has no path.
  bool touching_ends = false;
  unsigned seed = 1;
};

struct LimbPathPlan {
  std::optional<LimbJointPath> path;  // set on success
  std::string reason;                 // why not, otherwise
};

// The least clearance of the limb's links (those `root_joint` moves) to the
// obstacles and the robot's other links along the straight interpolation of
// its joints from q0's to q1's, the rest of the body on the witnesses'
// interpolation (`samples` points); `cap` at most (pairs farther are not measured).
double limbSweepClearance(const CollisionModel& collisions, Kinematics& kin, int root_joint, const Configuration& q0,
                          const Configuration& q1, double cap, int samples = 16);

// The joints `root_joint` moves on their straight interpolation from q0's to q1's.
LimbJointPath straightLimbPath(const RobotModel& robot, int root_joint, const Configuration& q0,
                               const Configuration& q1);

LimbPathPlan planLimbPath(const CollisionModel& collisions, Kinematics& kin, int root_joint, const Configuration& q0,
                          const Configuration& q1, const LimbPathPlanOptions& options = {});

}  // namespace acyclic
