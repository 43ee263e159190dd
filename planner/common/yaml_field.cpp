#include "planner/common/yaml_field.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "planner/common/geometry.h"

namespace acyclic {

YamlField YamlField::loadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FormatError(path, "", "cannot open the file");
  std::stringstream ss;
  ss << in.rdbuf();
  return loadText(ss.str(), path);
}

namespace {

// yaml-cpp keeps both entries of a key given twice and lookups see one of
// them: the other value would be silently ignored.
void refuseDuplicateKeys(const YAML::Node& n, const std::string& origin, const std::string& path) {
  if (n.IsMap()) {
    std::map<std::string, int> lines;
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) continue;
      const std::string key = kv.first.Scalar();
      const int line = kv.first.Mark().line + 1;
      const auto [it, fresh] = lines.emplace(key, line);
      if (!fresh)
        throw FormatError(origin, path.empty() ? key : path + "." + key,
                          "given twice in one map (lines " + std::to_string(it->second) + " and " +
                              std::to_string(line) + ")");
      refuseDuplicateKeys(kv.second, origin, path.empty() ? key : path + "." + key);
    }
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) refuseDuplicateKeys(n[i], origin, path + "[" + std::to_string(i) + "]");
  }
}

}  // namespace

YamlField YamlField::loadText(const std::string& text, const std::string& origin) {
  try {
    YAML::Node n = YAML::Load(text);
    refuseDuplicateKeys(n, origin, "");
    if (!n.IsMap()) throw FormatError(origin, "", "expected a YAML map at the top level");
    return YamlField(n, origin, "");
  } catch (const YAML::Exception& e) {
    throw FormatError(origin, "", "not valid YAML (line " + std::to_string(e.mark.line + 1) +
                                      "): " + e.msg);
  }
}

std::string YamlField::describe() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsScalar()) return "'" + node_.Scalar() + "'";
  if (node_.IsSequence()) return "a list of " + std::to_string(node_.size());
  return "a map";
}

void YamlField::fail(const std::string& expected) const {
  throw FormatError(file_, path_, "expected " + expected + ", got " + describe());
}

bool YamlField::has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
}

YamlField YamlField::operator[](const std::string& key) const {
  if (!node_.IsMap()) fail("a map with a field '" + key + "'");
  std::string child = path_.empty() ? key : path_ + "." + key;
  YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull())
    throw FormatError(file_, child, "missing (required)");
  return YamlField(n, file_, child);
}

YamlField YamlField::at(std::size_t i) const {
  if (!node_.IsSequence()) fail("a list");
  if (i >= node_.size()) fail("at least " + std::to_string(i + 1) + " elements");
  return YamlField(node_[i], file_, path_ + "[" + std::to_string(i) + "]");
}

std::size_t YamlField::size() const {
  if (!node_.IsSequence()) fail("a list");
  return node_.size();
}

std::vector<std::string> YamlField::keys() const {
  if (!node_.IsMap()) fail("a map");
  std::vector<std::string> out;
  for (const auto& kv : node_) out.push_back(kv.first.as<std::string>());
  return out;
}

double YamlField::number() const {
  if (!node_.IsScalar()) fail("a number");
  double v;
  if (!YAML::convert<double>::decode(node_, v) || !std::isfinite(v)) fail("a finite number");
  if (std::abs(v) > 1e9) fail("a number of plausible magnitude (at most 1e9)");
  return v;
}

double YamlField::angle() const {
  const double v = number();
  if (std::abs(v) > 4 * M_PI) fail("an angle in radians within +-4 pi");
  return v;
}

double YamlField::degrees() const {
  const double v = number();
  if (std::abs(v) > 720) fail("an angle in degrees within +-720");
  return v;
}

Eigen::Vector3d YamlField::angles3(bool degrees) const {
  if (!node_.IsSequence() || node_.size() != 3) fail("a list of 3 angles");
  Eigen::Vector3d a;
  for (int i = 0; i < 3; ++i) a[i] = degrees ? at(i).degrees() : at(i).angle();
  return a;
}

int YamlField::integer() const {
  if (!node_.IsScalar()) fail("an integer");
  int v;
  if (!YAML::convert<int>::decode(node_, v)) fail("an integer");
  return v;
}

double YamlField::positiveNumber() const {
  const double v = number();
  if (!(v > 0)) fail("a positive number");
  return v;
}

int YamlField::positiveInteger() const {
  const int v = integer();
  if (v < 1) fail("a positive integer");
  return v;
}

bool YamlField::boolean() const {
  if (!node_.IsScalar()) fail("true or false");
  bool v;
  if (!YAML::convert<bool>::decode(node_, v)) fail("true or false");
  return v;
}

std::string YamlField::string() const {
  if (!node_.IsScalar()) fail("a string");
  return node_.Scalar();
}

std::vector<std::string> YamlField::strings() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < size(); ++i) out.push_back(at(i).string());
  return out;
}

std::vector<double> YamlField::numbers() const {
  std::vector<double> out;
  for (std::size_t i = 0; i < size(); ++i) out.push_back(at(i).number());
  return out;
}

std::vector<double> YamlField::numbers(std::size_t n) const {
  if (!node_.IsSequence() || node_.size() != n) fail("a list of " + std::to_string(n) + " numbers");
  return numbers();
}

Eigen::Vector3d YamlField::vec3() const {
  auto v = numbers(3);
  return {v[0], v[1], v[2]};
}

Eigen::Vector2d YamlField::vec2() const {
  auto v = numbers(2);
  return {v[0], v[1]};
}

ConvexPolygon YamlField::polygon() const {
  std::vector<Eigen::Vector2d> pts;
  for (std::size_t k = 0; k < size(); ++k) pts.push_back(at(k).vec2());
  try {
    return ConvexPolygon(pts);
  } catch (const std::invalid_argument& e) {
    fail(std::string("a convex polygon [[x, y], ...] (") + e.what() + ")");
  }
}

void YamlField::allowOnly(const std::vector<std::string>& allowed) const {
  for (const auto& k : keys()) {
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == k;
    if (!ok) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw FormatError(file_, path_.empty() ? k : path_ + "." + k,
                        "unknown field (expected one of: " + list + ")");
    }
  }
}

void YamlField::requireFormat(const std::string& expected) const {
  if (!has("format")) throw FormatError(file_, "format", "missing: expected '" + expected + "'");
  std::string got = (*this)["format"].string();
  if (got != expected) (*this)["format"].fail("'" + expected + "'");
}

Eigen::Quaterniond readOrientation(const YamlField& parent) {
  int count = parent.has("rpy") + parent.has("rpy_deg") + parent.has("quaternion");
  if (count > 1)
    throw FormatError(parent.file(), parent.path(),
                      "give at most one of rpy, rpy_deg, quaternion");
  if (parent.has("rpy")) return rpyToQuaternion(parent["rpy"].angles3(false));
  if (parent.has("rpy_deg")) return rpyToQuaternion(parent["rpy_deg"].angles3(true) * M_PI / 180.0);
  if (parent.has("quaternion")) {
    auto v = parent["quaternion"].numbers(4);
    Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
    if (std::abs(q.norm() - 1.0) > 1e-6)
      parent["quaternion"].fail("a unit quaternion [w, x, y, z] (norm 1 within 1e-6)");
    return q.normalized();
  }
  return Eigen::Quaterniond::Identity();
}

Eigen::Isometry3d readPose(const YamlField& parent) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (parent.has("position")) T.translation() = parent["position"].vec3();
  T.linear() = readOrientation(parent).toRotationMatrix();
  return T;
}

}  // namespace acyclic
