#pragma once
// Checks a trajectory against the robot model before anything is sent:
// finite values, joint positions within the limits, joint velocities within
// the velocity limits, no jump between consecutive samples, and its start
// against the measured posture. A violation is refused with a reason naming
// the sample, the time and the joint; nothing is ever clamped.
#include <string>

#include <Eigen/Core>

#include "hrp2_bridge/bridge_config.h"
#include "planner/model/robot_model.h"
#include "planner/plan/trajectory.h"

namespace acyclic::hrp2 {

struct CheckResult {
  bool ok = true;
  std::string reason;   // empty when ok
  int sample = -1;      // the first offending sample, -1 if not about one
  int joint = -1;       // the offending joint (controller order), -1 if not about one
  static CheckResult failure(std::string why, int sample = -1, int joint = -1) {
    return {false, std::move(why), sample, joint};
  }
};

// The whole trajectory against the model's limits (config: margins, jump factor).
CheckResult checkTrajectory(const Trajectory& tr, const RobotModel& model, const BridgeConfig& config);

// A measured joint vector: the right size and finite.
CheckResult checkMeasured(const Eigen::VectorXd& q, const Eigen::VectorXd& dq, const RobotModel& model);

// The trajectory's first joint angles against the measured ones: refuse a jump
// larger than config.start_tolerance.
CheckResult checkStart(const Eigen::VectorXd& first, const Eigen::VectorXd& measured, const RobotModel& model,
                       const BridgeConfig& config);

}  // namespace acyclic::hrp2
