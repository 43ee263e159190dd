#pragma once
// The robot: URDF (joints, limits, masses, collision primitives) plus the
// robot description YAML beside it (controller order, contact spots,
// self-collision pairs, named postures). Immutable once loaded, so one model
// is shared by every thread; per-thread evaluation lives in Kinematics.
//
// Simbody is hidden behind this header (docs/design.md section 4: code including
// Simbody headers must be built with -UNDEBUG).
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "planner/common/geometry.h"
#include "planner/model/configuration.h"

namespace acyclic {

class YamlField;

struct JointInfo {
  std::string name;
  int index = -1;            // controller order
  int parent_link = -1;
  int child_link = -1;
  Eigen::Vector3d axis;      // in the joint frame (= child link frame)
  // The joint frame in its parent link's at angle zero (the URDF's origin):
  // child pose = parent pose * origin * rotation(axis, angle).
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  double lower = 0, upper = 0;   // rad
  double velocity = 0;       // rad/s
  double effort = 0;         // N m
  // rad/s^2: what a trajectory may ask of the joint (the time law keeps under
  // it; the trajectory check measures it from positions). The robot file's
  // acceleration_limits, kDefaultJointAcceleration where it says nothing.
  double acceleration = 0;
};

// HRP-2's public facts give no acceleration limit. 4 rad/s^2 is an
// engineering figure: a joint reaches its velocity limit (about 4 rad/s) in a
// second, and a link a metre out accelerates at 0.4 g at most (the time law's
// link cap keeps whole-body motions far gentler, quasi-static).
constexpr double kDefaultJointAcceleration = 4.0;

struct CollisionShape {
  enum class Kind { Box, Capsule, Sphere, Cylinder };
  Kind kind = Kind::Box;
  std::string name;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // box: full sizes
  double radius = 0;         // capsule, sphere, cylinder
  double length = 0;         // capsule: segment length; cylinder: height (along local z)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // in the owner's frame
};

struct LinkInfo {
  std::string name;
  int index = -1;
  int parent_joint = -1;     // -1 for the base link
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();   // link frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the com, link axes
  std::vector<CollisionShape> shapes;
};

struct ContactSpot {
  std::string name;
  int link = -1;
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();  // in the link; z inward
  ConvexPolygon polygon;
};

class RobotModel {
 public:
  // Loads an acyclic.robot/1 YAML and the URDF it names; FormatError on bad input.
  static std::shared_ptr<const RobotModel> load(const std::string& yaml_path);
  ~RobotModel();

  const std::string& name() const { return name_; }
  const std::string& descriptionPath() const { return yaml_path_; }
  const std::string& urdfPath() const { return urdf_path_; }
  int numJoints() const { return static_cast<int>(joints_.size()); }
  int tangentSize() const { return 6 + numJoints(); }
  int numLinks() const { return static_cast<int>(links_.size()); }
  int baseLink() const { return 0; }

  const std::vector<JointInfo>& joints() const { return joints_; }
  const std::vector<LinkInfo>& links() const { return links_; }
  const std::vector<ContactSpot>& spots() const { return spots_; }
  const std::vector<std::pair<int, int>>& selfCollisionPairs() const { return self_pairs_; }
  const std::map<std::string, Configuration>& postures() const { return postures_; }

  // Static tree structure (controller joint indices):
  const std::vector<int>& ancestorJoints(int link) const { return ancestors_[link]; }  // base to link
  bool jointMovesLink(int joint, int link) const { return moves_[joint][link]; }
  // The joints `joint` moves, itself included (a limb's, from its root), in controller order.
  std::vector<int> jointsMovedBy(int joint) const;
  double subtreeMass(int joint) const { return subtree_mass_[joint]; }  // links moved by the joint
  // The joint a link's limb hangs from: the last one on the way from the base
  // whose parent link branches (a leg's hip yaw, an arm's shoulder); -1 for
  // the trunk's links above every branch.
  int limbRootJoint(int link) const { return limb_root_[link]; }
  int spotLimbRootJoint(int spot) const { return limb_root_[spots_[spot].link]; }

  int jointIndex(const std::string& name) const;  // -1 if unknown
  int linkIndex(const std::string& name) const;
  int spotIndex(const std::string& name) const;
  std::vector<std::string> jointNames() const;
  double totalMass() const;

  Eigen::VectorXd lowerLimits() const;
  Eigen::VectorXd upperLimits() const;
  Eigen::VectorXd velocityLimits() const;
  Eigen::VectorXd accelerationLimits() const;
  Eigen::VectorXd effortLimits() const;

  // Reads a configuration from YAML: optional `posture` (a named posture to
  // start from), `base_position`, `base_orientation` [w,x,y,z] or `base_rpy_deg`,
  // and joints as `joints` (list of all, rad) or maps `joints_rad` / `joints_deg`
  // overriding named joints.
  Configuration readConfiguration(const YamlField& f) const;
  Configuration zeroConfiguration() const;
  const Configuration& posture(const std::string& name) const;  // throws std::out_of_range

  struct Impl;  // Simbody system; used by Kinematics
  const Impl& impl() const { return *impl_; }

 private:
  RobotModel();
  std::string name_, yaml_path_, urdf_path_;
  std::vector<JointInfo> joints_;
  std::vector<LinkInfo> links_;
  std::vector<ContactSpot> spots_;
  std::vector<std::pair<int, int>> self_pairs_;
  std::map<std::string, Configuration> postures_;
  std::vector<std::vector<int>> ancestors_;
  std::vector<std::vector<bool>> moves_;
  std::vector<double> subtree_mass_;
  std::vector<int> limb_root_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace acyclic
