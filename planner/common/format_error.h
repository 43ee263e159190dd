#pragma once
#include <stdexcept>
#include <string>

namespace acyclic {

// A bad input file: names the file, the field (dotted path, e.g.
// "start.contacts[2].spot") and what was expected there.
class FormatError : public std::runtime_error {
 public:
  FormatError(std::string file, std::string field, std::string expected)
      : std::runtime_error(compose(file, field, expected)),
        file_(std::move(file)), field_(std::move(field)), expected_(std::move(expected)) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  const std::string& expected() const { return expected_; }

 private:
  static std::string compose(const std::string& file, const std::string& field,
                             const std::string& expected) {
    return file + (field.empty() ? std::string() : ": field '" + field + "'") + ": " + expected;
  }
  std::string file_, field_, expected_;
};

}  // namespace acyclic
