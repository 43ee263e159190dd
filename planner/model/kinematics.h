#pragma once
// Per-thread evaluation of a RobotModel at one configuration: world poses,
// Jacobians, centre of mass, gravity torques (Simbody underneath).
//
// Jacobians are with respect to the tangent space of Configuration
// (configuration.h): columns [translation(3), rotation(3), joints(n)].
// A frame Jacobian's rows are [linear velocity(3); angular velocity(3)],
// world frame. One Kinematics per thread; the model is shared.
#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "planner/model/robot_model.h"

namespace acyclic {

class Kinematics {
 public:
  explicit Kinematics(std::shared_ptr<const RobotModel> model);
  ~Kinematics();
  Kinematics(const Kinematics&) = delete;
  Kinematics& operator=(const Kinematics&) = delete;

  const RobotModel& model() const { return *model_; }
  const std::shared_ptr<const RobotModel>& modelPtr() const { return model_; }

  void setConfiguration(const Configuration& q);
  // Only what collision queries read (link poses, joint axes and origins),
  // composed along the tree from the joints' origins without Simbody: a
  // tenth of setConfiguration's time, for clearance checks in bulk (the
  // limb path planner's). The poses agree with setConfiguration's to
  // rounding, not bit for bit: fit for yes-or-no answers against margins
  // of millimetres, not for the posture generator, whose searches hinge on
  // the last bits. Until the next setConfiguration, the Simbody queries
  // (Jacobians, centre of mass, gravity torques) throw std::logic_error.
  void setPoses(const Configuration& q);
  const Configuration& configuration() const { return q_; }

  // Cached at setConfiguration and setPoses (no Simbody call).
  const Eigen::Isometry3d& linkPose(int link) const { return link_pose_[link]; }
  const Eigen::Vector3d& jointAxis(int joint) const { return joint_axis_[joint]; }      // world
  const Eigen::Vector3d& jointOrigin(int joint) const { return joint_origin_[joint]; }  // world
  Eigen::Isometry3d spotPose(int spot) const;
  // Jacobian (3 x tangent) of a point fixed on a link, given in link coordinates.
  Eigen::MatrixXd pointJacobian(int link, const Eigen::Vector3d& point_in_link) const;
  // Jacobian (6 x tangent) of a frame fixed on a link, origin given in link coordinates.
  Eigen::MatrixXd frameJacobian(int link, const Eigen::Vector3d& origin_in_link) const;
  // The same Jacobians from the cached joint axes (the hot path of the
  // posture generator; tested against Simbody's): a point moving with a link,
  // given in world coordinates.
  Eigen::MatrixXd chainPointJacobian(int link, const Eigen::Vector3d& world_point) const;
  // grad += J(point)^T v: the gradient of v . point, without forming J.
  void addPointGradient(int link, const Eigen::Vector3d& world_point, const Eigen::Vector3d& v,
                        Eigen::Ref<Eigen::VectorXd> grad) const;
  // grad += d(u . w)/dq for a unit vector u fixed on a link and a constant w.
  void addAxisGradient(int link, const Eigen::Vector3d& u, const Eigen::Vector3d& w,
                       Eigen::Ref<Eigen::VectorXd> grad) const;

  Eigen::Vector3d centerOfMass() const;
  Eigen::MatrixXd centerOfMassJacobian() const;  // 3 x tangent
  // Generalized forces that hold the robot still against gravity, g(q): the
  // tangent-space vector such that equilibrium reads  tau + sum J^T f = g(q).
  // Entries [0, 6) are the base's (force, moment about the base origin, world).
  Eigen::VectorXd gravityTorques() const;

 private:
  struct State;
  void requireSize(const Configuration& q) const;  // std::invalid_argument on another joint count
  void setJointFrames();
  void requireSimbody(const char* query) const;  // throws after setPoses
  std::shared_ptr<const RobotModel> model_;
  std::unique_ptr<State> state_;
  Configuration q_;
  bool simbody_current_ = false;  // the Simbody state is at q_
  std::vector<Eigen::Isometry3d> link_pose_;
  std::vector<Eigen::Vector3d> joint_axis_, joint_origin_;
};

}  // namespace acyclic
