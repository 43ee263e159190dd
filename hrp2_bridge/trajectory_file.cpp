#include "hrp2_bridge/trajectory_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "planner/common/format_error.h"

namespace acyclic::hrp2 {

namespace fs = std::filesystem;

LoadedTrajectory loadTrajectoryFile(const std::string& path, const std::string& scenario_path) {
  std::ifstream in(path);
  if (!in) throw FormatError(path, "", "cannot open the trajectory file");
  std::stringstream text;
  text << in.rdbuf();
  std::string sc_path = scenario_path;
  if (sc_path.empty()) {
    // Only the scenario's name is needed before the scenario can read the rest.
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::exception& e) {
      throw FormatError(path, "", std::string("not JSON: ") + e.what());
    }
    if (!j.is_object() || !j.contains("scenario") || !j["scenario"].is_string() ||
        j["scenario"].get<std::string>().empty())
      throw FormatError(path, "scenario", "the scenario file (or give it with --scenario)");
    sc_path = j["scenario"].get<std::string>();
    if (!fs::exists(sc_path)) {
      const fs::path beside = fs::path(path).parent_path() / sc_path;
      if (fs::exists(beside)) sc_path = beside.string();
      else throw FormatError(path, "scenario", "an existing scenario file, got '" + sc_path +
                                                   "' (not found from here nor beside the trajectory; give --scenario)");
    }
  }
  LoadedTrajectory r{Scenario::load(sc_path), {}};
  r.trajectory = trajectoryFromJson(text.str(), path, r.scenario);
  return r;
}

}  // namespace acyclic::hrp2
