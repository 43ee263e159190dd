#include "interpolator/time_law.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace acyclic {

Configuration lerp(const Configuration& a, const Configuration& b, double f) {
  Configuration q = a;
  q.base_position = (1 - f) * a.base_position + f * b.base_position;
  q.base_orientation = a.base_orientation.slerp(f, b.base_orientation).normalized();
  q.joints = (1 - f) * a.joints + f * b.joints;
  return q;
}

void TimedPiece::Profile::at(double t, double* u, double* rate) const {
  const double A = accel;
  if (t <= t_accel) {
    *u = r0 * t + 0.5 * A * t * t;
    *rate = r0 + A * t;
  } else if (t <= t_accel + t_cruise) {
    *u = r0 * t_accel + 0.5 * A * t_accel * t_accel + peak * (t - t_accel);
    *rate = peak;
  } else {
    const double s = std::min(t - t_accel - t_cruise, t_decel);
    *u = r0 * t_accel + 0.5 * A * t_accel * t_accel + peak * t_cruise + peak * s - 0.5 * A * s * s;
    *rate = peak - A * s;
  }
  *u = std::clamp(*u, 0.0, length);
  *rate = std::max(*rate, 0.0);
}

TimedPiece::TimedPiece(const std::vector<Configuration>& knots, const RobotModel& robot, Kinematics& kin,
                       const TimeLawOptions& opt)
    : knots_(knots), dt_(opt.dt) {
  const int n = static_cast<int>(knots_.size()) - 1;  // segments
  if (n < 1) return;
  const int nj = static_cast<int>(knots_.front().joints.size());
  // Link origins along each segment, for the link bounds: joints move
  // linearly, so links move on arcs; a few sub-chords measure them.
  constexpr int kSub = 4;
  auto origins = [&](const Configuration& q) {
    kin.setConfiguration(q);
    std::vector<Eigen::Vector3d> o;
    for (int l = 0; l < robot.numLinks(); ++l) o.push_back(kin.linkPose(l).translation());
    return o;
  };
  auto jointAccel = [&](const JointInfo& j) { return opt.acceleration_scale * j.acceleration; };
  seg_.resize(n);
  slope_.assign(n, Eigen::VectorXd::Zero(nj));
  for (int k = 0; k < n; ++k) {
    // The time this segment takes at unit rate, every joint and link at or under its speed limit.
    Profile& p = seg_[k];
    double len = 0;
    for (const auto& j : robot.joints())
      len = std::max(len, std::abs(knots_[k + 1].joints[j.index] - knots_[k].joints[j.index]) /
                              (opt.velocity_share * j.velocity));
    std::vector<double> arc(robot.numLinks(), 0.0);
    const std::vector<Eigen::Vector3d> first = origins(knots_[k]);
    std::vector<Eigen::Vector3d> prev = first;
    for (int i = 1; i <= kSub; ++i) {
      const std::vector<Eigen::Vector3d> cur = origins(lerp(knots_[k], knots_[k + 1], static_cast<double>(i) / kSub));
      for (int l = 0; l < robot.numLinks(); ++l) arc[l] += (cur[l] - prev[l]).norm();
      prev = cur;
    }
    double link_arc = 0;
    for (int l = 0; l < robot.numLinks(); ++l) link_arc = std::max(link_arc, arc[l]);
    // The ZMP's shift per unit u'': sum_l m_l h_l (arc_l / len) / (M g),
    // heights at the segment's start above its lowest link origin.
    double zmp_moment = 0;
    if (opt.zmp_shift_cap > 0) {
      double lowest = std::numeric_limits<double>::infinity();
      for (const auto& x : first) lowest = std::min(lowest, x.z());
      for (int l = 0; l < robot.numLinks(); ++l) zmp_moment += robot.links()[l].mass * (first[l].z() - lowest) * arc[l];
      zmp_moment /= robot.totalMass() * 9.81;
    }
    len = std::max(len, link_arc / opt.speed_cap);
    p.length = len;
    if (len <= 0) continue;
    // u'' bound: each joint within half its acceleration limit, each link within the cap.
    slope_[k] = (knots_[k + 1].joints - knots_[k].joints) / len;
    double A = std::numeric_limits<double>::infinity();
    for (const auto& j : robot.joints())
      if (slope_[k][j.index] != 0) A = std::min(A, 0.5 * jointAccel(j) / std::abs(slope_[k][j.index]));
    if (link_arc > 0) A = std::min(A, opt.link_acceleration_cap * len / link_arc);
    if (zmp_moment > 0) A = std::min(A, opt.zmp_shift_cap * len / zmp_moment);
    p.accel = A;
  }

  // The rate u' at each knot: at rest at both ends, low enough at a corner,
  // reachable from both sides within each segment's acceleration.
  std::vector<double> r(n + 1, 1.0);
  r[0] = r[n] = 0;
  int last = -1;  // the last segment that moves
  for (int k = 0; k < n; ++k) {
    if (seg_[k].length <= 0) continue;
    if (last >= 0) {
      double bound = std::numeric_limits<double>::infinity();
      for (const auto& j : robot.joints()) {
        const double jump = std::abs(slope_[k][j.index] - slope_[last][j.index]);
        if (jump > 0) bound = std::min(bound, 0.5 * jointAccel(j) * opt.dt / jump);
      }
      for (int i = last + 1; i <= k; ++i) r[i] = std::min(r[i], bound);
    }
    last = k;
  }
  auto reach = [&](int k, double from) { return std::sqrt(from * from + 2 * seg_[k].accel * seg_[k].length); };
  for (int k = n - 1; k >= 0; --k) r[k] = std::min(r[k], seg_[k].length > 0 ? reach(k, r[k + 1]) : r[k + 1]);
  for (int k = 0; k < n; ++k) r[k + 1] = std::min(r[k + 1], seg_[k].length > 0 ? reach(k, r[k]) : r[k]);

  start_.assign(n, 0.0);
  for (int k = 0; k < n; ++k) {
    Profile& p = seg_[k];
    start_[k] = profile_time_;
    p.r0 = r[k], p.r1 = r[k + 1];
    if (p.length <= 0) continue;
    const double A = p.accel;
    p.peak = std::min(1.0, std::sqrt(0.5 * (p.r0 * p.r0 + p.r1 * p.r1) + A * p.length));
    p.peak = std::max({p.peak, p.r0, p.r1});
    const double x_accel = (p.peak * p.peak - p.r0 * p.r0) / (2 * A);
    const double x_decel = (p.peak * p.peak - p.r1 * p.r1) / (2 * A);
    p.t_accel = (p.peak - p.r0) / A;
    p.t_decel = (p.peak - p.r1) / A;
    p.t_cruise = std::max(0.0, p.length - x_accel - x_decel) / p.peak;
    profile_time_ += p.time();
  }
  // Whole samples: the profile slowed to the next one (speeds and accelerations only drop).
  if (profile_time_ > 0) steps_ = std::max(1, static_cast<int>(std::ceil(profile_time_ / dt_ - 1e-9)));
}

int TimedPiece::locate(double tp, double* fraction, double* rate) const {
  const int n = static_cast<int>(seg_.size());
  int k = static_cast<int>(std::upper_bound(start_.begin(), start_.end(), tp) - start_.begin()) - 1;
  k = std::clamp(k, 0, n - 1);
  while (k + 1 < n && seg_[k].length <= 0) ++k;
  const Profile& p = seg_[k];
  double u = 0, r = 0;
  if (p.length > 0) p.at(tp - start_[k], &u, &r);
  if (fraction) *fraction = p.length > 0 ? u / p.length : 1.0;
  if (rate) *rate = r;
  return k;
}

int TimedPiece::segmentAt(double t) const {
  if (steps_ == 0 || seg_.empty()) return 0;
  const double tp = std::clamp(t / duration(), 0.0, 1.0) * profile_time_;
  return locate(tp, nullptr, nullptr);
}

Configuration TimedPiece::at(double t, Eigen::VectorXd* dq) const {
  const int nj = static_cast<int>(knots_.front().joints.size());
  if (dq) *dq = Eigen::VectorXd::Zero(nj);
  if (steps_ == 0 || seg_.empty() || t >= duration()) return knots_.back();
  if (t <= 0) return knots_.front();
  const double slow = profile_time_ / duration();  // <= 1: the profile stretched to whole samples
  double f = 0, rate = 0;
  const int k = locate(t * slow, &f, &rate);
  if (dq) *dq = slope_[k] * (rate * slow);
  return lerp(knots_[k], knots_[k + 1], f);
}

}  // namespace acyclic
