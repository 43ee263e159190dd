#include "planner/search/planner_parameters.h"

#include <stdexcept>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "planner/scene/friction.h"

namespace acyclic {

namespace {

// What a member of a portfolio may change: how the search searches, not its
// budgets, threads or verification (those are the planner's, shared).
const std::vector<std::string> kVariantKeys = {
    "potential_k", "smoothing_tolerance", "guide_joint_weight", "reach_slack", "depth_weight", "alternative_step",
    "box_half_sizes", "duplicate_distance", "duplicate_angle", "max_contacts", "posture_iterations",
    "posture_linear_solver", "posture_lbfgs_in_kkt", "posture_stop_at_restoration", "posture_mu_oracle",
    "posture_distance_engine", "posture_pyramid_edges", "posture_support_inset", "posture_support_inset_y",
    "posture_friction_share", "collision_margin", "failure_memory", "failure_memory_distance",
    "failure_memory_angle", "swing_check", "guide_limb_guess"};

// Sets in p every key f has (f's keys already allowed by the caller).
void readFields(const YamlField& f, PlannerParameters& p) {
  auto positive = [&](const char* key, double& out) {
    if (f.has(key)) out = f[key].positiveNumber();
  };
  auto count = [&](const char* key, auto& out) {
    if (f.has(key)) out = f[key].positiveInteger();
  };
  positive("potential_k", p.potential_k);
  positive("smoothing_tolerance", p.smoothing_tolerance);
  positive("guide_joint_weight", p.guide_joint_weight);
  positive("reach_slack", p.reach_slack);
  if (f.has("depth_weight")) {
    p.depth_weight = f["depth_weight"].number();
    if (!(p.depth_weight >= 0)) f["depth_weight"].fail("a number >= 0");
  }
  if (f.has("alternative_step")) {
    p.alternative_step = f["alternative_step"].number();
    if (!(p.alternative_step >= 0)) f["alternative_step"].fail("a number >= 0 (m along the guide)");
  }
  positive("duplicate_distance", p.duplicate_distance);
  positive("duplicate_angle", p.duplicate_angle);
  positive("failure_memory_distance", p.failure_memory_distance);
  positive("failure_memory_angle", p.failure_memory_angle);
  if (f.has("failure_memory")) p.failure_memory = f["failure_memory"].boolean();
  if (f.has("swing_check")) p.swing_check = f["swing_check"].boolean();
  if (f.has("guide_limb_guess")) p.guide_limb_guess = f["guide_limb_guess"].boolean();
  if (f.has("verify_transitions")) p.verify_transitions = f["verify_transitions"].boolean();
  if (f.has("verify_on_expansion")) p.verify_on_expansion = f["verify_on_expansion"].boolean();
  positive("max_seconds", p.max_seconds);
  positive("collision_margin", p.posture.problem.collision_margin);
  count("max_contacts", p.max_contacts);
  count("max_nodes", p.max_nodes);
  if (f.has("max_plateau_nodes")) {
    p.max_plateau_nodes = f["max_plateau_nodes"].integer();
    if (p.max_plateau_nodes < 0) f["max_plateau_nodes"].fail("a count of nodes >= 0 (0: no such bound)");
  }
  count("max_posture_calls", p.max_posture_calls);
  count("posture_iterations", p.posture.max_iterations);
  count("threads", p.threads);
  if (f.has("posture_linear_solver")) {
    const std::string v = f["posture_linear_solver"].string();
    if (v != "ldl" && v != "mumps") f["posture_linear_solver"].fail("ldl or mumps");
    p.posture.linear_solver = v;
  }
  if (f.has("posture_lbfgs_in_kkt")) p.posture.lbfgs_in_kkt = f["posture_lbfgs_in_kkt"].boolean();
  if (f.has("posture_stop_at_restoration"))
    p.posture.stop_at_restoration = f["posture_stop_at_restoration"].boolean();
  if (f.has("posture_mu_oracle")) {
    const std::string v = f["posture_mu_oracle"].string();
    if (!isMuOracle(v)) f["posture_mu_oracle"].fail(muOracleChoices());
    p.posture.mu_oracle = v;
  }
  if (f.has("posture_distance_engine")) {
    const auto e = distanceEngineNamed(f["posture_distance_engine"].string());
    if (!e) f["posture_distance_engine"].fail("fcl or convex");
    p.posture.distance_engine = *e;
  }
  if (f.has("posture_pyramid_edges")) {
    const int v = f["posture_pyramid_edges"].integer();
    if (v != 4 && v != kFrictionPyramidEdges)
      f["posture_pyramid_edges"].fail("4 or " + std::to_string(kFrictionPyramidEdges) +
                                      " (edges of the contract's friction pyramid)");
    p.posture.problem.pyramid_sides = v;
  }
  if (f.has("posture_support_inset")) {
    const double v = f["posture_support_inset"].number();
    if (!(v >= 0 && v < 0.1)) f["posture_support_inset"].fail("a length in [0, 0.1) m");
    p.posture.problem.support_inset = v;
  }
  if (f.has("posture_support_inset_y")) {
    const double v = f["posture_support_inset_y"].number();
    if (!(v >= 0 && v < 0.1)) f["posture_support_inset_y"].fail("a length in [0, 0.1) m");
    p.posture.problem.support_inset_y = v;
  }
  if (f.has("posture_friction_share")) {
    const double v = f["posture_friction_share"].number();
    if (!(v > 0 && v <= 1)) f["posture_friction_share"].fail("a share of the friction coefficient in (0, 1]");
    p.posture.problem.friction_share = v;
  }
  // The interpolator's (withScenarioMargins); checked here with the rest of the section.
  if (f.has("transition_mu_oracle")) {
    const std::string v = f["transition_mu_oracle"].string();
    if (!isMuOracle(v)) f["transition_mu_oracle"].fail(muOracleChoices());
  }
  if (f.has("zmp_shift_cap")) {
    const double v = f["zmp_shift_cap"].number();
    if (!(v >= 0 && v < 0.1)) f["zmp_shift_cap"].fail("a length in [0, 0.1) m (0: no such bound)");
  }
  if (f.has("box_half_sizes")) {
    const Eigen::Vector3d b = f["box_half_sizes"].vec3();
    if ((b.array() <= 0).any()) f["box_half_sizes"].fail("three positive half sizes [x (m), y (m), theta (rad)]");
    p.box = {b.x(), b.y(), b.z()};
  }
}

// planner: portfolio: a list of members, each a map of the keys above (and
// an optional name) applied to the planner's parameters.
std::vector<PlannerVariant> portfolioOf(const YamlField& list, const PlannerParameters& base) {
  if (!list.isSequence() || list.size() < 2)
    list.fail("a list of at least two members, each a map of planner keys to change (an empty map: as configured)");
  std::vector<std::string> allowed = kVariantKeys;
  // A member's own budgets: what a sequence gives it before the next (in a race, too).
  for (const char* key : {"name", "max_nodes", "max_posture_calls", "max_plateau_nodes"}) allowed.push_back(key);
  std::vector<PlannerVariant> members;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YamlField m = list.at(i);
    if (!m.isMap()) m.fail("a map of planner keys to change ({} for the planner as configured)");
    m.allowOnly(allowed);
    PlannerVariant v;
    v.name = m.has("name") ? m["name"].string() : "member " + std::to_string(i + 1);
    for (const PlannerVariant& other : members)
      if (other.name == v.name) (m.has("name") ? m["name"] : m).fail("a name no other member has");
    PlannerParameters check = base;  // bad values fail here, naming the file and field
    readFields(m, check);
    v.apply = [m](PlannerParameters& p) { readFields(m, p); };
    members.push_back(std::move(v));
  }
  return members;
}

// Every key of a planner section.
std::vector<std::string> plannerKeys() {
  std::vector<std::string> allowed = kVariantKeys;
  for (const char* key : {"threads", "max_nodes", "max_posture_calls", "max_plateau_nodes", "max_seconds",
                          "verify_transitions",
                          "verify_on_expansion", "zmp_shift_cap", "transition_mu_oracle", "portfolio",
                          "portfolio_mode"})
    allowed.push_back(key);
  return allowed;
}

// "KEY=VALUE" as the key and VALUE read as YAML (FormatError naming origin).
std::pair<std::string, YAML::Node> parseSetting(const std::string& setting, const std::string& origin) {
  const auto eq = setting.find('=');
  if (eq == std::string::npos || eq == 0)
    throw FormatError(origin, "", "expected KEY=VALUE (a key of the scenario's planner section, docs/design.md "
                                   "section 5), got '" + setting + "'");
  const std::string key = setting.substr(0, eq);
  if (eq + 1 == setting.size())
    throw FormatError(origin, "planner." + key, "expected a value after '=' (null to drop the scenario's own)");
  try {
    return {key, YAML::Load(setting.substr(eq + 1))};
  } catch (const YAML::Exception& e) {
    throw FormatError(origin, "planner." + key, "expected a YAML value, got '" + setting.substr(eq + 1) +
                                                     "' (" + e.msg + ")");
  }
}

// The parameters a planner section gives (FormatError naming its file and field).
PlannerParameters parametersOf(const YamlField& f) {
  PlannerParameters p;
  f.allowOnly(plannerKeys());
  readFields(f, p);
  if (f.has("portfolio")) p.portfolio = portfolioOf(f["portfolio"], p);
  if (f.has("portfolio_mode")) {
    const std::string v = f["portfolio_mode"].string();
    if (v != "race" && v != "sequence") f["portfolio_mode"].fail("race or sequence");
    p.portfolio_mode =
        v == "race" ? PlannerParameters::PortfolioMode::Race : PlannerParameters::PortfolioMode::Sequence;
  }
  return p;
}

// The settings as (key, value), each read on its own as the scenario's keys
// are (a bad one is a FormatError naming origin and its field).
std::vector<std::pair<std::string, YAML::Node>> checkedSettings(const std::vector<std::string>& settings,
                                                                const std::string& origin) {
  std::vector<std::pair<std::string, YAML::Node>> out;
  for (const std::string& setting : settings) {
    auto [key, value] = parseSetting(setting, origin);
    YAML::Node alone(YAML::NodeType::Map);
    alone[key] = value;
    const YamlField f(alone, origin, "planner");
    if (value.IsNull()) f.allowOnly(plannerKeys());  // a key to drop: only its name to check
    else parametersOf(f);
    out.emplace_back(std::move(key), std::move(value));
  }
  return out;
}

}  // namespace

PlannerParameters plannerParameters(const Scenario& sc) {
  return sc.planner_section ? parametersOf(*sc.planner_section) : PlannerParameters();
}

void keepPortfolioMember(PlannerParameters& p, const std::string& name, const std::string& scenario) {
  std::string names;
  for (const PlannerVariant& v : p.portfolio) {
    if (v.name != name) {
      names += (names.empty() ? "" : ", ") + v.name;
      continue;
    }
    const PlannerVariant member = v;
    p.portfolio.clear();
    if (member.apply) member.apply(p);
    return;
  }
  throw std::invalid_argument(scenario + ": --member: no portfolio member named \"" + name + "\" (" +
                              (names.empty() ? std::string("the scenario has no portfolio") : "its members: " + names) +
                              ")");
}

void checkPlannerSettings(const std::vector<std::string>& settings, const std::string& origin) {
  checkedSettings(settings, origin);
}

void setPlannerKeys(Scenario& sc, const std::vector<std::string>& settings, const std::string& origin) {
  if (settings.empty()) return;
  const auto checked = checkedSettings(settings, origin);  // all of them before any is set
  YAML::Node section = sc.planner_section ? YAML::Clone(sc.planner_section->node()) : YAML::Node(YAML::NodeType::Map);
  for (const auto& [key, value] : checked) {
    if (value.IsNull()) section.remove(key);
    else section[key] = value;
  }
  sc.planner_section = YamlField(section, sc.planner_section ? sc.planner_section->file() : sc.path, "planner");
}

}  // namespace acyclic
