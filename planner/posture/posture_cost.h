#pragma once
// Costs of the posture generator, behind one interface (docs/design.md section 6):
// distance to a reference posture now, the guide potential f_T later.
#include <vector>

#include <Eigen/Core>

#include "planner/model/kinematics.h"

namespace acyclic {

class PostureCost {
 public:
  virtual ~PostureCost() = default;
  // The cost at the kinematics' configuration; adds its gradient (tangent
  // space, configuration.h) to grad.
  virtual double evaluate(const Kinematics& kin, Eigen::Ref<Eigen::VectorXd> grad) const = 0;
  // A constant positive diagonal approximating the cost's Hessian in the
  // tangent space (the solver's curvature when asked not to use L-BFGS).
  virtual Eigen::VectorXd diagonalHessian(int tangent_size) const = 0;
};

// w_joint |q - r|^2 + w_position |p - p_r|^2 + w_rotation |R - R_r|_F^2
// (p, R: the base's), plus w_i |s_i - t_i|^2 for each spot target: a spot's
// origin s_i pulled toward a world point t_i (a free foot kept on its own
// path while the interpolator moves another body).
class ReferencePostureCost : public PostureCost {
 public:
  struct SpotTarget {
    int spot = -1;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    double weight = 0;
  };
  explicit ReferencePostureCost(Configuration reference, double w_joint = 1.0, double w_position = 10.0,
                                double w_rotation = 1.0, std::vector<SpotTarget> spot_targets = {});
  double evaluate(const Kinematics& kin, Eigen::Ref<Eigen::VectorXd> grad) const override;
  // The reference's terms only: a spot target's curvature depends on the
  // configuration (2 w J^T J), none of it diagonal.
  Eigen::VectorXd diagonalHessian(int tangent_size) const override;
  const Configuration& reference() const { return ref_; }

 private:
  Configuration ref_;
  Eigen::Matrix3d ref_rotation_;
  double wj_, wp_, wr_;
  std::vector<SpotTarget> spots_;
};

}  // namespace acyclic
