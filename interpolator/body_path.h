#pragma once
// The moving body's path between two stances (docs/design.md section 10): straight
// along the surface normal where it leaves a surface and where it reaches one,
// a C1 cubic spline between (through raised via-points after a repair), the
// orientation held on the straight parts (a sole stays flat near the floor)
// and slerped along the spline. Parameterized by arc length, s in [0, 1].
#include <optional>
#include <vector>

#include <Eigen/Geometry>

namespace acyclic {

struct BodyPathEnd {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // the spot's world frame
  std::optional<Eigen::Vector3d> normal;  // outward surface normal when the end is on a surface
};

class BodyPath {
 public:
  // `lift`: length of each straight part; `vias`: points the spline passes through.
  BodyPath(BodyPathEnd from, BodyPathEnd to, double lift, std::vector<Eigen::Vector3d> vias = {});

  double length() const { return lift0_ + curve_length_ + lift1_; }
  Eigen::Isometry3d pose(double s) const;
  // The parameter at which the body is `clearance` off its start (end) surface
  // along the normal; 0 (1) when that end is not on a surface.
  double leaveParameter(double clearance) const;
  // Whether s lies on a straight part (near a surface: orientation held).
  bool straightAt(double s) const;
  // Where the straight parts meet the spline (0 and 1 when an end has none).
  double liftEndParameter() const { return length() > 0 ? lift0_ / length() : 0.0; }
  double arriveStartParameter() const { return length() > 0 ? 1.0 - lift1_ / length() : 1.0; }
  double arriveParameter(double clearance) const;

  // The same ends with two via-points, at a third and two thirds of the way,
  // `height` above the higher end of the spline (along the mean of the end
  // normals, or world z): a repair that raises the path away from what it
  // collides with.
  BodyPath raised(double height) const { return bridged(height, 0); }
  // The same bridge moved `across` sideways (across the chord, square to
  // `up`; positive to the left of the chord seen from above): a detour
  // around what the body would sweep through on its way, as a chair's leg
  // beside a foot that steps past it, which no height clears.
  BodyPath bridged(double height, double across) const;
  // One via-point at fraction `at` of the way, at the higher end's height,
  // `across` sideways (as bridged's): a detour that turns early or late, as a
  // foot that must first step sideways past a post and then back.
  BodyPath detoured(double at, double across) const;
  // The same ends through planned waypoints (positions and orientations),
  // the orientation slerped between consecutive ones instead of from end to
  // end: a path planned around the obstacles (body_path_planner.h).
  BodyPath through(const std::vector<Eigen::Isometry3d>& waypoints) const;
  const std::vector<Eigen::Vector3d>& vias() const { return vias_; }
  // Where the spline starts and ends (the tops of the straight parts), with
  // the end orientations: what a planned path connects.
  Eigen::Isometry3d splineStart() const;
  Eigen::Isometry3d splineEnd() const;
  // Along the mean of the end normals (or world z): where a repair raises the path.
  Eigen::Vector3d up() const;

 private:
  Eigen::Vector3d curvePoint(double u) const;  // u in [0, number of spline segments]
  // A repair's via-point: at fraction `at` of the spline's chord, `height` above its higher end, `across` sideways.
  Eigen::Vector3d viaPoint(double at, double height, double across) const;
  BodyPathEnd from_, to_;
  double lift_;
  double lift0_ = 0, lift1_ = 0;
  std::vector<Eigen::Vector3d> vias_;
  std::vector<Eigen::Quaterniond> via_orientations_;  // empty: slerp from end to end
  std::vector<Eigen::Vector3d> points_, tangents_;  // spline knots and their tangents
  std::vector<double> table_u_, table_len_;         // arc-length table of the spline
  double curve_length_ = 0;
};

}  // namespace acyclic
