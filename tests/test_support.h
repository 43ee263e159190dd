#pragma once
// Helpers shared by the tests: paths, finite differences, temporary files.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <Eigen/Core>

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

}  // namespace acyclic::test
