#pragma once
// Field access into parsed JSON that names the file and the dotted field on
// error (FormatError), shared by the JSON formats (plan, trajectory).
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "planner/common/format_error.h"
#include "planner/scene/scenario.h"

namespace acyclic::json_field {

using nlohmann::json;

inline json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

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



// The pieces the formats share (defined in plan.cpp).
// Writes text to path beside, then renames: a crash never leaves half a file.
void writeFileAtomically(const std::string& path, const std::string& text);
// A file's text; FormatError naming it when it cannot be read.
std::string readWholeFile(const std::string& path);
// Parses JSON and checks its "format" field; FormatError naming origin otherwise.
json parseFormat(const std::string& text, const std::string& origin, const std::string& format);
json specToJson(const ContactSpec& c, const Scenario& sc);          // spot, surface, supporting, x, y, theta
ContactSpec specFromJson(const J& j, const Scenario& sc);
json configurationToJson(const Configuration& q);                  // base_position, base_orientation, joints
Configuration configurationFromJson(const J& j, const Scenario& sc);
// "joint_names" must list the robot's joints in controller order.
void checkJointNames(const J& names, const Scenario& sc);

}  // namespace acyclic::json_field
