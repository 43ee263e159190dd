#pragma once
// A trajectory file with the scenario it was planned in: the scenario given,
// or else the one the file names (its `scenario` field, resolved by
// planner/plan/scenario_reference.h). FormatError naming the file and field
// on bad input.
#include <string>

#include "planner/plan/trajectory.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

struct LoadedTrajectory {
  Scenario scenario;
  Trajectory trajectory;
};

LoadedTrajectory loadTrajectoryFile(const std::string& path, const std::string& scenario_path = "");

}  // namespace acyclic::hrp2
