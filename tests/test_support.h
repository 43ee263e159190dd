#pragma once
// Helpers shared by the tests: paths, finite differences, temporary files.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <sys/wait.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "planner/common/format_error.h"

namespace acyclic::test {

inline std::string sourcePath(const std::string& rel) { return std::string(ACYCLIC_SOURCE_DIR) + "/" + rel; }
inline std::string binaryPath(const std::string& rel) { return std::string(ACYCLIC_BINARY_DIR) + "/" + rel; }

// A fresh folder under the system temp dir, removed with the object.
class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/acyclic-test-XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  const std::string& path() const { return path_; }
  std::string write(const std::string& name, const std::string& text) const {
    const std::string p = path_ + "/" + name;
    std::ofstream(p) << text;
    return p;
  }

 private:
  std::string path_;
};

// ||A - B||_F / max(||B||_F, floor): the relative error of A against B.
inline double relativeError(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double floor = 1e-3) {
  return (A - B).norm() / std::max(B.norm(), floor);
}

inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Runs a command line; returns its exit status and what it printed (stdout and stderr).
struct ProcessRun {
  int status;
  std::string output;
};
inline ProcessRun runProcess(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

// A scenario file's text with its robot and scene paths made absolute, so that
// a test can change it and write it anywhere.
inline std::string scenarioText(const std::string& rel) {
  std::string text = readFile(sourcePath(rel));
  const std::string models = sourcePath("models/");
  // The fields, not a comment that names the same files.
  text.replace(text.find("\nrobot: ../hrp2/") + 8, 8, models + "hrp2/");
  text.replace(text.find("\nscene: ../scenes/") + 8, 10, models + "scenes/");
  return text;
}

// step_forward's scenario, written to `dir`, on an open floor with a pad
// 0.24 m by 0.16 m in front of the right foot whose frame is turned by
// `yaw_deg` about the vertical (180: facing against the robot); without
// `right_sole_in_start`, the start stands on the left foot alone. Returns
// the scenario file's path.
inline std::string padScenario(const TempDir& dir, double yaw_deg, bool right_sole_in_start = true) {
  std::string scene = readFile(sourcePath("models/scenes/open_floor.yaml"));
  scene += "  - {name: pad, obstacle: floor, position: [0.22, -0.095, 0], rpy_deg: [0, 0, " + std::to_string(yaw_deg) +
           "], friction: 0.7,\n"
           "     polygon: [[-0.12, -0.08], [0.12, -0.08], [0.12, 0.08], [-0.12, 0.08]]}\n";
  std::string text = scenarioText("models/scenarios/step_forward.yaml");
  const std::string open_floor = sourcePath("models/scenes/open_floor.yaml");
  text.replace(text.find(open_floor), open_floor.size(), dir.write("pad_scene.yaml", scene));
  const std::string right = "    - {spot: r_sole, surface: floor}\n";
  if (!right_sole_in_start) text.erase(text.find(right), right.size());
  return dir.write("pad.yaml", text);
}

// Replaces `from` by `to` in a file's text and expects `parse(text)` to throw
// a FormatError naming `file` and `field`.
template <class Parse>
void expectBadField(const Parse& parse, const std::string& text, const std::string& file, const std::string& from,
                    const std::string& to, const std::string& field) {
  std::string t = text;
  const auto at = t.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  t.replace(at, from.size(), to);
  try {
    parse(t);
    ADD_FAILURE() << "accepted a bad file (" << field << ")";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_EQ(e.file(), file);
  }
}

}  // namespace acyclic::test
