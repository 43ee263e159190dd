#include "planner/plan/plan.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "planner/common/format_error.h"

namespace acyclic {

using nlohmann::json;

std::vector<ContactSpec> PlanStance::specs() const {
  std::vector<ContactSpec> out;
  for (const auto& c : contacts) out.push_back(c.spec);
  return out;
}

namespace {

json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

// Field access that names the file and the field on error.
struct J {
  const json& j;
  const std::string& file;
  std::string path;
  [[noreturn]] void fail(const std::string& expected) const { throw FormatError(file, path, "expected " + expected); }
  J at(const std::string& key) const {
    if (!j.is_object()) fail("an object with a field '" + key + "'");
    if (!j.contains(key)) throw FormatError(file, path.empty() ? key : path + "." + key, "missing (required)");
    return {j.at(key), file, path.empty() ? key : path + "." + key};
  }
  bool has(const std::string& key) const { return j.is_object() && j.contains(key); }
  J item(std::size_t i) const { return {j.at(i), file, path + "[" + std::to_string(i) + "]"}; }
  std::size_t size() const {
    if (!j.is_array()) fail("a list");
    return j.size();
  }
  double number() const {
    if (!j.is_number()) fail("a number");
    return j.get<double>();
  }
  std::string string() const {
    if (!j.is_string()) fail("a string");
    return j.get<std::string>();
  }
  bool boolean() const {
    if (!j.is_boolean()) fail("true or false");
    return j.get<bool>();
  }
  std::vector<double> numbers(std::size_t n) const {
    if (!j.is_array() || j.size() != n) fail("a list of " + std::to_string(n) + " numbers");
    std::vector<double> v;
    for (std::size_t i = 0; i < n; ++i) v.push_back(item(i).number());
    return v;
  }
  Eigen::Vector3d vec3() const {
    auto v = numbers(3);
    return {v[0], v[1], v[2]};
  }
};

}  // namespace

std::string planToJson(const Plan& plan, const Scenario& sc) {
  json j;
  j["format"] = "acyclic.plan/1";
  j["scenario"] = plan.scenario;
  j["robot"] = plan.robot;
  j["joint_names"] = sc.robot->jointNames();
  j["stances"] = json::array();
  for (const auto& s : plan.stances) {
    json js;
    js["contacts"] = json::array();
    for (const auto& c : s.contacts) {
      json jc;
      jc["spot"] = sc.robot->spots()[c.spec.spot].name;
      jc["surface"] = sc.scene->surfaces()[c.spec.surface].name;
      jc["supporting"] = c.spec.supporting;
      jc["x"] = c.spec.placement.x;
      jc["y"] = c.spec.placement.y;
      jc["theta"] = c.spec.placement.theta;
      jc["position"] = vec(c.frame.translation());
      const Eigen::Quaterniond q(c.frame.linear());
      jc["orientation"] = json::array({q.w(), q.x(), q.y(), q.z()});
      jc["points"] = json::array();
      jc["forces"] = json::array();
      for (const auto& p : c.points) jc["points"].push_back(vec(p));
      for (const auto& f : c.forces) jc["forces"].push_back(vec(f));
      js["contacts"].push_back(jc);
    }
    const Configuration& q = s.configuration;
    const Eigen::Quaterniond o = q.base_orientation.normalized();
    js["configuration"] = {{"base_position", vec(q.base_position)},
                           {"base_orientation", json::array({o.w(), o.x(), o.y(), o.z()})},
                           {"joints", std::vector<double>(q.joints.data(), q.joints.data() + q.joints.size())}};
    js["potential"] = s.potential;
    j["stances"].push_back(js);
  }
  j["stats"] = {{"nodes_generated", plan.stats.nodes_generated},
                {"nodes_expanded", plan.stats.nodes_expanded},
                {"posture_calls", plan.stats.posture_calls},
                {"posture_failures", plan.stats.posture_failures},
                {"seconds", plan.stats.seconds}};
  return j.dump(1);
}

void writePlan(const Plan& plan, const Scenario& sc, const std::string& path) {
  // Write beside, then rename: a crash never leaves half a plan.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write " + tmp);
    out << planToJson(plan, sc) << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot rename " + tmp + " to " + path);
}

Plan readPlan(const std::string& path, const Scenario& sc) {
  std::ifstream in(path);
  if (!in) throw FormatError(path, "", "cannot open the file");
  std::stringstream ss;
  ss << in.rdbuf();
  return planFromJson(ss.str(), path, sc);
}

Plan planFromJson(const std::string& text, const std::string& origin, const Scenario& sc) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw FormatError(origin, "", std::string("not valid JSON: ") + e.what());
  }
  const J root{doc, origin, ""};
  if (root.at("format").string() != "acyclic.plan/1") root.at("format").fail("'acyclic.plan/1'");
  Plan plan;
  plan.scenario = root.has("scenario") ? root.at("scenario").string() : "";
  plan.robot = root.has("robot") ? root.at("robot").string() : "";
  const J names = root.at("joint_names");
  if (names.size() != static_cast<std::size_t>(sc.robot->numJoints())) names.fail("the robot's 30 joint names");
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names.item(i).string() != sc.robot->joints()[i].name)
      names.item(i).fail("'" + sc.robot->joints()[i].name + "' (the robot's controller order)");
  const J stances = root.at("stances");
  for (std::size_t si = 0; si < stances.size(); ++si) {
    const J js = stances.item(si);
    PlanStance st;
    const J contacts = js.at("contacts");
    for (std::size_t ci = 0; ci < contacts.size(); ++ci) {
      const J jc = contacts.item(ci);
      PlanContact c;
      c.spec.spot = sc.robot->spotIndex(jc.at("spot").string());
      if (c.spec.spot < 0) jc.at("spot").fail("a contact spot of the robot");
      c.spec.surface = sc.scene->surfaceIndex(jc.at("surface").string());
      if (c.spec.surface < 0) jc.at("surface").fail("a surface of the scene");
      c.spec.supporting = jc.at("supporting").boolean();
      c.spec.placement = {jc.at("x").number(), jc.at("y").number(), jc.at("theta").number()};
      c.frame = contactFrame(sc.scene->surfaces()[c.spec.surface], c.spec.placement);
      if (jc.has("points")) {
        const J pts = jc.at("points"), fs = jc.at("forces");
        if (pts.size() != fs.size()) fs.fail("as many forces as points");
        for (std::size_t k = 0; k < pts.size(); ++k) {
          c.points.push_back(pts.item(k).vec3());
          c.forces.push_back(fs.item(k).vec3());
        }
      }
      st.contacts.push_back(c);
    }
    const J jq = js.at("configuration");
    st.configuration.base_position = jq.at("base_position").vec3();
    const auto o = jq.at("base_orientation").numbers(4);
    st.configuration.base_orientation = Eigen::Quaterniond(o[0], o[1], o[2], o[3]);
    if (std::abs(st.configuration.base_orientation.norm() - 1) > 1e-6)
      jq.at("base_orientation").fail("a unit quaternion [w, x, y, z]");
    const auto jv = jq.at("joints").numbers(sc.robot->numJoints());
    st.configuration.joints = Eigen::Map<const Eigen::VectorXd>(jv.data(), jv.size());
    st.potential = js.has("potential") ? js.at("potential").number() : 0.0;
    plan.stances.push_back(st);
  }
  if (root.has("stats")) {
    const J s = root.at("stats");
    auto num = [&](const char* k) { return s.has(k) ? s.at(k).number() : 0.0; };
    plan.stats.nodes_generated = static_cast<long>(num("nodes_generated"));
    plan.stats.nodes_expanded = static_cast<long>(num("nodes_expanded"));
    plan.stats.posture_calls = static_cast<long>(num("posture_calls"));
    plan.stats.posture_failures = static_cast<long>(num("posture_failures"));
    plan.stats.seconds = num("seconds");
  }
  return plan;
}

StanceDiff diffStances(const std::vector<ContactSpec>& a, const std::vector<ContactSpec>& b) {
  auto same = [](const ContactSpec& x, const ContactSpec& y) {
    return x.spot == y.spot && x.surface == y.surface && std::abs(x.placement.x - y.placement.x) <= 1e-3 &&
           std::abs(x.placement.y - y.placement.y) <= 1e-3 &&
           std::abs(std::remainder(x.placement.theta - y.placement.theta, 2 * M_PI)) <= M_PI / 180;
  };
  StanceDiff d;
  std::vector<bool> matched_b(b.size(), false);
  for (const auto& ca : a) {
    bool found = false;
    for (std::size_t k = 0; k < b.size() && !found; ++k)
      if (!matched_b[k] && same(ca, b[k])) {
        matched_b[k] = found = true;
        d.flipped += ca.supporting != b[k].supporting;
      }
    d.removed += !found;
  }
  for (bool m : matched_b) d.added += !m;
  return d;
}

std::string checkStep(const PlanStance& a, const PlanStance& b, const Scenario&) {
  const StanceDiff d = diffStances(a.specs(), b.specs());
  if (d.changes() == 1) return "";
  std::ostringstream os;
  os << d.added << " contacts added, " << d.removed << " removed, " << d.flipped
     << " changed support (expected exactly one change)";
  return os.str();
}

}  // namespace acyclic
