#include "hrp2_bridge/trajectory_check.h"

#include <cmath>
#include <cstdio>

#include "planner/common/fmt.h"

namespace acyclic::hrp2 {

namespace {

// Rounding of the file format and of interpolation must not refuse a motion
// that sits exactly on a limit.
constexpr double kSlack = 1e-9;


std::string at(int i, double t) { return "sample " + std::to_string(i) + fmt(" (t = %.3f s)", t); }

bool finite(const Eigen::VectorXd& v) { return v.allFinite(); }

}  // namespace

CheckResult checkTrajectory(const Trajectory& tr, const RobotModel& m, const BridgeConfig& cfg) {
  const int n = m.numJoints();
  if (tr.samples.empty()) return CheckResult::failure("the trajectory has no sample");
  if (!(tr.dt > 0) || !std::isfinite(tr.dt)) return CheckResult::failure(fmt("bad sample period dt = %g s", tr.dt));
  const Eigen::VectorXd lo = m.lowerLimits().array() + cfg.position_margin;
  const Eigen::VectorXd hi = m.upperLimits().array() - cfg.position_margin;
  const Eigen::VectorXd vmax = m.velocityLimits() * cfg.velocity_margin;
  for (std::size_t k = 0; k < tr.samples.size(); ++k) {
    const int i = static_cast<int>(k);
    const TrajectorySample& s = tr.samples[k];
    if (!std::isfinite(s.t)) return CheckResult::failure(at(i, s.t) + ": time is not finite", i);
    if (s.q.joints.size() != n || s.dq.size() != n)
      return CheckResult::failure(at(i, s.t) + ": " + std::to_string(s.q.joints.size()) + " joint angles and " +
                                      std::to_string(s.dq.size()) + " velocities, the robot has " +
                                      std::to_string(n) + " joints", i);
    if (s.phase < 0 || s.phase >= static_cast<int>(tr.phases.size()))
      return CheckResult::failure(at(i, s.t) + ": phase index out of range", i);
    if (!s.q.base_position.allFinite() || !s.q.base_orientation.coeffs().allFinite())
      return CheckResult::failure(at(i, s.t) + ": base pose is not finite (NaN or inf)", i);
    for (int j = 0; j < n; ++j) {
      const std::string joint = m.joints()[j].name;
      if (!std::isfinite(s.q.joints[j]) || !std::isfinite(s.dq[j]))
        return CheckResult::failure(at(i, s.t) + ": " + joint + " is not finite (NaN or inf)", i, j);
      if (s.q.joints[j] < lo[j] - kSlack || s.q.joints[j] > hi[j] + kSlack)
        return CheckResult::failure(at(i, s.t) + ": " + joint +
                                        fmt(" = %.4f rad outside its limits [%.4f, %.4f]", s.q.joints[j], lo[j], hi[j]),
                                    i, j);
      if (std::abs(s.dq[j]) > vmax[j] + kSlack)
        return CheckResult::failure(at(i, s.t) + ": " + joint +
                                        fmt(" velocity %.3f rad/s exceeds its limit %.3f rad/s", s.dq[j], vmax[j]),
                                    i, j);
    }
    if (k == 0) continue;
    const TrajectorySample& p = tr.samples[k - 1];
    const double h = s.t - p.t;
    if (!(h > 0)) return CheckResult::failure(at(i, s.t) + ": time does not increase", i);
    // The velocities could be consistent with the limits while the positions
    // jump: the step itself is bounded too.
    for (int j = 0; j < n; ++j) {
      const double step = std::abs(s.q.joints[j] - p.q.joints[j]);
      const double allowed = cfg.jump_factor * vmax[j] * h;
      if (step > allowed + kSlack)
        return CheckResult::failure(at(i, s.t) + ": " + m.joints()[j].name +
                                        fmt(" jumps by %.4f rad in %.4f s (at most %.4f rad)", step, h, allowed),
                                    i, j);
    }
  }
  return {};
}

CheckResult checkMeasured(const Eigen::VectorXd& q, const Eigen::VectorXd& dq, const RobotModel& m) {
  if (q.size() != m.numJoints() || dq.size() != m.numJoints())
    return CheckResult::failure("measured state has " + std::to_string(q.size()) + " joint angles and " +
                                std::to_string(dq.size()) + " velocities, the robot has " +
                                std::to_string(m.numJoints()) + " joints");
  if (!finite(q) || !finite(dq)) return CheckResult::failure("measured state is not finite (NaN or inf)");
  return {};
}

CheckResult checkStart(const Eigen::VectorXd& first, const Eigen::VectorXd& measured, const RobotModel& m,
                       const BridgeConfig& cfg) {
  if (first.size() != measured.size()) return CheckResult::failure("start: joint count differs from the robot's");
  Eigen::Index j = 0;
  const double worst = (first - measured).cwiseAbs().maxCoeff(&j);
  if (!(worst <= cfg.start_tolerance))
    return CheckResult::failure("start: " + m.joints()[j].name +
                                    fmt(" is %.4f rad from the measured posture (at most %.4f): refusing to jump",
                                        worst, cfg.start_tolerance),
                                0, static_cast<int>(j));
  return {};
}

}  // namespace acyclic::hrp2
