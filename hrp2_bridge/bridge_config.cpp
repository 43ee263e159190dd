#include "hrp2_bridge/bridge_config.h"

#include <stdexcept>
#include <utility>
#include <vector>

#include "planner/common/yaml_field.h"

namespace acyclic::hrp2 {

namespace {

// Every field with its storage, so that load() and validate() cannot drift apart.
std::vector<std::pair<const char*, double BridgeConfig::*>> fields() {
  return {{"dt", &BridgeConfig::dt},
          {"state_timeout", &BridgeConfig::state_timeout},
          {"stall_timeout", &BridgeConfig::stall_timeout},
          {"start_tolerance", &BridgeConfig::start_tolerance},
          {"rest_velocity", &BridgeConfig::rest_velocity},
          {"velocity_margin", &BridgeConfig::velocity_margin},
          {"position_margin", &BridgeConfig::position_margin},
          {"jump_factor", &BridgeConfig::jump_factor},
          {"max_tracking_error", &BridgeConfig::max_tracking_error},
          {"release_blend", &BridgeConfig::release_blend},
          {"stabilizer_lead", &BridgeConfig::stabilizer_lead},
          {"stabilizer_lag", &BridgeConfig::stabilizer_lag},
          {"coplanar_tolerance", &BridgeConfig::coplanar_tolerance},
          {"status_period", &BridgeConfig::status_period}};
}

std::string checkValue(const BridgeConfig& c, const std::string& name, double v) {
  if (!(v >= 0)) return "a non-negative number";
  if ((name == "dt" || name == "state_timeout" || name == "stall_timeout" || name == "status_period" ||
       name == "start_tolerance" || name == "max_tracking_error") && v <= 0)
    return "a positive number";
  if (name == "velocity_margin" && (v <= 0 || v > 1)) return "a fraction in (0, 1]";
  if (name == "jump_factor" && v < 1) return "a factor >= 1";
  if (name == "state_timeout" && v < c.dt) return "at least one period dt";
  return "";
}

}  // namespace

void BridgeConfig::validate() const {
  for (const auto& [name, member] : fields()) {
    const std::string why = checkValue(*this, name, this->*member);
    if (!why.empty())
      throw std::invalid_argument(std::string("bridge config: ") + name + " = " + std::to_string(this->*member) +
                                  ": expected " + why);
  }
}

BridgeConfig BridgeConfig::load(const std::string& path) {
  const YamlField root = YamlField::loadFile(path);
  root.requireFormat("acyclic.hrp2_bridge/1");
  std::vector<std::string> allowed = {"format", "check_contract"};
  for (const auto& f : fields()) allowed.push_back(f.first);
  root.allowOnly(allowed);
  BridgeConfig c;
  for (const auto& [name, member] : fields())
    if (root.has(name)) c.*member = root[name].number();
  if (root.has("check_contract")) c.check_contract = root["check_contract"].boolean();
  for (const auto& [name, member] : fields()) {
    const std::string why = checkValue(c, name, c.*member);
    if (why.empty()) continue;
    if (root.has(name)) root[name].fail(why);
    root.fail(std::string(name) + " (default " + std::to_string(c.*member) + "): " + why);
  }
  return c;
}

}  // namespace acyclic::hrp2
