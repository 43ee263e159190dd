#include "planner/plan/plan.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "planner/plan/json_field.h"

namespace acyclic {

using nlohmann::json;
using json_field::J;
using json_field::vec;

std::vector<ContactSpec> PlanStance::specs() const {
  std::vector<ContactSpec> out;
  for (const auto& c : contacts) out.push_back(c.spec);
  return out;
}


namespace json_field {

json specToJson(const ContactSpec& c, const Scenario& sc) {
  return {{"spot", sc.robot->spots()[c.spot].name},
          {"surface", sc.scene->surfaces()[c.surface].name},
          {"supporting", c.supporting},
          {"x", c.placement.x},
          {"y", c.placement.y},
          {"theta", c.placement.theta}};
}

ContactSpec specFromJson(const J& jc, const Scenario& sc) {
  ContactSpec c;
  c.spot = sc.robot->spotIndex(jc.at("spot").string());
  if (c.spot < 0) jc.at("spot").fail("a contact spot of the robot");
  c.surface = sc.scene->surfaceIndex(jc.at("surface").string());
  if (c.surface < 0) jc.at("surface").fail("a surface of the scene");
  c.supporting = jc.at("supporting").boolean();
  c.placement = {jc.at("x").number(), jc.at("y").number(), jc.at("theta").number()};
  return c;
}

json configurationToJson(const Configuration& q) {
  const Eigen::Quaterniond o = q.base_orientation.normalized();
  return {{"base_position", vec(q.base_position)},
          {"base_orientation", json::array({o.w(), o.x(), o.y(), o.z()})},
          {"joints", std::vector<double>(q.joints.data(), q.joints.data() + q.joints.size())}};
}

Configuration configurationFromJson(const J& jq, const Scenario& sc) {
  Configuration q;
  q.base_position = jq.at("base_position").vec3();
  const auto o = jq.at("base_orientation").numbers(4);
  q.base_orientation = Eigen::Quaterniond(o[0], o[1], o[2], o[3]);
  if (std::abs(q.base_orientation.norm() - 1) > 1e-6) jq.at("base_orientation").fail("a unit quaternion [w, x, y, z]");
  const auto jv = jq.at("joints").numbers(sc.robot->numJoints());
  q.joints = Eigen::Map<const Eigen::VectorXd>(jv.data(), jv.size());
  return q;
}

void writeFileAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write " + tmp);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot rename " + tmp + " to " + path);
}

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FormatError(path, "", "cannot open the file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

json parseFormat(const std::string& text, const std::string& origin, const std::string& format) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw FormatError(origin, "", std::string("not valid JSON: ") + e.what());
  }
  const J root{doc, origin, ""};
  if (root.at("format").string() != format) root.at("format").fail("'" + format + "'");
  return doc;
}

void checkJointNames(const J& names, const Scenario& sc) {
  if (names.size() != static_cast<std::size_t>(sc.robot->numJoints()))
    names.fail("the robot's " + std::to_string(sc.robot->numJoints()) + " joint names");
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names.item(i).string() != sc.robot->joints()[i].name)
      names.item(i).fail("'" + sc.robot->joints()[i].name + "' (the robot's controller order)");
}

}  // namespace json_field

std::string planToJson(const Plan& plan, const Scenario& sc) {
  json j;
  j["format"] = "acyclic.plan/1";
  j["scenario"] = plan.scenario;
  j["robot"] = plan.robot;
  if (!plan.planner_settings.empty()) j["planner_settings"] = plan.planner_settings;
  j["joint_names"] = sc.robot->jointNames();
  j["stances"] = json::array();
  for (const auto& s : plan.stances) {
    json js;
    js["contacts"] = json::array();
    for (const auto& c : s.contacts) {
      json jc = json_field::specToJson(c.spec, sc);
      jc["position"] = vec(c.frame.translation());
      const Eigen::Quaterniond q(c.frame.linear());
      jc["orientation"] = json::array({q.w(), q.x(), q.y(), q.z()});
      jc["points"] = json::array();
      jc["forces"] = json::array();
      for (const auto& p : c.points) jc["points"].push_back(vec(p));
      for (const auto& f : c.forces) jc["forces"].push_back(vec(f));
      js["contacts"].push_back(jc);
    }
    js["configuration"] = json_field::configurationToJson(s.configuration);
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
  json_field::writeFileAtomically(path, planToJson(plan, sc) + "\n");
}

Plan readPlan(const std::string& path, const Scenario& sc) {
  return planFromJson(json_field::readWholeFile(path), path, sc);
}

Plan planFromJson(const std::string& text, const std::string& origin, const Scenario& sc) {
  const json doc = json_field::parseFormat(text, origin, "acyclic.plan/1");
  const J root{doc, origin, ""};
  Plan plan;
  plan.scenario = root.has("scenario") ? root.at("scenario").string() : "";
  plan.robot = root.has("robot") ? root.at("robot").string() : "";
  if (root.has("planner_settings")) {
    const J settings = root.at("planner_settings");
    for (std::size_t i = 0; i < settings.size(); ++i) plan.planner_settings.push_back(settings.item(i).string());
  }
  json_field::checkJointNames(root.at("joint_names"), sc);
  const J stances = root.at("stances");
  for (std::size_t si = 0; si < stances.size(); ++si) {
    const J js = stances.item(si);
    PlanStance st;
    const J contacts = js.at("contacts");
    for (std::size_t ci = 0; ci < contacts.size(); ++ci) {
      const J jc = contacts.item(ci);
      PlanContact c;
      c.spec = json_field::specFromJson(jc, sc);
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
    st.configuration = json_field::configurationFromJson(js.at("configuration"), sc);
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
