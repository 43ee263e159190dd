#pragma once
// Waist and ZMP references for HRP-2's controller, from the quasi-static
// model (the motion is slow enough that the ZMP is the centre of pressure of
// the static contact forces):
// - only coplanar feet: the centre of mass projected along gravity onto the
//   feet's plane (there, the only possible centre of pressure);
// - otherwise: the centre of pressure of the feet's forces in the quasi-static
//   LP (planner/check/quasi_static.h) - what the ankle force sensors see while
//   hands, knees or thighs carry the rest; the CoM projection when the feet
//   carry less than 1% of the weight or the LP has no solution (counted).
//   Where extra contacts carry load the forces are not unique, and an LP
//   solved from scratch lands on whichever vertex its method finds: with the
//   eight-facet friction pyramid the feet's centre of pressure then swept
//   23 cm in 0.15 s under a slow arm motion. Each LP therefore starts from
//   the previous sample's optimal basis (QuasiStaticChecker::setWarmStart),
//   so the forces move continuously while that basis stays optimal; samples
//   are computed in order, so the same trajectory gives the same references.
// The ZMP is given in the world and in the waist (base) frame, as the
// SequencePlayer's .zmp file wants it.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "planner/check/quasi_static.h"
#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

struct WaistZmp {
  Eigen::Vector3d waist_position = Eigen::Vector3d::Zero();  // world
  Eigen::Vector3d waist_rpy = Eigen::Vector3d::Zero();       // world, URDF roll-pitch-yaw
  Eigen::Vector3d zmp_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d zmp_waist = Eigen::Vector3d::Zero();
  bool from_forces = false;   // the feet's centre of pressure (else the CoM projection)
  bool lp_failed = false;     // the LP had no solution: the CoM projection stands in
};

class ReferenceModel {
 public:
  ReferenceModel(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene);
  // At configuration q with the phase's contacts; `coplanar_feet` from the
  // stabilizer schedule (only coplanar feet: no LP needed).
  WaistZmp compute(const Configuration& q, const std::vector<ContactSpec>& contacts, bool coplanar_feet);

 private:
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  Kinematics kin_;
  QuasiStaticChecker lp_;
};

}  // namespace acyclic::hrp2
