#pragma once
// A whole-body configuration and its tangent space.
//
// Storage (files, messages): base position (3), base orientation unit
// quaternion (w, x, y, z), joint angles in controller order. SI units.
//
// Tangent space (velocities, Jacobian columns, gradients), size 6 + n:
//   [0, 3)   base translation, world frame
//   [3, 6)   base rotation vector, world frame (R <- exp(w) R)
//   [6, 6+n) joint angles, controller order
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace acyclic {

struct Configuration {
  Eigen::Vector3d base_position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond base_orientation = Eigen::Quaterniond::Identity();
  Eigen::VectorXd joints;

  int tangentSize() const { return 6 + static_cast<int>(joints.size()); }
  Eigen::Isometry3d basePose() const;
};

// q (+) dq: moves q along the tangent vector dq (see the layout above).
Configuration integrate(const Configuration& q, const Eigen::VectorXd& dq);
// The tangent vector dq such that integrate(q0, dq) == q1.
Eigen::VectorXd difference(const Configuration& q0, const Configuration& q1);

}  // namespace acyclic
