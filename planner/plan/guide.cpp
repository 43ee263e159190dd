#include "planner/plan/guide.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "planner/plan/json_field.h"

namespace acyclic {

using nlohmann::json;
using json_field::J;

std::string guideToJson(const Guide& g, const Scenario& sc) {
  json j;
  j["format"] = "acyclic.guide/1";
  j["scenario"] = g.scenario;
  j["source"] = g.source;
  j["seconds"] = g.seconds;
  j["joint_names"] = sc.robot->jointNames();
  j["key_postures"] = json::array();
  for (const auto& q : g.key_postures) j["key_postures"].push_back(json_field::configurationToJson(q));
  return j.dump(1);
}

void writeGuide(const Guide& g, const Scenario& sc, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write " + tmp);
    out << guideToJson(g, sc) << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot rename " + tmp + " to " + path);
}

Guide readGuide(const std::string& path, const Scenario& sc) {
  std::ifstream in(path);
  if (!in) throw FormatError(path, "", "cannot open the file");
  std::stringstream ss;
  ss << in.rdbuf();
  return guideFromJson(ss.str(), path, sc);
}

Guide guideFromJson(const std::string& text, const std::string& origin, const Scenario& sc) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw FormatError(origin, "", std::string("not valid JSON: ") + e.what());
  }
  const J root{doc, origin, ""};
  if (root.at("format").string() != "acyclic.guide/1") root.at("format").fail("'acyclic.guide/1'");
  json_field::checkJointNames(root.at("joint_names"), sc);
  Guide g;
  g.scenario = root.has("scenario") ? root.at("scenario").string() : "";
  g.source = root.has("source") ? root.at("source").string() : "";
  g.seconds = root.has("seconds") ? root.at("seconds").number() : 0.0;
  const J keys = root.at("key_postures");
  if (keys.size() < 2) keys.fail("at least two key postures");
  for (std::size_t i = 0; i < keys.size(); ++i) g.key_postures.push_back(json_field::configurationFromJson(keys.item(i), sc));
  return g;
}

}  // namespace acyclic
