#include "hrp2_bridge/trajectory_file.h"

#include <fstream>
#include <sstream>

#include "planner/common/format_error.h"
#include "planner/plan/scenario_reference.h"

namespace acyclic::hrp2 {

LoadedTrajectory loadTrajectoryFile(const std::string& path, const std::string& scenario_path) {
  std::ifstream in(path);
  if (!in) throw FormatError(path, "", "cannot open the trajectory file");
  std::stringstream text;
  text << in.rdbuf();
  const std::string sc_path = scenario_path.empty() ? scenarioNamedBy(path) : scenario_path;
  LoadedTrajectory r{Scenario::load(sc_path), {}};
  r.trajectory = trajectoryFromJson(text.str(), path, r.scenario);
  return r;
}

}  // namespace acyclic::hrp2
