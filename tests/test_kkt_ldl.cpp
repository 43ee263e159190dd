// The KKT factorization Ipopt uses for posture problems (kkt_ldl.h): on
// systems of Ipopt's shape, rows x | s | c | d, its solutions against a dense
// solve, its inertia against the eigenvalues, singular and unsupported
// patterns reported.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

#include <Eigen/Dense>

#include "planner/posture/kkt_ldl.h"

namespace {

// Ipopt's augmented system with a diagonal Hessian block:
//   [ W+Sx   0    Jc^T   Jd^T ]
//   [  0     Ss    0     -I   ]
//   [  Jc    0   -dc I    0   ]
//   [  Jd   -I     0    -dd I ]
// as triplets of the lower triangle (1-based), and densely.
struct Kkt {
  int n = 0;
  std::vector<int> irn, jcn;
  std::vector<double> a;
  Eigen::MatrixXd dense;
  void add(int i, int j, double v) {  // 0-based, any triangle
    if (i < j) std::swap(i, j);
    irn.push_back(i + 1), jcn.push_back(j + 1), a.push_back(v);
    dense(i, j) += v;
    if (i != j) dense(j, i) += v;
  }
};

Kkt makeKkt(int nx, int mc, int md, unsigned seed, double dc = 0, double dd = 0, double density = 0.3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), pos(0.1, 10);
  std::bernoulli_distribution keep(density);
  Kkt k;
  k.n = nx + 2 * md + mc;
  k.dense = Eigen::MatrixXd::Zero(k.n, k.n);
  const int s0 = nx, c0 = nx + md, d0 = nx + md + mc;
  for (int i = 0; i < nx; ++i) k.add(i, i, pos(rng));
  for (int i = 0; i < md; ++i) k.add(s0 + i, s0 + i, std::pow(10.0, 4 * u(rng)));  // slacks' Sigma spans 1e-4..1e4
  for (int i = 0; i < mc; ++i) {
    k.add(c0 + i, c0 + i, -dc);
    k.add(c0 + i, i % nx, 1 + pos(rng));  // every row has an entry: full rank but by chance
    for (int j = 0; j < nx; ++j)
      if (keep(rng)) k.add(c0 + i, j, u(rng));
  }
  for (int i = 0; i < md; ++i) {
    k.add(d0 + i, d0 + i, -dd);
    k.add(d0 + i, s0 + i, -1);
    for (int j = 0; j < nx; ++j)
      if (keep(rng)) k.add(d0 + i, j, u(rng));
  }
  return k;
}

struct Factors {
  std::vector<int> perm, parent, count, Lp, Li;
  std::vector<double> Lx, D;
  int negative = 0;
  long lnz = 0;
  int status = -1;
};

Factors factorize(const Kkt& k) {
  Factors f;
  f.perm.resize(k.n), f.parent.resize(k.n), f.count.resize(k.n);
  std::string why;
  f.lnz = acyclic::kkt::analyse(k.n, static_cast<int>(k.a.size()), k.irn.data(), k.jcn.data(), f.perm.data(),
                                f.parent.data(), f.count.data(), &why);
  EXPECT_GE(f.lnz, 0) << why;
  if (f.lnz < 0) return f;
  f.Lp.resize(k.n + 1), f.Li.resize(f.lnz), f.Lx.resize(f.lnz), f.D.resize(k.n);
  f.status = acyclic::kkt::factor(k.n, static_cast<int>(k.a.size()), k.irn.data(), k.jcn.data(), k.a.data(),
                                  f.perm.data(), f.parent.data(), f.count.data(), f.Lp.data(), f.Li.data(),
                                  f.Lx.data(), f.D.data(), &f.negative);
  return f;
}

Eigen::VectorXd solveWith(const Factors& f, const Eigen::VectorXd& b) {
  Eigen::VectorXd x = b, work(b.size());
  acyclic::kkt::solve(static_cast<int>(b.size()), f.perm.data(), f.Lp.data(), f.Li.data(), f.Lx.data(), f.D.data(),
                      x.data(), work.data());
  return x;
}

int negativeEigenvalues(const Eigen::MatrixXd& m) {
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(m).eigenvalues();
  return static_cast<int>((ev.array() < 0).count());
}

// The columns of L from the first of its last columns that are full below
// the diagonal: the block factor() eliminates densely.
int fullTrailingColumns(const Factors& f) {
  const int n = static_cast<int>(f.count.size());
  int t = n;
  while (t > 0 && f.count[t - 1] == n - t) --t;
  return n - t;
}

TEST(KktLdl, SolvesIpoptsAugmentedSystemsWithTheirInertia) {
  // Sizes of the posture problems (about 90 variables, 30 equality and 140
  // inequality rows) and smaller ones.
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const int nx = seed <= 3 ? 12 : 90, mc = seed <= 3 ? 4 : 30, md = seed <= 3 ? 9 : 140;
    const Kkt k = makeKkt(nx, mc, md, seed);
    const Factors f = factorize(k);
    ASSERT_EQ(f.status, 0) << "seed " << seed;
    EXPECT_EQ(f.negative, mc + md) << "seed " << seed;
    EXPECT_EQ(f.negative, negativeEigenvalues(k.dense)) << "seed " << seed;
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(k.n, -1, 2);
    const Eigen::VectorXd x = solveWith(f, b);
    const Eigen::VectorXd ref = k.dense.fullPivLu().solve(b);
    EXPECT_LT((k.dense * x - b).norm(), 1e-9 * b.norm()) << "seed " << seed;
    EXPECT_LT((x - ref).norm(), 1e-8 * (1 + ref.norm())) << "seed " << seed;
    if (seed > 3) {  // most of the variables and equality rows eliminated densely
      EXPECT_GE(fullTrailingColumns(f), (nx + mc) * 3 / 4) << "seed " << seed;
    }
  }
}

// Several right-hand sides at once (solveMany, what Ipopt's blocks of
// L-BFGS vectors get): each solution is solve()'s, bit for bit, for every
// block size up to two groups and more, on systems with and without a dense
// trailing block (its backward sums of every length, each residue mod 4),
// and with sparse variables left of it.
TEST(KktLdl, SolvesSeveralRightHandSidesAtOnceBitForBit) {
  struct Shape {
    int nx, mc, md;
    double density;
  };
  int with_dense = 0, without_dense = 0;
  for (const Shape& sh : {Shape{12, 4, 9, 0.3}, Shape{5, 2, 4, 0.3}, Shape{90, 30, 140, 0.3},
                          Shape{90, 30, 140, 0.02}, Shape{37, 11, 50, 0.15}}) {
    const Kkt k = makeKkt(sh.nx, sh.mc, sh.md, 7 + sh.nx, 0, 0, sh.density);
    const Factors f = factorize(k);
    ASSERT_EQ(f.status, 0) << "nx " << sh.nx;
    (fullTrailingColumns(f) >= 8 ? with_dense : without_dense)++;
    std::mt19937 rng(sh.nx);
    std::uniform_real_distribution<double> u(-3, 3);
    for (int nrhs = 1; nrhs <= 2 * acyclic::kkt::kMaxSolvedAtOnce + 3; ++nrhs) {
      Eigen::MatrixXd B(k.n, nrhs);
      for (int c = 0; c < nrhs; ++c)
        for (int i = 0; i < k.n; ++i) B(i, c) = u(rng);
      Eigen::MatrixXd X = B;
      std::vector<double> work(static_cast<std::size_t>(k.n) * acyclic::kkt::kMaxSolvedAtOnce);
      acyclic::kkt::solveMany(k.n, nrhs, f.perm.data(), f.Lp.data(), f.Li.data(), f.Lx.data(), f.D.data(), X.data(),
                              work.data());
      for (int c = 0; c < nrhs; ++c) {
        const Eigen::VectorXd one = solveWith(f, B.col(c));
        ASSERT_EQ(0, std::memcmp(one.data(), X.col(c).data(), sizeof(double) * k.n))
            << "nx " << sh.nx << ", " << nrhs << " at once, vector " << c << ": largest difference "
            << (one - X.col(c)).cwiseAbs().maxCoeff();
      }
    }
  }
  EXPECT_GT(with_dense, 0);
  EXPECT_GT(without_dense, 0);
}

// Sparser Jacobians (a posture problem's forces touch few rows) leave some
// variables out of the dense trailing block: their columns, with positive
// pivots and many rows in the block, update it as the inequality rows' do.
// Same solutions and inertia as the dense reference.
TEST(KktLdl, VariablesLeftOfTheDenseBlockUpdateItToo) {
  for (unsigned seed = 21; seed <= 24; ++seed) {
    const int nx = 90, mc = 30, md = 140;
    const Kkt k = makeKkt(nx, mc, md, seed, 0, 0, seed % 2 ? 0.02 : 0.05);
    const Factors f = factorize(k);
    ASSERT_EQ(f.status, 0) << "seed " << seed;
    const int m = fullTrailingColumns(f);
    EXPECT_GE(m, 8) << "seed " << seed;
    int variables_left = 0;
    for (int c = 0; c < k.n - m; ++c) variables_left += f.perm[c] < nx;
    EXPECT_GT(variables_left, 0) << "seed " << seed;
    EXPECT_EQ(f.negative, negativeEigenvalues(k.dense)) << "seed " << seed;
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(k.n, -1, 2);
    const Eigen::VectorXd x = solveWith(f, b);
    EXPECT_LT((k.dense * x - b).norm(), 1e-9 * b.norm()) << "seed " << seed;
  }
}

// L-BFGS's low-rank part as rows (Ipopt's limited_memory_aug_solver=extended,
// PostureGeneratorOptions::lbfgs_in_kkt): rows for the update's vectors V and
// U, with -1 and +1 on the diagonal, against every variable. The graph stays
// bipartite, the rows join the dense block, and the solutions and inertia are
// those of the dense reference.
TEST(KktLdl, SolvesSystemsWithLbfgsRows) {
  for (unsigned seed = 31; seed <= 34; ++seed) {
    const int nx = 90, mc = 30, md = 140, pairs = 6;
    Kkt k = makeKkt(nx, mc, md, seed);
    const int n0 = k.n;
    k.n += 2 * pairs;
    Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(k.n, k.n);
    grown.topLeftCorner(n0, n0) = k.dense;
    k.dense = grown;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    for (int r = 0; r < 2 * pairs; ++r) {
      const int row = n0 + r;
      k.add(row, row, r < pairs ? -1.0 : 1.0);  // V's rows, then U's
      for (int j = 0; j < nx; ++j) k.add(row, j, u(rng));
    }
    const Factors f = factorize(k);
    ASSERT_EQ(f.status, 0) << "seed " << seed;
    EXPECT_GE(fullTrailingColumns(f), 2 * pairs) << "seed " << seed;
    EXPECT_EQ(f.negative, negativeEigenvalues(k.dense)) << "seed " << seed;
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(k.n, -1, 2);
    const Eigen::VectorXd x = solveWith(f, b);
    EXPECT_LT((k.dense * x - b).norm(), 1e-9 * b.norm()) << "seed " << seed;
  }
}

TEST(KktLdl, CondensesTheInequalityRowsOntoTheVariables) {
  // The order eliminates each slack, then its row, then the variables, then
  // the equality rows: L has no more entries than the dense lower triangle
  // of the variables and equality rows plus one per slack and inequality row.
  const int nx = 90, mc = 30, md = 140;
  const Kkt k = makeKkt(nx, mc, md, 7);
  const Factors f = factorize(k);
  ASSERT_EQ(f.status, 0);
  const long trailing = nx + mc;
  EXPECT_LE(f.lnz, trailing * (trailing - 1) / 2 + md * (nx + 1));
  for (int i = 0; i < md; ++i) {
    EXPECT_EQ(f.perm[2 * i], nx + i);            // slack i
    EXPECT_EQ(f.perm[2 * i + 1], nx + md + mc + i);  // then its inequality row
  }
}

TEST(KktLdl, DuplicateEntriesAreSummed) {
  Kkt k = makeKkt(10, 3, 6, 11);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(k.n);
  const Eigen::VectorXd x1 = solveWith(factorize(k), b);
  // Split every entry into two halves (Ipopt's triplets repeat positions).
  Kkt split = k;
  split.irn.clear(), split.jcn.clear(), split.a.clear();
  for (std::size_t e = 0; e < k.a.size(); ++e)
    for (int h = 0; h < 2; ++h)
      split.irn.push_back(k.irn[e]), split.jcn.push_back(k.jcn[e]), split.a.push_back(k.a[e] / 2);
  const Factors f = factorize(split);
  ASSERT_EQ(f.status, 0);
  EXPECT_LT((solveWith(f, b) - x1).norm(), 1e-12 * x1.norm());
}

TEST(KktLdl, RankDeficientEqualityRowsAreSingularUntilRegularized) {
  // Two identical equality rows: a zero pivot (Ipopt then adds -dc I).
  auto twin = [](double dc) {
    Kkt k = makeKkt(8, 2, 3, 5, dc);
    const int c0 = 8 + 3;
    // Copy row c0's Jacobian entries onto a new equality row c0 + 1 by rebuilding.
    Kkt t;
    t.n = k.n;
    t.dense = Eigen::MatrixXd::Zero(t.n, t.n);
    for (std::size_t e = 0; e < k.a.size(); ++e) {
      const int i = k.irn[e] - 1, j = k.jcn[e] - 1;
      if (i == c0 + 1 && j != i) continue;  // drop row c0+1's own entries
      t.add(i, j, k.a[e]);
      if (i == c0 && j != i) t.add(c0 + 1, j, k.a[e]);
    }
    return t;
  };
  EXPECT_NE(factorize(twin(0)).status, 0);
  const Kkt reg = twin(1e-8);
  const Factors f = factorize(reg);
  ASSERT_EQ(f.status, 0);
  EXPECT_EQ(f.negative, negativeEigenvalues(reg.dense));
}

TEST(KktLdl, ReportsTheInertiaOfAnIndefiniteHessianBlock) {
  // A negative curvature in W: one more negative pivot, which Ipopt reads as
  // wrong inertia and corrects by adding dw I.
  Kkt k = makeKkt(12, 4, 9, 3);
  k.add(2, 2, -1e7);  // beyond what condensing the inequality rows adds
  const Factors f = factorize(k);
  ASSERT_EQ(f.status, 0);
  EXPECT_EQ(f.negative, negativeEigenvalues(k.dense));
  EXPECT_GT(f.negative, 4 + 9);
}

TEST(KktLdl, RefusesAPatternThatIsNotBipartite) {
  // An entry between two variables (a full Hessian block): not handled here.
  Kkt k = makeKkt(6, 2, 3, 9);
  k.add(1, 0, 0.5);
  k.add(6 + 3, 1, 0.3);  // the first equality row meets both: an odd cycle
  std::vector<int> perm(k.n), parent(k.n), count(k.n);
  std::string why;
  EXPECT_EQ(acyclic::kkt::analyse(k.n, static_cast<int>(k.a.size()), k.irn.data(), k.jcn.data(), perm.data(),
                                  parent.data(), count.data(), &why),
            -1);
  EXPECT_NE(why.find("bipartite"), std::string::npos) << why;
  k.irn.push_back(k.n + 1), k.jcn.push_back(1), k.a.push_back(1);
  EXPECT_EQ(acyclic::kkt::analyse(k.n, static_cast<int>(k.a.size()), k.irn.data(), k.jcn.data(), perm.data(),
                                  parent.data(), count.data(), &why),
            -1);
  EXPECT_NE(why.find("out of range"), std::string::npos) << why;
}

}  // namespace

// factor() keeps what it found of a pattern for the next factorization of the
// same pattern (planner/posture/kkt_ldl.cpp, Program). It must notice any
// other pattern, even of the same size: here the same matrix with its
// triplets in another order (each value then comes from another place), and
// the same with one entry moved to another column. Each is solved as a fresh
// factorization would, and the first, factorized again, gives the same
// factors bit for bit.
TEST(KktLdl, APatternsKeptAnalysisServesOnlyThatPattern) {
  const Kkt a = makeKkt(40, 10, 50, 31);
  Kkt shuffled = a;
  std::mt19937 rng(7);
  std::vector<int> order(a.a.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), rng);
  for (std::size_t i = 0; i < order.size(); ++i)
    shuffled.irn[i] = a.irn[order[i]], shuffled.jcn[i] = a.jcn[order[i]], shuffled.a[i] = a.a[order[i]];
  // One entry of an inequality row moved to another variable's column.
  Kkt other = a;
  const int d0 = 40 + 50 + 10;  // first inequality row (0-based)
  std::size_t moved = 0;
  while (!(other.irn[moved] - 1 >= d0 && other.jcn[moved] - 1 < 40)) ++moved;
  const int row = other.irn[moved] - 1, from = other.jcn[moved] - 1, to = (from + 7) % 40;
  other.jcn[moved] = to + 1;
  other.dense(row, from) -= other.a[moved], other.dense(from, row) -= other.a[moved];
  other.dense(row, to) += other.a[moved], other.dense(to, row) += other.a[moved];
  ASSERT_EQ(a.n, other.n);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.n, -1, 2);
  const Factors first = factorize(a);
  for (const Kkt* k : std::vector<const Kkt*>{&a, &shuffled, &other, &a}) {
    const Factors f = factorize(*k);
    ASSERT_EQ(f.status, 0);
    const Eigen::VectorXd x = solveWith(f, b);
    EXPECT_LT((k->dense * x - b).norm(), 1e-9 * b.norm());
    if (k == &a) {
      EXPECT_EQ(f.Li, first.Li);
      EXPECT_EQ(f.Lx, first.Lx);
      EXPECT_EQ(f.D, first.D);
    }
  }
}
