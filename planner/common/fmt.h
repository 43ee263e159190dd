#pragma once
// printf-style formatting of up to three figures into a message: the
// violations and summaries the checks and the bridge report.
#include <cstdio>
#include <string>

namespace acyclic {

inline std::string fmt(const char* f, double a = 0, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

}  // namespace acyclic
