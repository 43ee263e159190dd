#include "planner/model/configuration.h"

#include <stdexcept>

#include "planner/common/geometry.h"

namespace acyclic {

Eigen::Isometry3d Configuration::basePose() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = base_orientation.normalized().toRotationMatrix();
  T.translation() = base_position;
  return T;
}

Configuration integrate(const Configuration& q, const Eigen::VectorXd& dq) {
  if (dq.size() != q.tangentSize()) throw std::invalid_argument("integrate: tangent size mismatch");
  Configuration out = q;
  out.base_position += dq.segment<3>(0);
  out.base_orientation =
      Eigen::Quaterniond(expSO3(dq.segment<3>(3)) * q.base_orientation.normalized().toRotationMatrix());
  out.joints += dq.tail(q.joints.size());
  return out;
}

Eigen::VectorXd difference(const Configuration& q0, const Configuration& q1) {
  if (q0.joints.size() != q1.joints.size()) throw std::invalid_argument("difference: joint count mismatch");
  Eigen::VectorXd dq(q0.tangentSize());
  dq.segment<3>(0) = q1.base_position - q0.base_position;
  dq.segment<3>(3) = logSO3(q1.base_orientation.normalized().toRotationMatrix() *
                            q0.base_orientation.normalized().toRotationMatrix().transpose());
  dq.tail(q0.joints.size()) = q1.joints - q0.joints;
  return dq;
}

}  // namespace acyclic
