#include "planner/plan/scenario_reference.h"

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "planner/common/format_error.h"

namespace acyclic {

namespace fs = std::filesystem;

std::string resolveScenarioReference(const std::string& file_path, const std::string& named) {
  if (named.empty()) throw FormatError(file_path, "scenario", "the scenario file's path (or give --scenario)");
  const fs::path s = named;
  if (s.is_absolute()) return s.string();
  const fs::path beside = fs::path(file_path).parent_path() / s;
  if (fs::exists(beside)) return beside.string();
  if (fs::exists(s)) return s.string();
  throw FormatError(file_path, "scenario",
                    "an existing scenario file, got '" + named +
                        "' (found neither beside the file nor in the current directory; give --scenario)");
}

std::string scenarioNamedBy(const std::string& file_path) {
  std::ifstream in(file_path);
  if (!in) throw FormatError(file_path, "", "cannot read the file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw FormatError(file_path, "", std::string("not JSON: ") + e.what());
  }
  if (!j.is_object() || !j.contains("scenario") || !j["scenario"].is_string())
    throw FormatError(file_path, "scenario", "the scenario file's path, a string (or give --scenario)");
  return resolveScenarioReference(file_path, j["scenario"].get<std::string>());
}

}  // namespace acyclic
