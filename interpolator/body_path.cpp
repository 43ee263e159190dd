#include "interpolator/body_path.h"

#include <algorithm>
#include <cmath>

namespace acyclic {

namespace {
constexpr int kTableSteps = 256;  // arc-length table entries per spline segment
}

BodyPath::BodyPath(BodyPathEnd from, BodyPathEnd to, double lift, std::vector<Eigen::Vector3d> vias)
    : from_(std::move(from)), to_(std::move(to)), lift_(lift), vias_(std::move(vias)) {
  if (from_.normal) from_.normal->normalize(), lift0_ = lift;
  if (to_.normal) to_.normal->normalize(), lift1_ = lift;
  const Eigen::Vector3d a = from_.pose.translation() + lift0_ * from_.normal.value_or(Eigen::Vector3d::Zero());
  const Eigen::Vector3d b = to_.pose.translation() + lift1_ * to_.normal.value_or(Eigen::Vector3d::Zero());
  points_.push_back(a);
  for (const auto& v : vias_) points_.push_back(v);
  points_.push_back(b);
  const int m = static_cast<int>(points_.size());
  tangents_.resize(m);
  for (int i = 0; i < m; ++i) {
    if (i == 0) {
      // Tangents along the normals no longer than twice the lift: a long
      // motion does not bulge far above its straight parts.
      const double chord = std::min((points_[1] - points_[0]).norm(), 2 * lift);
      // Leaving along the normal: the spline starts in the direction of the
      // straight part (C1 at the junction, same speed per unit of u).
      tangents_[i] = from_.normal ? Eigen::Vector3d(chord * *from_.normal) : Eigen::Vector3d(points_[1] - points_[0]);
    } else if (i == m - 1) {
      const double chord = std::min((points_[m - 1] - points_[m - 2]).norm(), 2 * lift);
      tangents_[i] = to_.normal ? Eigen::Vector3d(-chord * *to_.normal) : Eigen::Vector3d(points_[m - 1] - points_[m - 2]);
    } else {
      tangents_[i] = 0.5 * (points_[i + 1] - points_[i - 1]);  // Catmull-Rom
    }
  }
  table_u_.push_back(0);
  table_len_.push_back(0);
  Eigen::Vector3d prev = points_[0];
  for (int seg = 0; seg + 1 < m; ++seg)
    for (int k = 1; k <= kTableSteps; ++k) {
      const double u = seg + static_cast<double>(k) / kTableSteps;
      const Eigen::Vector3d p = curvePoint(u);
      table_u_.push_back(u);
      table_len_.push_back(table_len_.back() + (p - prev).norm());
      prev = p;
    }
  curve_length_ = table_len_.back();
}

Eigen::Vector3d BodyPath::curvePoint(double u) const {
  const int nseg = static_cast<int>(points_.size()) - 1;
  const int seg = std::clamp(static_cast<int>(std::floor(u)), 0, nseg - 1);
  const double t = std::clamp(u - seg, 0.0, 1.0);
  const double t2 = t * t, t3 = t2 * t;
  // Cubic Hermite basis.
  return (2 * t3 - 3 * t2 + 1) * points_[seg] + (t3 - 2 * t2 + t) * tangents_[seg] + (-2 * t3 + 3 * t2) * points_[seg + 1] +
         (t3 - t2) * tangents_[seg + 1];
}

Eigen::Isometry3d BodyPath::pose(double s) const {
  const double L = length();
  const double d = std::clamp(s, 0.0, 1.0) * L;
  const Eigen::Quaterniond q0(from_.pose.linear()), q1(to_.pose.linear());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (d <= lift0_ && lift0_ > 0) {  // leaving straight along the normal
    T.linear() = from_.pose.linear();
    T.translation() = from_.pose.translation() + d * *from_.normal;
    return T;
  }
  if (d >= L - lift1_ && lift1_ > 0) {  // arriving straight along the normal
    T.linear() = to_.pose.linear();
    T.translation() = to_.pose.translation() + (L - d) * *to_.normal;
    return T;
  }
  const double c = d - lift0_;
  const auto it = std::lower_bound(table_len_.begin(), table_len_.end(), c);
  double u = table_u_.back();
  if (it != table_len_.end()) {
    const std::size_t i = std::max<std::size_t>(1, it - table_len_.begin());
    const double span = table_len_[i] - table_len_[i - 1];
    const double f = span > 0 ? (c - table_len_[i - 1]) / span : 0.0;
    u = table_u_[i - 1] + f * (table_u_[i] - table_u_[i - 1]);
  }
  T.translation() = curvePoint(u);
  if (!via_orientations_.empty()) {
    // Between two consecutive waypoints, by the arc length from the first.
    const int nseg = static_cast<int>(points_.size()) - 1;
    const int seg = std::clamp(static_cast<int>(std::floor(u)), 0, nseg - 1);
    const double l0 = table_len_[seg * kTableSteps], l1 = table_len_[(seg + 1) * kTableSteps];
    const double f = l1 - l0 > 1e-9 ? std::clamp((c - l0) / (l1 - l0), 0.0, 1.0) : 0.5;
    const Eigen::Quaterniond a = seg == 0 ? q0 : via_orientations_[seg - 1];
    const Eigen::Quaterniond b = seg + 1 == nseg ? q1 : via_orientations_[seg];
    T.linear() = a.slerp(f, b).toRotationMatrix();
    return T;
  }
  const double frac = curve_length_ > 1e-9 ? c / curve_length_ : 0.5;
  T.linear() = q0.slerp(std::clamp(frac, 0.0, 1.0), q1).toRotationMatrix();
  return T;
}

BodyPath BodyPath::through(const std::vector<Eigen::Isometry3d>& waypoints) const {
  std::vector<Eigen::Vector3d> vias;
  for (const auto& w : waypoints) vias.push_back(w.translation());
  BodyPath p(from_, to_, lift_, std::move(vias));
  for (const auto& w : waypoints) p.via_orientations_.emplace_back(w.linear());
  return p;
}

Eigen::Isometry3d BodyPath::splineStart() const {
  Eigen::Isometry3d T = from_.pose;
  T.translation() = points_.front();
  return T;
}

Eigen::Isometry3d BodyPath::splineEnd() const {
  Eigen::Isometry3d T = to_.pose;
  T.translation() = points_.back();
  return T;
}

bool BodyPath::straightAt(double s) const {
  const double d = std::clamp(s, 0.0, 1.0) * length();
  return (lift0_ > 0 && d <= lift0_ + 1e-12) || (lift1_ > 0 && d >= length() - lift1_ - 1e-12);
}

double BodyPath::leaveParameter(double clearance) const {
  return from_.normal && length() > 0 ? std::min(clearance, lift0_) / length() : 0.0;
}

double BodyPath::arriveParameter(double clearance) const {
  return to_.normal && length() > 0 ? 1.0 - std::min(clearance, lift1_) / length() : 1.0;
}

Eigen::Vector3d BodyPath::up() const {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  if (from_.normal) up += *from_.normal;
  if (to_.normal) up += *to_.normal;
  if (up.norm() < 1e-6) up = Eigen::Vector3d::UnitZ();
  return up.normalized();
}

Eigen::Vector3d BodyPath::viaPoint(double at, double height, double across) const {
  const Eigen::Vector3d u = up(), a = points_.front(), b = points_.back();
  const double top = std::max(a.dot(u), b.dot(u)) + height;
  Eigen::Vector3d side = u.cross(b - a);
  side = side.norm() > 1e-9 ? Eigen::Vector3d(side.normalized()) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d v = a + at * (b - a);
  return v + (top - v.dot(u)) * u + across * side;
}

BodyPath BodyPath::detoured(double at, double across) const {
  return BodyPath(from_, to_, lift_, {viaPoint(at, 0, across)});
}

BodyPath BodyPath::bridged(double height, double across) const {
  // A bridge: rise to `height` above the higher end of the spline by a third
  // of the way, cross at that height, come down over the last third. It
  // clears an obstacle between the ends, or an edge the lower end is below.
  return BodyPath(from_, to_, lift_, {viaPoint(1.0 / 3, height, across), viaPoint(2.0 / 3, height, across)});
}

}  // namespace acyclic
