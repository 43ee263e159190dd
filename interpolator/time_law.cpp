#include "interpolator/time_law.h"

#include <algorithm>
#include <cmath>

namespace acyclic {

Configuration lerp(const Configuration& a, const Configuration& b, double f) {
  Configuration q = a;
  q.base_position = (1 - f) * a.base_position + f * b.base_position;
  q.base_orientation = a.base_orientation.slerp(f, b.base_orientation).normalized();
  q.joints = (1 - f) * a.joints + f * b.joints;
  return q;
}

TimedPiece::TimedPiece(const std::vector<Configuration>& knots, const RobotModel& robot, Kinematics& kin,
                       const TimeLawOptions& opt)
    : knots_(knots), dt_(opt.dt) {
  // Link origins along each segment, for the speed cap: joints move linearly,
  // so links move on arcs; a few sub-chords measure them.
  constexpr int kSub = 4;
  auto origins = [&](const Configuration& q) {
    kin.setConfiguration(q);
    std::vector<Eigen::Vector3d> o;
    for (int l = 0; l < robot.numLinks(); ++l) o.push_back(kin.linkPose(l).translation());
    return o;
  };
  cum_.push_back(0);
  for (std::size_t k = 0; k + 1 < knots_.size(); ++k) {
    // The time this segment takes at unit rate, every joint and link at or under its limit.
    double len = 0;
    for (const auto& j : robot.joints())
      len = std::max(len, std::abs(knots_[k + 1].joints[j.index] - knots_[k].joints[j.index]) /
                              (opt.velocity_share * j.velocity));
    std::vector<double> arc(robot.numLinks(), 0.0);
    std::vector<Eigen::Vector3d> prev = origins(knots_[k]);
    for (int i = 1; i <= kSub; ++i) {
      const std::vector<Eigen::Vector3d> cur = origins(lerp(knots_[k], knots_[k + 1], static_cast<double>(i) / kSub));
      for (int l = 0; l < robot.numLinks(); ++l) arc[l] += (cur[l] - prev[l]).norm();
      prev = cur;
    }
    for (int l = 0; l < robot.numLinks(); ++l) len = std::max(len, arc[l] / opt.speed_cap);
    seg_.push_back(len);
    cum_.push_back(cum_.back() + len);
  }
  total_ = cum_.back();
  // Rate du/dt = total/T * s'(tau) <= 1: T >= kPeakRate * total.
  steps_ = total_ > 0 ? static_cast<int>(std::ceil(kPeakRate * total_ / dt_ - 1e-9)) : 0;
}

int TimedPiece::segmentAt(double t) const {
  if (steps_ == 0 || knots_.size() < 2) return 0;
  const double tau = std::clamp(t / duration(), 0.0, 1.0);
  const double u = tau * tau * tau * (10 - 15 * tau + 6 * tau * tau) * total_;
  std::size_t k = std::upper_bound(cum_.begin(), cum_.end(), u) - cum_.begin();
  k = std::clamp<std::size_t>(k, 1, seg_.size()) - 1;
  while (k + 1 < seg_.size() && seg_[k] == 0) ++k;
  return static_cast<int>(k);
}

Configuration TimedPiece::at(double t, Eigen::VectorXd* dq) const {
  const int nj = static_cast<int>(knots_.front().joints.size());
  if (dq) *dq = Eigen::VectorXd::Zero(nj);
  if (steps_ == 0 || knots_.size() < 2) return knots_.back();
  const double T = duration();
  const double tau = std::clamp(t / T, 0.0, 1.0);
  const double s = tau * tau * tau * (10 - 15 * tau + 6 * tau * tau);
  const double ds = 30 * tau * tau * (1 - tau) * (1 - tau);  // ds/dtau
  const double u = s * total_;
  const std::size_t k = static_cast<std::size_t>(segmentAt(t));
  const double f = seg_[k] > 0 ? std::clamp((u - cum_[k]) / seg_[k], 0.0, 1.0) : 1.0;
  if (dq && seg_[k] > 0) {
    const double du_dt = total_ * ds / T;
    *dq = (knots_[k + 1].joints - knots_[k].joints) / seg_[k] * du_dt;
  }
  return lerp(knots_[k], knots_[k + 1], f);
}

}  // namespace acyclic
