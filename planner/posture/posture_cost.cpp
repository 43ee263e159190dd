#include "planner/posture/posture_cost.h"

namespace acyclic {

ReferencePostureCost::ReferencePostureCost(Configuration reference, double w_joint, double w_position,
                                           double w_rotation, std::vector<SpotTarget> spot_targets)
    : ref_(std::move(reference)),
      ref_rotation_(ref_.base_orientation.normalized().toRotationMatrix()),
      wj_(w_joint), wp_(w_position), wr_(w_rotation), spots_(std::move(spot_targets)) {}

double ReferencePostureCost::evaluate(const Kinematics& kin, Eigen::Ref<Eigen::VectorXd> grad) const {
  const Configuration& q = kin.configuration();
  const Eigen::VectorXd dj = q.joints - ref_.joints;
  const Eigen::Vector3d dp = q.base_position - ref_.base_position;
  const Eigen::Matrix3d R = kin.linkPose(0).linear();
  const Eigen::Matrix3d D = R - ref_rotation_;
  // d|R - Rr|^2 = -2 tr(Rr^T [w]x R) = -2 tr(M [w]x), M = R Rr^T
  const Eigen::Matrix3d M = R * ref_rotation_.transpose();
  grad.segment<3>(0) += 2 * wp_ * dp;
  grad.segment<3>(3) += -2 * wr_ * Eigen::Vector3d(M(1, 2) - M(2, 1), M(2, 0) - M(0, 2), M(0, 1) - M(1, 0));
  grad.tail(dj.size()) += 2 * wj_ * dj;
  double spots = 0;
  for (const auto& t : spots_) {
    const Eigen::Vector3d s = kin.spotPose(t.spot).translation();
    const Eigen::Vector3d d = s - t.point;
    spots += t.weight * d.squaredNorm();
    kin.addPointGradient(kin.model().spots()[t.spot].link, s, 2 * t.weight * d, grad);
  }
  return wj_ * dj.squaredNorm() + wp_ * dp.squaredNorm() + wr_ * D.squaredNorm() + spots;
}

Eigen::VectorXd ReferencePostureCost::diagonalHessian(int n) const {
  Eigen::VectorXd d(n);
  d.segment<3>(0).setConstant(2 * wp_);
  d.segment<3>(3).setConstant(4 * wr_);  // |R - Rr|^2 ~ 2 |w|^2 near the reference
  d.tail(n - 6).setConstant(2 * wj_);
  return d;
}

}  // namespace acyclic
