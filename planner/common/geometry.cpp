#include "planner/common/geometry.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

namespace acyclic {

Eigen::Quaterniond rpyToQuaternion(const Eigen::Vector3d& rpy) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()));
}

Eigen::Vector3d quaternionToRpy(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  double roll = std::atan2(R(2, 1), R(2, 2));
  double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& w) {
  double a = w.norm();
  if (a < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

ConvexPolygon::ConvexPolygon(std::vector<Eigen::Vector2d> v) : v_(std::move(v)) {
  const std::size_t n = v_.size();
  if (n < 3) throw std::invalid_argument("a polygon needs at least 3 vertices");
  double a2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = v_[i];
    const auto& q = v_[(i + 1) % n];
    a2 += p.x() * q.y() - q.x() * p.y();
  }
  if (std::abs(a2) < 1e-12) throw std::invalid_argument("the polygon has zero area");
  if (a2 < 0) std::reverse(v_.begin(), v_.end());
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector2d e1 = v_[(i + 1) % n] - v_[i];
    Eigen::Vector2d e2 = v_[(i + 2) % n] - v_[(i + 1) % n];
    if (e1.norm() < 1e-12) throw std::invalid_argument("the polygon repeats a vertex");
    if (e1.x() * e2.y() - e1.y() * e2.x() < -1e-12)
      throw std::invalid_argument("the polygon is not convex (vertex " + std::to_string((i + 1) % n) + ")");
  }
}

Eigen::Vector2d ConvexPolygon::nearestBoundaryPoint(const Eigen::Vector2d& p) const {
  const std::size_t n = v_.size();
  Eigen::Vector2d best = v_[0];
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d a = v_[i], e = v_[(i + 1) % n] - a;
    const Eigen::Vector2d q = a + std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0) * e;
    if ((q - p).norm() < best_distance) best_distance = (q - p).norm(), best = q;
  }
  return best;
}

double ConvexPolygon::signedDistance(const Eigen::Vector2d& p) const {
  const std::size_t n = v_.size();
  double max_out = -std::numeric_limits<double>::infinity();  // max signed edge distance
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d a = v_[i], e = v_[(i + 1) % n] - a;
    const Eigen::Vector2d outward(e.y(), -e.x());
    max_out = std::max(max_out, outward.normalized().dot(p - a));
  }
  const double to_boundary = (nearestBoundaryPoint(p) - p).norm();  // exact
  return max_out > 0 ? to_boundary : -to_boundary;
}

double ConvexPolygon::area() const {
  double a2 = 0;
  for (std::size_t i = 0; i < v_.size(); ++i) {
    const auto& p = v_[i];
    const auto& q = v_[(i + 1) % v_.size()];
    a2 += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a2;
}

ConvexPolygon ConvexPolygon::inset(double d) const {
  if (!(d >= 0) || !std::isfinite(d)) throw std::invalid_argument("polygon inset: expected a finite d >= 0");
  return insetEdges([d](const Eigen::Vector2d&) { return d; });
}

ConvexPolygon ConvexPolygon::inset(double dx, double dy) const {
  if (!(dx >= 0 && dy >= 0) || !std::isfinite(dx) || !std::isfinite(dy))
    throw std::invalid_argument("polygon inset: expected finite dx, dy >= 0");
  if (dx == dy) return inset(dx);  // a disc's erosion, not a square's: edges move by d whatever their direction
  return insetEdges([dx, dy](const Eigen::Vector2d& n) { return dx * std::abs(n.x()) + dy * std::abs(n.y()); });
}

ConvexPolygon ConvexPolygon::insetEdges(const std::function<double(const Eigen::Vector2d&)>& move) const {
  const Eigen::Vector2d c = centroid();
  const std::size_t n = v_.size();
  std::vector<Eigen::Vector2d> normal(n);  // outward unit normal of edge i (v_i to v_i+1)
  std::vector<double> d(n), h(n);          // edge i's move inward, the centroid's distance to it
  double scale = 1;
  bool moves = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e = v_[(i + 1) % n] - v_[i];
    normal[i] = Eigen::Vector2d(e.y(), -e.x()).normalized();
    d[i] = move(normal[i]);
    h[i] = normal[i].dot(v_[i] - c);
    moves = moves || d[i] > 0;
    if (d[i] > 0.75 * h[i]) scale = std::min(scale, 0.75 * h[i] / d[i]);
  }
  if (!moves) return *this;
  for (double& di : d) di *= scale;
  // Vertex i joins edges i-1 and i: the point d[i-1] inside the first, d[i] inside the second.
  std::vector<Eigen::Vector2d> w(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = (i + n - 1) % n;
    Eigen::Matrix2d M;
    M.row(0) = normal[a].transpose();
    M.row(1) = normal[i].transpose();
    w[i] = v_[i] - M.inverse() * Eigen::Vector2d(d[a], d[i]);
  }
  bool kept = true;  // every edge keeps its direction: none vanished
  for (std::size_t i = 0; i < n && kept; ++i)
    kept = (w[(i + 1) % n] - w[i]).dot(v_[(i + 1) % n] - v_[i]) > 0;
  if (!kept) {
    double s = 1;  // edge i moves inward by (1 - s) * h_i >= d_i
    for (std::size_t i = 0; i < n; ++i) s = std::min(s, 1 - d[i] / h[i]);
    for (std::size_t i = 0; i < n; ++i) w[i] = c + s * (v_[i] - c);
  }
  return ConvexPolygon(std::move(w));
}

Eigen::Vector2d ConvexPolygon::centroid() const {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double a2 = 0;
  for (std::size_t i = 0; i < v_.size(); ++i) {
    const auto& p = v_[i];
    const auto& q = v_[(i + 1) % v_.size()];
    double cr = p.x() * q.y() - q.x() * p.y();
    a2 += cr;
    c += (p + q) * cr;
  }
  return c / (3.0 * a2);
}

}  // namespace acyclic
