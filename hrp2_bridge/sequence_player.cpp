#include "hrp2_bridge/sequence_player.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <functional>
#include <stdexcept>

namespace acyclic::hrp2 {

namespace {

// One file of rows; `row` appends the columns after t.
std::string writeRows(const PreparedTrajectory& p, const std::string& path,
                      const std::function<void(const CommandSample&, std::string&)>& row) {
  const std::string tmp = path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
  std::string line;
  char buf[64];
  for (const CommandSample& s : p.samples) {
    std::snprintf(buf, sizeof buf, "%.6f", s.t);
    line = buf;
    row(s, line);
    line += '\n';
    std::fputs(line.c_str(), f);
  }
  const bool ok = std::fflush(f) == 0 && !std::ferror(f);
  std::fclose(f);
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
  }
  return path;
}

void append(std::string& line, double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, " %.9f", v);
  line += buf;
}

}  // namespace

std::vector<std::string> writeSequencePlayer(const PreparedTrajectory& p, const std::string& base) {
  std::vector<std::string> out;
  out.push_back(writeRows(p, base + ".pos", [](const CommandSample& s, std::string& l) {
    for (Eigen::Index j = 0; j < s.q.size(); ++j) append(l, s.q[j]);
  }));
  out.push_back(writeRows(p, base + ".waist", [](const CommandSample& s, std::string& l) {
    for (int i = 0; i < 3; ++i) append(l, s.waist_position[i]);
    for (int i = 0; i < 3; ++i) append(l, s.waist_rpy[i]);
  }));
  out.push_back(writeRows(p, base + ".zmp", [](const CommandSample& s, std::string& l) {
    for (int i = 0; i < 3; ++i) append(l, s.zmp_waist[i]);
  }));
  return out;
}

}  // namespace acyclic::hrp2
