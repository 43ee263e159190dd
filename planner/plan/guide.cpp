#include "planner/plan/guide.h"


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
  json_field::writeFileAtomically(path, guideToJson(g, sc) + "\n");
}

Guide readGuide(const std::string& path, const Scenario& sc) {
  return guideFromJson(json_field::readWholeFile(path), path, sc);
}

Guide guideFromJson(const std::string& text, const std::string& origin, const Scenario& sc) {
  const json doc = json_field::parseFormat(text, origin, "acyclic.guide/1");
  const J root{doc, origin, ""};
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
