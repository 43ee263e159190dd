// The KKT factorization (planner/posture/kkt_ldl.h) on the systems Ipopt
// hands it while the posture generator solves bench_posture's problems: every
// k-th of them is kept, then each is analysed once and factorized and solved
// many times. Prints the systems' sizes and the time per factorization and
// per solve (median over the systems of each one's mean). Usage:
// bench_kkt [OPTIONS]; --help lists the options.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "cli_checks.h"
#include "posture_problems.h"

#include "planner/posture/heap_tuning.h"
#include "planner/posture/kkt_ldl.h"

using namespace acyclic;

namespace {

struct Matrix {
  int n = 0, nz = 0;
  std::vector<int> irn, jcn;
  std::vector<double> a;
};
std::vector<Matrix> kept;
int every = 37;
long seen = 0;

void keep(int n, int nz, const int* irn, const int* jcn, const double* a) {
  if (seen++ % every) return;
  kept.push_back({n, nz, {irn, irn + nz}, {jcn, jcn + nz}, {a, a + nz}});
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  int problems = 30, reps = 50;
  unsigned seed = 1;
  CLI::App app{"The KKT factorization on the systems Ipopt hands it while the posture generator solves\n"
               "bench_posture's problems: their sizes, and the time per factorization and per solve."};
  app.add_option("--problems", problems, "bench_posture problems solved to collect systems")
      ->check(acyclic::bench::positive())
      ->capture_default_str();
  app.add_option("--seed", seed, "seed of the problem set")->capture_default_str();
  app.add_option("--every", every, "keep every k-th system")->check(acyclic::bench::positive())->capture_default_str();
  app.add_option("--reps", reps, "factorizations and solves of each kept system")
      ->check(acyclic::bench::positive())
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const Scenario sc = Scenario::load(ACYCLIC_SOURCE_DIR "/models/scenarios/chair_table.yaml");
  {
    PostureGenerator pg(sc.robot, sc.scene);
    kkt::observeFactorizations(keep);
    for (const auto& p : acyclic::bench::makeProblems(sc, problems, seed)) pg.solve(p.request);
    kkt::observeFactorizations(nullptr);
  }
  std::vector<double> t_factor, t_solve, t_six_singly, t_six_at_once;
  int differing = 0;  // systems whose solveMany results differ in a bit from solve's
  double rows = 0, entries = 0, block = 0;
  for (const Matrix& m : kept) {
    const int n = m.n;
    std::vector<int> perm(n), parent(n), count(n), Lp(n + 1);
    const long lnz = kkt::analyse(n, m.nz, m.irn.data(), m.jcn.data(), perm.data(), parent.data(), count.data(), nullptr);
    if (lnz < 0) continue;
    std::vector<int> Li(lnz);
    std::vector<double> Lx(lnz), D(n), work(n);
    int negative = 0, status = 0;
    auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r)
      status = kkt::factor(n, m.nz, m.irn.data(), m.jcn.data(), m.a.data(), perm.data(), parent.data(), count.data(),
                           Lp.data(), Li.data(), Lx.data(), D.data(), &negative);
    auto t1 = std::chrono::steady_clock::now();
    if (status) continue;  // singular (Ipopt regularizes and factorizes again): not a full factorization
    t_factor.push_back(std::chrono::duration<double>(t1 - t0).count() / reps);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1, 2);
    Eigen::VectorXd x(n);
    t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r) {
      x = b;
      kkt::solve(n, perm.data(), Lp.data(), Li.data(), Lx.data(), D.data(), x.data(), work.data());
    }
    t1 = std::chrono::steady_clock::now();
    t_solve.push_back(std::chrono::duration<double>(t1 - t0).count() / reps);
    // Six right-hand sides (L-BFGS's update vectors), one by one and at once.
    constexpr int kMany = 6;
    Eigen::MatrixXd B(n, kMany), X(n, kMany);
    for (int c = 0; c < kMany; ++c) B.col(c) = b * (1.0 + c) + Eigen::VectorXd::Constant(n, 0.1 * c);
    std::vector<double> many_work(static_cast<std::size_t>(n) * kkt::kMaxSolvedAtOnce);
    t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r) {
      X = B;
      for (int c = 0; c < kMany; ++c)
        kkt::solve(n, perm.data(), Lp.data(), Li.data(), Lx.data(), D.data(), X.col(c).data(), work.data());
    }
    t1 = std::chrono::steady_clock::now();
    t_six_singly.push_back(std::chrono::duration<double>(t1 - t0).count() / reps);
    const Eigen::MatrixXd singly = X;
    t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r) {
      X = B;
      kkt::solveMany(n, kMany, perm.data(), Lp.data(), Li.data(), Lx.data(), D.data(), X.data(), many_work.data());
    }
    t1 = std::chrono::steady_clock::now();
    t_six_at_once.push_back(std::chrono::duration<double>(t1 - t0).count() / reps);
    if (std::memcmp(X.data(), singly.data(), sizeof(double) * static_cast<std::size_t>(n * kMany)) != 0) ++differing;
    int t = n;
    while (t > 0 && count[t - 1] == n - t) --t;
    rows += n, entries += lnz, block += n - t;
  }
  const double k = static_cast<double>(t_factor.size());
  std::printf("kkt_ldl on %zu of %ld systems from %d posture problems (seed %u), %d repetitions each\n",
              t_factor.size(), seen, problems, seed, reps);
  if (t_factor.empty()) return 1;
  std::printf("  size: mean %.0f rows, %.0f entries of L, a dense block of %.0f\n", rows / k, entries / k, block / k);
  std::printf("  factorization: median %.1f us\n  solve:         median %.2f us\n", median(t_factor) * 1e6,
              median(t_solve) * 1e6);
  std::printf("  six right-hand sides: one by one median %.2f us, at once (solveMany) %.2f us: %.2fx; %d of %zu"
              " systems differ in a bit\n",
              median(t_six_singly) * 1e6, median(t_six_at_once) * 1e6, median(t_six_singly) / median(t_six_at_once),
              differing, t_six_at_once.size());
  if (differing) return 1;
  return 0;
}
