#pragma once
// Contact forces a simulated robot would measure, from the quasi-static model:
// the spots that touch a surface (geometrically, at the current
// configuration) all support, and the quasi-static LP
// (planner/check/quasi_static.h) gives forces at their corners; each
// contact's resultant is reported as a wrench in the spot's frame (its
// "sensor frame").
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "planner/check/quasi_static.h"
#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

struct ContactWrench {
  std::string name;                                  // the spot
  Eigen::Matrix<double, 6, 1> wrench = Eigen::Matrix<double, 6, 1>::Zero();  // force, moment (spot frame)
};

class ContactForces {
 public:
  ContactForces(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene);
  // Spots within `distance` m of a surface's plane, normals opposed within
  // `angle` rad, origin inside the surface polygon (with the same margin).
  std::vector<ContactSpec> detect(const Configuration& q, double distance = 0.01, double angle = 0.1);
  // The detected contacts' wrenches; `equilibrium` false when the LP finds no forces.
  std::vector<ContactWrench> compute(const Configuration& q, bool* equilibrium);

 private:
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  Kinematics kin_;
  QuasiStaticChecker lp_;
};

}  // namespace acyclic::hrp2
