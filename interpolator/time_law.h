#pragma once
// Time parameterization (docs/design.md section 10): each piece of motion is a
// polyline of configurations, travelled from rest to rest along the polyline
// itself (the path the interpolator validated), as fast as these bounds allow:
// - velocity: every joint within a share of its velocity limit, every link
//   origin under a global speed cap (the motion stays quasi-static);
// - acceleration: every joint within half its acceleration limit
//   (RobotModel, JointInfo::acceleration) inside a segment, every link origin
//   within a linear acceleration cap;
// - balance (optional): the zero-moment point moved by the links'
//   accelerations at most zmp_shift_cap from where the quasi-static plan has
//   it, estimated per segment as sum_l m_l h_l |a_l| / (M g) (h_l a link
//   origin's height above the lowest link origin, |a_l| its acceleration
//   along the path; vertical accelerations and rotational inertia left out);
// - corners: at a knot where the polyline turns, the speed is low enough that
//   each joint's velocity jumps by at most half its acceleration limit times
//   dt.
// So the positions, sampled every dt, show each joint's acceleration (second
// difference over dt^2) within its limit: half for the segments, half for a
// corner between two samples. The speed along the path is a trapezoid in
// time on each segment (a forward and a backward pass over the knots, as
// time-optimal path parameterization does with constant bounds per segment);
// velocities are its exact derivative. Durations are whole numbers of the
// controller's dt (the profile is slowed to the next sample), so that every
// piece starts on a sample.
#include <memory>
#include <vector>

#include "planner/model/kinematics.h"

namespace acyclic {

struct TimeLawOptions {
  double dt = 0.005;            // s
  double velocity_share = 0.9;  // of each joint's velocity limit
  double speed_cap = 0.2;       // m/s, any link origin
  // m/s^2, any link origin: about a tenth of gravity, so that inertial
  // forces stay small beside the weight the quasi-static check balances.
  double link_acceleration_cap = 1.0;
  // m: the ZMP's shift by the motion's accelerations at most this (0: no
  // such bound). 0.01 lets the CoM accelerate at about 0.12 m/s^2 when it is
  // 0.8 m high and nothing else moves.
  double zmp_shift_cap = 0;
  // Scales every joint's acceleration limit (1: the model's); for
  // experiments and tests that isolate the velocity bounds.
  double acceleration_scale = 1.0;
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

 private:
  // Segment k's speed profile: u is the path parameter in "time at the
  // velocity limits" (u' <= 1), trapezoidal in time from rate r0 to r1.
  struct Profile {
    double length = 0;          // in u
    double accel = 0;           // |u''| bound
    double r0 = 0, r1 = 0, peak = 0;
    double t_accel = 0, t_cruise = 0, t_decel = 0;
    double time() const { return t_accel + t_cruise + t_decel; }
    // Distance travelled (in u) and rate after time t on the segment.
    void at(double t, double* u, double* rate) const;
  };
  // Where the profile is at profile time tp: segment and fraction along it, and u'.
  int locate(double tp, double* fraction, double* rate) const;

  std::vector<Configuration> knots_;
  std::vector<Profile> seg_;
  std::vector<Eigen::VectorXd> slope_;  // each segment's joint velocities per unit rate
  std::vector<double> start_;   // each segment's start in profile time
  double profile_time_ = 0;     // the profile's own duration
  double dt_ = 0;
  int steps_ = 0;
};

}  // namespace acyclic
