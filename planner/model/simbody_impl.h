#pragma once
// Private to the model library: the Simbody system behind RobotModel.
// Include only from files compiled with -UNDEBUG (see planner/CMakeLists.txt).
#include <Simbody.h>

#include <vector>

#include "planner/model/robot_model.h"

namespace acyclic {

struct RobotModel::Impl {
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  std::vector<SimTK::MobilizedBodyIndex> link_mobod;  // by link index
  SimTK::MobilizedBodyIndex base_mobod;
  std::vector<int> tangent_of_u;   // Simbody generalized speed index -> tangent index
  std::vector<int> q_of_joint;     // controller joint index -> Simbody q index
  SimTK::State default_state;      // realized to Topology/Model
  Eigen::Vector3d gravity{0, 0, -9.81};
};

}  // namespace acyclic
