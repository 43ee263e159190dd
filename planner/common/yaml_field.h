#pragma once
// A YAML node that knows which file and field it came from, so that every
// error about it names both (docs/design.md section 5).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "planner/common/format_error.h"
#include "planner/common/geometry.h"

namespace acyclic {

class YamlField {
 public:
  // Loads a file; a missing file, a YAML syntax error or a key given twice in
  // one map (both lines named) is a FormatError.
  static YamlField loadFile(const std::string& path);
  // Parses text that came from `origin` (a file name or a message description).
  static YamlField loadText(const std::string& text, const std::string& origin);

  YamlField(YAML::Node node, std::string file, std::string path)
      : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const YAML::Node& node() const { return node_; }

  bool has(const std::string& key) const;
  YamlField operator[](const std::string& key) const;  // required member of a map
  YamlField at(std::size_t i) const;                   // element of a sequence
  std::size_t size() const;                            // sequence length (requires a sequence)
  std::vector<std::string> keys() const;               // map keys in file order (requires a map)

  bool isMap() const { return node_.IsMap(); }
  bool isSequence() const { return node_.IsSequence(); }
  bool isScalar() const { return node_.IsScalar(); }

  // A finite number of plausible magnitude (|x| <= 1e9): a non-finite or
  // absurd value is bad input, named with its file and field.
  double number() const;
  // An angle in radians (|a| <= 4 pi), or in degrees (|a| <= 720, returned
  // in degrees: the caller converts as it always did, bit for bit): any
  // orientation or joint angle is within that.
  double angle() const;
  double degrees() const;
  Eigen::Vector3d angles3(bool degrees) const;  // [a, b, c], in the unit asked for
  int integer() const;
  // number() > 0 and integer() >= 1, else "a positive number" / "a positive
  // integer", named with the file and field.
  double positiveNumber() const;
  int positiveInteger() const;
  bool boolean() const;
  std::string string() const;
  std::vector<std::string> strings() const;
  std::vector<double> numbers() const;                 // any length
  std::vector<double> numbers(std::size_t n) const;    // exactly n
  Eigen::Vector3d vec3() const;
  Eigen::Vector2d vec2() const;
  // A convex polygon [[x, y], ...]; the error says why one is not.
  ConvexPolygon polygon() const;

  // Rejects keys not in `allowed` (a typo should not be silently ignored).
  void allowOnly(const std::vector<std::string>& allowed) const;
  // Requires `format: <expected>` at this (top-level) node.
  void requireFormat(const std::string& expected) const;

  [[noreturn]] void fail(const std::string& expected) const;

 private:
  std::string describe() const;
  YAML::Node node_;
  std::string file_;
  std::string path_;
};

// An orientation from a map that holds exactly one of: rpy (rad), rpy_deg,
// or quaternion [w, x, y, z]; identity when none is present.
Eigen::Quaterniond readOrientation(const YamlField& parent);
// A pose: position (default zero) plus orientation as above.
Eigen::Isometry3d readPose(const YamlField& parent);

}  // namespace acyclic
