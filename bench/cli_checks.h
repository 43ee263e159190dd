#pragma once
// Checks of the benchmarks' numeric options with plain messages ("must be
// positive"): Debian's CLI11 2.1 words CLI::PositiveNumber's failures as a
// range whose end is the largest double written out in full.
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>

namespace acyclic::bench {

inline CLI::Validator numberAbove(double lo, bool inclusive, const std::string& what) {
  return CLI::Validator(
      [lo, inclusive, what](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (s.empty() || *end != '\0') return "'" + s + "' is not a number";
        if (!(inclusive ? v >= lo : v > lo)) return "'" + s + "': must be " + what;
        return "";
      },
      inclusive ? "NONNEGATIVE" : "POSITIVE");
}
inline const CLI::Validator& positive() {
  static const CLI::Validator v = numberAbove(0, false, "positive");
  return v;
}
inline const CLI::Validator& nonNegative() {
  static const CLI::Validator v = numberAbove(0, true, "zero or more");
  return v;
}

}  // namespace acyclic::bench
