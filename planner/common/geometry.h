#pragma once
// Small geometric helpers shared by the model, the scene and the checks.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

namespace acyclic {

// Roll-pitch-yaw (rotations about fixed x, then y, then z: R = Rz Ry Rx), as in URDF.
Eigen::Quaterniond rpyToQuaternion(const Eigen::Vector3d& rpy);
Eigen::Vector3d quaternionToRpy(const Eigen::Quaterniond& q);

// Rotation vector (axis times angle) to rotation and back.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& w);
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);

// A convex polygon in a plane, vertices counter-clockwise.
class ConvexPolygon {
 public:
  ConvexPolygon() = default;
  // Throws std::invalid_argument (with the reason) when the vertices do not
  // form a convex polygon with positive area; clockwise input is reversed.
  explicit ConvexPolygon(std::vector<Eigen::Vector2d> vertices);

  const std::vector<Eigen::Vector2d>& vertices() const { return v_; }
  std::size_t size() const { return v_.size(); }
  // Signed distance from p to the boundary: negative inside, positive outside
  // (exact outside, minus the distance to the nearest edge inside).
  double signedDistance(const Eigen::Vector2d& p) const;
  // The point of the boundary nearest p (inside or out).
  Eigen::Vector2d nearestBoundaryPoint(const Eigen::Vector2d& p) const;
  bool contains(const Eigen::Vector2d& p, double tolerance = 0.0) const {
    return signedDistance(p) <= tolerance;
  }
  double area() const;
  Eigen::Vector2d centroid() const;
  // The polygon shrunk by d >= 0: every edge moved inward by d along its
  // normal, so that its points are at least d inside every edge of this one.
  // d is capped at three quarters of the centroid's distance to the nearest
  // edge, so that a small polygon keeps a positive size (at least a quarter
  // of its own about the centroid). Where moving the edges would make one vanish (a short edge
  // between two sharp corners), the polygon is scaled about the centroid
  // instead, each edge moving inward by at least the capped d.
  ConvexPolygon inset(double d) const;
  // Shrunk by a box: the points p such that p + [-dx, dx] x [-dy, dy] is
  // inside (an edge of outward normal n moved inward by dx |n_x| + dy |n_y|);
  // (dx, dy) scaled down where an edge would move more than three quarters
  // of the centroid's distance to it, scaled about the centroid where one
  // would vanish (as inset(d)). For dx = dy it is inset(dx).
  ConvexPolygon inset(double dx, double dy) const;

 private:
  // Both insets: edge i (outward unit normal n) moved inward by move(n),
  // capped and, where an edge would vanish, scaled about the centroid.
  ConvexPolygon insetEdges(const std::function<double(const Eigen::Vector2d&)>& move) const;

  std::vector<Eigen::Vector2d> v_;
};

}  // namespace acyclic
