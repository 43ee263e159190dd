#include "planner/scene/scenario.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "planner/common/yaml_field.h"
#include "planner/model/kinematics.h"

namespace acyclic {
namespace fs = std::filesystem;

bool GoalCondition::linkWithinBounds(const Kinematics& k) const {
  const double v = k.linkPose(link).translation()[axis];
  return v >= min && v <= max;
}

bool GoalCondition::satisfied(const Kinematics& k, const std::vector<ContactSpec>& stance) const {
  for (int spot : supporting_spots) {
    auto it = std::find_if(stance.begin(), stance.end(), [&](const ContactSpec& c) { return c.spot == spot; });
    if (it == stance.end() || !it->supporting) return false;
  }
  return linkWithinBounds(k);
}

std::string GoalCondition::describe(const RobotModel& m) const {
  std::ostringstream os;
  os << m.links()[link].name << "." << "xyz"[axis];
  if (std::isfinite(min)) os << " >= " << min;
  if (std::isfinite(min) && std::isfinite(max)) os << " and";
  if (std::isfinite(max)) os << " <= " << max;
  for (std::size_t i = 0; i < supporting_spots.size(); ++i)
    os << (i == 0 ? ", supported by " : " and ") << m.spots()[supporting_spots[i]].name;
  return os.str();
}

std::string Scenario::describe(const ContactSpec& c) const {
  return robot->spots()[c.spot].name + "@" + scene->surfaces()[c.surface].name +
         (c.supporting ? " (supporting)" : " (geometric only)");
}

bool Scenario::allows(int spot, int surface) const {
  auto isIn = [](const std::vector<int>& v, int i) { return std::find(v.begin(), v.end(), i) != v.end(); };
  return isIn(allowed_spots, spot) && isIn(allowed_surfaces, surface) &&
         std::find(forbidden_contacts.begin(), forbidden_contacts.end(), std::make_pair(spot, surface)) ==
             forbidden_contacts.end();
}

Scenario Scenario::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FormatError(path, "", "cannot open the file");
  std::stringstream ss;
  ss << in.rdbuf();
  return loadText(ss.str(), path, fs::path(path).parent_path().string());
}

Scenario Scenario::loadText(const std::string& text, const std::string& origin, const std::string& base_dir) {
  YamlField root = YamlField::loadText(text, origin);
  root.requireFormat("acyclic.scenario/1");
  root.allowOnly({"format", "name", "robot", "scene", "seed", "start", "allowed_spots", "allowed_surfaces",
                  "forbidden_contacts", "goal", "key_postures", "planner", "published"});
  Scenario sc;
  sc.path = origin;
  sc.name = root.has("name") ? root["name"].string() : fs::path(origin).stem().string();
  auto resolve = [&](const YamlField& f) { return (fs::path(base_dir) / f.string()).lexically_normal().string(); };
  sc.robot = RobotModel::load(resolve(root["robot"]));
  sc.scene = Scene::load(resolve(root["scene"]));
  if (root.has("seed")) {
    int s = root["seed"].integer();
    if (s < 0) root["seed"].fail("a non-negative integer");
    sc.seed = static_cast<std::uint64_t>(s);
  }

  auto spotOf = [&](const YamlField& f) {
    int i = sc.robot->spotIndex(f.string());
    if (i < 0) {
      std::string names;
      for (const auto& s : sc.robot->spots()) names += (names.empty() ? "" : ", ") + s.name;
      f.fail("a contact spot of the robot (" + names + ")");
    }
    return i;
  };
  auto surfaceOf = [&](const YamlField& f) {
    int i = sc.scene->surfaceIndex(f.string());
    if (i < 0) {
      std::string names;
      for (const auto& s : sc.scene->surfaces()) names += (names.empty() ? "" : ", ") + s.name;
      f.fail("a surface of the scene (" + names + ")");
    }
    return i;
  };

  YamlField start = root["start"];
  start.allowOnly({"configuration", "contacts"});
  sc.start = sc.robot->readConfiguration(start["configuration"]);
  Kinematics kin(sc.robot);
  kin.setConfiguration(sc.start);
  YamlField contacts = start["contacts"];
  std::set<int> used_spots;
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    YamlField c = contacts.at(i);
    c.allowOnly({"spot", "surface", "supporting", "x", "y", "theta", "theta_deg"});
    ContactSpec cs;
    cs.spot = spotOf(c["spot"]);
    if (!used_spots.insert(cs.spot).second) c["spot"].fail("a spot not already in contact");
    cs.surface = surfaceOf(c["surface"]);
    cs.supporting = c.has("supporting") ? c["supporting"].boolean() : true;
    // Placement: given, or taken from the start configuration.
    cs.placement = projectOnSurface(sc.scene->surfaces()[cs.surface], kin.spotPose(cs.spot));
    if (c.has("x")) cs.placement.x = c["x"].number();
    if (c.has("y")) cs.placement.y = c["y"].number();
    if (c.has("theta") && c.has("theta_deg")) c.fail("at most one of theta and theta_deg");
    if (c.has("theta")) cs.placement.theta = c["theta"].angle();
    if (c.has("theta_deg")) cs.placement.theta = c["theta_deg"].degrees() * M_PI / 180;
    sc.start_stance.push_back(cs);
  }
  if (sc.start_stance.empty()) contacts.fail("at least one contact");

  if (root.has("allowed_spots")) {
    YamlField a = root["allowed_spots"];
    for (std::size_t i = 0; i < a.size(); ++i) sc.allowed_spots.push_back(spotOf(a.at(i)));
  } else {
    for (std::size_t i = 0; i < sc.robot->spots().size(); ++i) sc.allowed_spots.push_back(static_cast<int>(i));
  }
  if (root.has("allowed_surfaces")) {
    YamlField a = root["allowed_surfaces"];
    for (std::size_t i = 0; i < a.size(); ++i) sc.allowed_surfaces.push_back(surfaceOf(a.at(i)));
  } else {
    for (std::size_t i = 0; i < sc.scene->surfaces().size(); ++i)
      sc.allowed_surfaces.push_back(static_cast<int>(i));
  }

  if (root.has("forbidden_contacts")) {
    YamlField a = root["forbidden_contacts"];
    for (std::size_t i = 0; i < a.size(); ++i) {
      YamlField c = a.at(i);
      c.allowOnly({"spot", "surface"});
      // A pair outside allowed_spots or allowed_surfaces is accepted (it is
      // never made anyway): a scenario narrowed to fewer spots keeps its list.
      const int spot = spotOf(c["spot"]), surface = surfaceOf(c["surface"]);
      const std::pair<int, int> pair{spot, surface};
      if (std::find(sc.forbidden_contacts.begin(), sc.forbidden_contacts.end(), pair) != sc.forbidden_contacts.end())
        c.fail("a pair not already listed");
      sc.forbidden_contacts.push_back(pair);
    }
  }

  YamlField goal = root["goal"];
  goal.allowOnly({"link", "axis", "min", "max", "supported_by"});
  sc.goal.link = sc.robot->linkIndex(goal["link"].string());
  if (sc.goal.link < 0) goal["link"].fail("a link of the robot");
  const std::string axis = goal["axis"].string();
  if (axis != "x" && axis != "y" && axis != "z") goal["axis"].fail("one of x, y, z");
  sc.goal.axis = axis[0] - 'x';
  if (!goal.has("min") && !goal.has("max")) goal.fail("a map with min, max or both");
  if (goal.has("min")) sc.goal.min = goal["min"].number();
  if (goal.has("max")) sc.goal.max = goal["max"].number();
  if (sc.goal.min > sc.goal.max) goal.fail("min <= max");
  if (goal.has("supported_by")) {
    YamlField a = goal["supported_by"];
    for (std::size_t i = 0; i < a.size(); ++i) {
      const int spot = spotOf(a.at(i));
      if (std::find(sc.goal.supporting_spots.begin(), sc.goal.supporting_spots.end(), spot) !=
          sc.goal.supporting_spots.end())
        a.at(i).fail("a spot not already listed");
      if (std::find(sc.allowed_spots.begin(), sc.allowed_spots.end(), spot) == sc.allowed_spots.end())
        a.at(i).fail("one of allowed_spots");
      sc.goal.supporting_spots.push_back(spot);
    }
  }

  if (root.has("key_postures")) {
    YamlField kp = root["key_postures"];
    for (std::size_t i = 0; i < kp.size(); ++i) sc.key_postures.push_back(sc.robot->readConfiguration(kp.at(i)));
    if (sc.key_postures.size() == 1) kp.fail("at least two key postures (a start and an end)");
  }
  if (root.has("planner")) {
    if (!root["planner"].isMap()) root["planner"].fail("a map of planner parameters");
    sc.planner_section = root["planner"];
  }
  if (root.has("published")) {
    const YamlField f = root["published"];
    if (!f.isMap()) f.fail("a map: source, and any of nodes, stances, seconds, machine");
    f.allowOnly({"source", "nodes", "stances", "seconds", "machine"});
    PublishedRun ref;
    ref.source = f["source"].string();
    if (ref.source.empty()) f["source"].fail("a non-empty text naming the publication");
    if (f.has("nodes")) ref.nodes = f["nodes"].positiveInteger();
    if (f.has("stances")) ref.stances = f["stances"].positiveInteger();
    if (f.has("seconds")) ref.seconds = f["seconds"].positiveNumber();
    if (f.has("machine")) ref.machine = f["machine"].string();
    sc.published = ref;
  }
  return sc;
}

}  // namespace acyclic
