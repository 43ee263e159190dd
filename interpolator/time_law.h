#pragma once
// Time parameterization (DESIGN.md section 10): each piece of motion is a
// polyline of configurations travelled from rest to rest with a quintic
// profile s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 (zero velocity and
// acceleration at both ends), as slow as the slowest of its segments needs:
// every joint within a share of its velocity limit, every link origin under a
// global speed cap (the motion stays quasi-static). Durations are whole
// numbers of the controller's dt, so that every piece starts on a sample.
#include <memory>
#include <vector>

#include "planner/model/kinematics.h"

namespace acyclic {

struct TimeLawOptions {
  double dt = 0.005;            // s
  double velocity_share = 0.9;  // of each joint's velocity limit
  double speed_cap = 0.2;       // m/s, any link origin
};

// Configuration on the segment between a and b at fraction f: base position
// and joints linear, base orientation by slerp.
Configuration lerp(const Configuration& a, const Configuration& b, double f);

class TimedPiece {
 public:
  TimedPiece(const std::vector<Configuration>& knots, const RobotModel& robot, Kinematics& kin,
             const TimeLawOptions& options);
  int steps() const { return steps_; }         // duration in dt
  double duration() const { return steps_ * dt_; }
  // Configuration and joint velocities at time t in [0, duration()].
  Configuration at(double t, Eigen::VectorXd* dq = nullptr) const;
  // The knot segment (k: between knots k and k + 1) that at(t) interpolates.
  int segmentAt(double t) const;

  static constexpr double kPeakRate = 1.875;  // max ds/dtau of the quintic profile

 private:
  std::vector<Configuration> knots_;
  std::vector<double> seg_, cum_;  // each segment's length in "time at the limits", cumulative
  double total_ = 0, dt_ = 0;
  int steps_ = 0;
};

}  // namespace acyclic
