#include "planner/posture/kkt_ldl.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace acyclic::kkt {

namespace {

// factor() and solve() are compiled for AVX2 as well, chosen at run time on
// x86-64 (GCC's target_clones). The file is compiled with -ffp-contract=off
// (planner/CMakeLists.txt), so no clone fuses a multiply and an add: the
// results are the same bit for bit on any machine.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ACYCLIC_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define ACYCLIC_VECTOR_CLONES
#endif

// Relative size under which a pivot counts as zero: a few hundred roundings.
constexpr double kZeroPivot = 1e-13;
// A trailing block smaller than this is left to the sparse elimination.
constexpr int kMinDense = 8;
// A column with this many rows in the trailing block updates it densely.
constexpr int kHeavyColumn = 12;

// What a factorization does that depends on the pattern only: found by the
// first factorization of a pattern and replayed by the next ones (Ipopt
// factorizes the same pattern at every iteration of a solve), so that the
// numeric pass walks flat lists instead of the elimination tree. The
// arithmetic, and its order, is the same either way.
struct Program {
  // The pattern it was made for (compared whole: no hash to collide).
  int n = -1, nz = -1;
  std::vector<int> irn, jcn, perm;
  // The permuted upper triangle (permutedUpper).
  std::vector<int> colptr, rows, src;
  int t = 0, m = 0;  // the dense trailing block's first column and size
  // Row k of L left of the block: steps [row_step[k], row_step[k + 1]), in
  // elimination order. Step: column `col` of L gets row k at `write`, after
  // updating the working row through its entries [Lp[col], `update_end`),
  // whose rows are consecutive from `first_row` when that is >= 0 (the
  // nearly full columns of the configuration: a contiguous, vectorized
  // update instead of a scatter).
  struct Step {
    int col, write, update_end, first_row;
  };
  std::vector<int> row_step;
  std::vector<Step> steps;
  // Columns left of the block: where their rows inside the block start in
  // Li/Lx, and whether they update it densely (heavy) or entry by entry;
  // the heavy ones in order.
  std::vector<int> block_begin;
  std::vector<char> heavy;
  std::vector<int> heavy_columns;
  bool matches(int n_, int nz_, const int* irn_, const int* jcn_, const int* perm_) const {
    return n == n_ && nz == nz_ && std::equal(irn.begin(), irn.end(), irn_) &&
           std::equal(jcn.begin(), jcn.end(), jcn_) && std::equal(perm.begin(), perm.end(), perm_);
  }
};

// Scratch reused across calls on one thread (never state between calls but
// the program, which is checked against the pattern before each use).
struct Scratch {
  Program program;
  std::vector<double> y;                     // factor's row being eliminated
  std::vector<double> schur, scale;          // the dense trailing block, its pivots' scales
  Eigen::MatrixXd g_pos, g_neg;              // heavy columns' block rows times sqrt|D|, by the sign of D
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// Column k of the matrix permuted by perm (perm[new] = old), upper triangle,
// as CSC: colptr[n+1], rows and the triplet each entry comes from (so that
// values map without a copy).
void permutedUpper(int n, int nz, const int* irn, const int* jcn, const int* perm, std::vector<int>& colptr,
                   std::vector<int>& rows, std::vector<int>& src) {
  std::vector<int> pinv(n);
  for (int i = 0; i < n; ++i) pinv[perm[i]] = i;
  colptr.assign(n + 1, 0);
  for (int k = 0; k < nz; ++k) {
    const int i = pinv[irn[k] - 1], j = pinv[jcn[k] - 1];
    ++colptr[(i > j ? i : j) + 1];
  }
  for (int j = 0; j < n; ++j) colptr[j + 1] += colptr[j];
  rows.resize(nz);
  src.resize(nz);
  std::vector<int> next(colptr.begin(), colptr.end() - 1);  // each column's next free position
  for (int k = 0; k < nz; ++k) {
    const int i = pinv[irn[k] - 1], j = pinv[jcn[k] - 1];
    const int col = i > j ? i : j, p = next[col]++;
    rows[p] = i > j ? j : i;
    src[p] = k;
  }
}

// Where the dense trailing block starts: the columns from there on are full
// below the diagonal. In these systems it is most of the variables and the
// equality rows once the slacks are condensed (70-120 of 300-400 rows, about
// half of the factorization's work), and it is factorized densely.
// `count(c)`: the entries below the diagonal in column c of L (the analysis's
// colcount in factor, Lp's differences in solve: the same rule for both).
template <class Count>
int denseStart(int n, Count count) {
  int t = n;
  while (t > 0 && count(t - 1) == n - t) --t;
  return n - t >= kMinDense ? t : n;
}

// Whether entries [begin, end) of a column of L hold consecutive rows: its
// rows increase, so first and last tell (the configuration's nearly full
// columns, updated without indices).
inline bool consecutiveRows(const int* Li, int begin, int end) {
  return end - begin >= 2 && Li[end - 1] - Li[begin] == end - begin - 1;
}

// The dot products l . w of the dense backward sweep, for R right-hand
// sides at once: w holds R interleaved vectors (w[q * R + r]; R = 1: one
// vector). Each sum is formed in the order Eigen 3.4's dot() forms it for
// doubles with SSE2 packets (Redux.h, LinearVectorizedTraversal), which
// solve() called before this: two accumulators of two lanes over the first
// multiple of 4, then one more pair, the lanes added, then the last
// element. So the factorization's results did not change when solve() came
// to use it, and they no longer depend on Eigen's version or vector width.
// The R sums run side by side.
template <int R>
__attribute__((always_inline)) inline void eigenOrderDots(const double* __restrict l, const double* __restrict w,
                                                          int len, double* __restrict out) {
  if (len == 0) {
    for (int r = 0; r < R; ++r) out[r] = 0.0;
    return;
  }
  const int size2 = (len / 4) * 4, size1 = (len / 2) * 2;
  if (size1 == 0) {
    for (int r = 0; r < R; ++r) out[r] = l[0] * w[r];
    return;
  }
  double a0[R], a1[R], b0[R], b1[R];
  for (int r = 0; r < R; ++r) a0[r] = l[0] * w[r], a1[r] = l[1] * w[R + r];
  if (size1 > 2) {
    for (int r = 0; r < R; ++r) b0[r] = l[2] * w[2 * R + r], b1[r] = l[3] * w[3 * R + r];
    for (int i = 4; i < size2; i += 4)
      for (int r = 0; r < R; ++r) {
        a0[r] = a0[r] + l[i] * w[i * R + r];
        a1[r] = a1[r] + l[i + 1] * w[(i + 1) * R + r];
        b0[r] = b0[r] + l[i + 2] * w[(i + 2) * R + r];
        b1[r] = b1[r] + l[i + 3] * w[(i + 3) * R + r];
      }
    for (int r = 0; r < R; ++r) a0[r] = a0[r] + b0[r], a1[r] = a1[r] + b1[r];
    if (size1 > size2)
      for (int r = 0; r < R; ++r) {
        a0[r] = a0[r] + l[size2] * w[size2 * R + r];
        a1[r] = a1[r] + l[size2 + 1] * w[(size2 + 1) * R + r];
      }
  }
  for (int r = 0; r < R; ++r) out[r] = a0[r] + a1[r];
  if (size1 < len)
    for (int r = 0; r < R; ++r) out[r] = out[r] + l[len - 1] * w[(len - 1) * R + r];
}

}  // namespace

long analyse(int n, int nz, const int* irn, const int* jcn, int* perm, int* parent, int* colcount, std::string* why) {
  for (int k = 0; k < nz; ++k)
    if (irn[k] < 1 || irn[k] > n || jcn[k] < 1 || jcn[k] > n) {
      if (why) *why = "entry " + std::to_string(k) + " out of range";
      return -1;
    }
  // Symmetric adjacency without the diagonal (duplicates kept: harmless).
  std::vector<int> deg(n + 1, 0), adj;
  for (int k = 0; k < nz; ++k)
    if (irn[k] != jcn[k]) ++deg[irn[k]], ++deg[jcn[k]];
  std::vector<int> start(n + 1, 0);
  for (int i = 0; i < n; ++i) start[i + 1] = start[i] + deg[i + 1];
  adj.resize(start[n]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int k = 0; k < nz; ++k)
    if (irn[k] != jcn[k]) adj[fill[irn[k] - 1]++] = jcn[k] - 1, adj[fill[jcn[k] - 1]++] = irn[k] - 1;

  // Two colours: primal (0) and dual (1). Ipopt's blocks come primal first,
  // so each connected part starts from its lowest row as primal.
  std::vector<int> colour(n, -1), queue;
  for (int s = 0; s < n; ++s) {
    if (colour[s] >= 0) continue;
    colour[s] = 0;
    queue.assign(1, s);
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int i = queue[q];
      for (int p = start[i]; p < start[i + 1]; ++p) {
        const int j = adj[p];
        if (colour[j] < 0) {
          colour[j] = 1 - colour[i];
          queue.push_back(j);
        } else if (colour[j] == colour[i]) {
          if (why) *why = "rows " + std::to_string(i) + " and " + std::to_string(j) + " make the pattern non-bipartite";
          return -1;
        }
      }
    }
  }
  // Distinct neighbours of a row (duplicates in the triplets repeat them).
  auto onlyNeighbour = [&](int i) {
    int only = -1;
    for (int p = start[i]; p < start[i + 1]; ++p) {
      if (only >= 0 && adj[p] != only) return -1;
      only = adj[p];
    }
    return only;
  };
  std::vector<char> placed(n, 0);
  int k = 0;
  auto place = [&](int i) {
    if (!placed[i]) placed[i] = 1, perm[k++] = i;
  };
  for (int i = 0; i < n; ++i)
    if (colour[i] == 0) {
      const int j = onlyNeighbour(i);
      if (j >= 0 && colour[j] == 1) place(i), place(j);
    }
  for (int i = 0; i < n; ++i)
    if (colour[i] == 0) place(i);
  for (int i = 0; i < n; ++i) place(i);

  // Elimination tree and column counts of the permuted matrix (LDL's
  // symbolic pass, up-looking).
  std::vector<int> colptr, rows, src;
  permutedUpper(n, nz, irn, jcn, perm, colptr, rows, src);
  std::vector<int> flag(n);
  long total = 0;
  for (int c = 0; c < n; ++c) {
    parent[c] = -1;
    flag[c] = c;
    colcount[c] = 0;
    for (int p = colptr[c]; p < colptr[c + 1]; ++p)
      for (int i = rows[p]; i < c && flag[i] != c; i = parent[i]) {
        if (parent[i] == -1) parent[i] = c;
        ++colcount[i];
        ++total;
        flag[i] = c;
      }
  }
  return total;
}

namespace {

// The program of a pattern: the original up-looking traversal (the nonzero
// pattern of each row of L as paths up the elimination tree from the
// entries of its column of the upper triangle, as far as the dense block),
// recorded instead of computed on.
void makeProgram(Program& pr, int n, int nz, const int* irn, const int* jcn, const int* perm, const int* parent,
                 const int* colcount) {
  pr.n = -1;  // matches nothing until it is whole (an allocation may throw on the way)
  permutedUpper(n, nz, irn, jcn, perm, pr.colptr, pr.rows, pr.src);
  const int t = denseStart(n, [colcount](int c) { return colcount[c]; });
  pr.t = t, pr.m = n - t;
  std::vector<int> Lp(n + 1);
  Lp[0] = 0;
  for (int c = 0; c < n; ++c) Lp[c + 1] = Lp[c] + colcount[c];
  std::vector<int> flag(n, -1), filled(n, 0), above(n, 0), pattern(n);
  std::vector<int> Li(Lp[n]);  // the rows of L's entries, as factor() writes them
  pr.row_step.assign(n + 1, 0);
  pr.steps.clear();
  for (int k = 0; k < n; ++k) {
    int top = n;
    flag[k] = k;
    for (int p = pr.colptr[k]; p < pr.colptr[k + 1]; ++p) {
      int i = pr.rows[p];
      if (i >= t) continue;
      int len = 0;
      for (; i < t && flag[i] != k; i = parent[i]) {
        pattern[len++] = i;
        flag[i] = k;
      }
      while (len > 0) pattern[--top] = pattern[--len];
    }
    for (; top < n; ++top) {
      const int i = pattern[top];
      // Column i's entries above the block so far (those inside it go to the
      // block through the Schur update).
      const int begin = Lp[i], end = Lp[i] + above[i];
      pr.steps.push_back({i, Lp[i] + filled[i], end, consecutiveRows(Li.data(), begin, end) ? Li[begin] : -1});
      Li[Lp[i] + filled[i]] = k;
      ++filled[i];
      if (k < t) ++above[i];
    }
    pr.row_step[k + 1] = static_cast<int>(pr.steps.size());
  }
  pr.block_begin.resize(t);
  pr.heavy.resize(t);
  pr.heavy_columns.clear();
  for (int i = 0; i < t; ++i) {
    pr.block_begin[i] = Lp[i] + above[i];
    pr.heavy[i] = Lp[i + 1] - pr.block_begin[i] >= kHeavyColumn;
    if (pr.heavy[i]) pr.heavy_columns.push_back(i);
  }
  pr.irn.assign(irn, irn + nz);
  pr.jcn.assign(jcn, jcn + nz);
  pr.perm.assign(perm, perm + n);
  pr.nz = nz;
  pr.n = n;
}

// Column j of the dense block, column-major in S (m x m, lower triangle):
// divided by its pivot dj into L's column, then the trailing columns
// updated by it, and their pivots' scales.
__attribute__((always_inline)) inline void eliminateDenseColumn(double* S, int m, int j, double dj, double* scale) {
  double* colj = S + static_cast<std::size_t>(j) * m;
  const double inv = 1.0 / dj;
  for (int r = j + 1; r < m; ++r) colj[r] *= inv;  // now L's column
  for (int c = j + 1; c < m; ++c) {
    const double w = colj[c] * dj;
    double* colc = S + static_cast<std::size_t>(c) * m;
    for (int r = c; r < m; ++r) colc[r] -= w * colj[r];
    scale[c] += std::abs(w * colj[c]);
  }
}

}  // namespace

// Compiled for AVX2 as well (ACYCLIC_VECTOR_CLONES): twice the doubles per
// instruction in the loops the compiler vectorizes, the same operations in
// the same order.
ACYCLIC_VECTOR_CLONES int factor(int n, int nz, const int* irn, const int* jcn, const double* a, const int* perm,
                         const int* parent, const int* colcount, int* Lp, int* Li, double* Lx, double* D,
                         int* negative) {
  Scratch& s = scratch();
  Program& pr = s.program;
  if (!pr.matches(n, nz, irn, jcn, perm)) makeProgram(pr, n, nz, irn, jcn, perm, parent, colcount);
  const std::vector<int>& colptr = pr.colptr;
  const std::vector<int>& rows = pr.rows;
  const std::vector<int>& src = pr.src;

  Lp[0] = 0;
  for (int c = 0; c < n; ++c) Lp[c + 1] = Lp[c] + colcount[c];
  const int t = pr.t, m = pr.m;
  std::vector<double>& y = s.y;
  y.assign(n, 0.0);
  // The trailing block, column-major (lower triangle used), and the scale
  // of each of its pivots: the sum of the magnitudes it is made of.
  std::vector<double>& S = s.schur;
  std::vector<double>& scale = s.scale;
  S.assign(static_cast<std::size_t>(m) * m, 0.0);
  scale.resize(m);
  *negative = 0;
  auto pivot = [&](int k, double dk, double sc) {
    // A pivot lost in rounding (dependent equality rows) is a zero pivot.
    if (!(std::abs(dk) > kZeroPivot * sc) || !std::isfinite(dk)) return false;
    D[k] = dk;
    if (dk < 0) ++*negative;
    return true;
  };
  const Program::Step* step = pr.steps.data();
  for (int k = 0; k < n; ++k) {
    // Row k of L left of the trailing block (the program's steps), its
    // column k of the matrix scattered first (inside the block: straight
    // into it).
    for (int p = colptr[k]; p < colptr[k + 1]; ++p) {
      const int i = rows[p];
      if (i >= t) S[static_cast<std::size_t>(i - t) * m + (k - t)] += a[src[p]];
      else y[i] += a[src[p]];
    }
    double dk = 0, sc = 0;
    if (k < t) {
      dk = y[k];
      sc = std::abs(dk);
      y[k] = 0.0;
    }
    const Program::Step* const last = pr.steps.data() + pr.row_step[k + 1];
    for (; step < last; ++step) {
      const int i = step->col;
      const double yi = y[i];
      y[i] = 0.0;
      if (step->first_row >= 0) {
        double* __restrict yr = y.data() + step->first_row;
        const double* __restrict lx = Lx + Lp[i];
        const int len = step->update_end - Lp[i];
        for (int q = 0; q < len; ++q) yr[q] -= lx[q] * yi;
      } else {
        for (int p = Lp[i]; p < step->update_end; ++p) y[Li[p]] -= Lx[p] * yi;
      }
      const double lki = yi / D[i];
      if (k < t) {
        dk -= lki * yi;
        sc += std::abs(lki * yi);
      }
      Li[step->write] = k;
      Lx[step->write] = lki;
    }
    if (k < t && !pivot(k, dk, sc)) return k + 1;
  }
  if (m == 0) return 0;

  // The block's Schur complement: minus l D l^T for each column left of it,
  // over that column's rows inside the block (the last entries of the
  // column). Short columns (a friction row's three forces) update the block
  // entry by entry; long ones (a torque row's joints and forces) are
  // gathered, by the sign of their pivot, into dense columns of G+ and G-
  // scaled by sqrt|D|, and S -= G+ G+^T - G- G-^T as two symmetric rank
  // updates (Eigen's blocked kernels).
  for (int j = 0; j < m; ++j) scale[j] = std::abs(S[static_cast<std::size_t>(j) * m + j]);  // |a_jj|
  for (int i = 0; i < t; ++i) {
    const int b = pr.block_begin[i];
    const int e = Lp[i + 1];
    for (int p = b; p < e; ++p) scale[Li[p] - t] += std::abs(Lx[p] * D[i] * Lx[p]);
    if (pr.heavy[i]) continue;
    for (int p = b; p < e; ++p) {
      const int c = Li[p] - t;
      const double w = Lx[p] * D[i];
      double* col = S.data() + static_cast<std::size_t>(c) * m;
      for (int q = p; q < e; ++q) col[Li[q] - t] -= w * Lx[q];
    }
  }
  if (!pr.heavy_columns.empty()) {
    int npos = 0, nneg = 0;
    for (int i : pr.heavy_columns) (D[i] > 0 ? npos : nneg)++;
    Eigen::MatrixXd& Gp = s.g_pos;
    Eigen::MatrixXd& Gn = s.g_neg;
    Gp.setZero(m, npos);
    Gn.setZero(m, nneg);
    int ip = 0, in = 0;
    for (int i : pr.heavy_columns) {
      const double r = std::sqrt(std::abs(D[i]));
      double* g = D[i] > 0 ? Gp.col(ip++).data() : Gn.col(in++).data();
      for (int p = pr.block_begin[i]; p < Lp[i + 1]; ++p) g[Li[p] - t] = Lx[p] * r;
    }
    Eigen::Map<Eigen::MatrixXd> Sm(S.data(), m, m);
    if (npos) Sm.selfadjointView<Eigen::Lower>().rankUpdate(Gp, -1.0);
    if (nneg) Sm.selfadjointView<Eigen::Lower>().rankUpdate(Gn, 1.0);
  }

  // Dense LDL^T of the block, right-looking, without pivoting: for each
  // column j, its pivot, then the trailing columns updated by contiguous
  // loops the compiler vectorizes.
  for (int j = 0; j < m; ++j) {
    double* colj = S.data() + static_cast<std::size_t>(j) * m;
    const double dj = colj[j];
    if (!pivot(t + j, dj, scale[j])) return t + j + 1;
    eliminateDenseColumn(S.data(), m, j, dj, scale.data());
    int p = Lp[t + j];
    for (int r = j + 1; r < m; ++r, ++p) {
      Li[p] = t + r;
      Lx[p] = colj[r];
    }
  }
  return 0;
}

namespace {

// The solve of R right-hand sides b + r * n, r < R, interleaved in work
// (work[i * R + r], n * R of it): each entry of L is read once for all R,
// and the backward sweeps' sums, a chain of dependent additions per vector,
// run R side by side. Every vector's arithmetic is in the same order
// whatever R, so solve() (R = 1) and solveMany() give the same results, bit
// for bit. Columns from t on are the dense trailing block (factor): each
// holds every row below its diagonal, contiguously in Lx, and is swept
// without indices.
template <int R>
__attribute__((always_inline)) inline void solveInterleaved(int n, const int* perm, const int* Lp, const int* Li,
                                                            const double* Lx, const double* D, double* b,
                                                            double* __restrict work) {
  const int t = denseStart(n, [Lp](int c) { return Lp[c + 1] - Lp[c]; });
  for (int k = 0; k < n; ++k)
    for (int r = 0; r < R; ++r) work[k * R + r] = b[r * n + perm[k]];
  double x[R];
  for (int j = 0; j < t; ++j) {
    for (int r = 0; r < R; ++r) x[r] = work[j * R + r];
    const int begin = Lp[j], end = Lp[j + 1];
    if (consecutiveRows(Li, begin, end)) {  // the configuration's nearly full columns: no indices
      double* __restrict w = work + Li[begin] * R;
      const double* __restrict l = Lx + begin;
      for (int q = 0; q < end - begin; ++q)
        for (int r = 0; r < R; ++r) w[q * R + r] -= l[q] * x[r];
    } else {
      for (int p = begin; p < end; ++p) {
        double* __restrict w = work + Li[p] * R;
        const double l = Lx[p];
        for (int r = 0; r < R; ++r) w[r] -= l * x[r];
      }
    }
  }
  for (int j = t; j < n; ++j) {
    const int len = n - 1 - j;
    for (int r = 0; r < R; ++r) x[r] = work[j * R + r];
    double* __restrict w = work + (j + 1) * R;
    const double* __restrict l = Lx + Lp[j];
    for (int q = 0; q < len; ++q)
      for (int r = 0; r < R; ++r) w[q * R + r] -= l[q] * x[r];
  }
  for (int j = 0; j < n; ++j)
    for (int r = 0; r < R; ++r) work[j * R + r] /= D[j];
  for (int j = n - 1; j >= t; --j) {
    eigenOrderDots<R>(Lx + Lp[j], work + (j + 1) * R, n - 1 - j, x);
    for (int r = 0; r < R; ++r) work[j * R + r] -= x[r];
  }
  for (int j = t - 1; j >= 0; --j) {
    for (int r = 0; r < R; ++r) x[r] = work[j * R + r];
    for (int p = Lp[j]; p < Lp[j + 1]; ++p) {
      const double* __restrict w = work + Li[p] * R;
      const double l = Lx[p];
      for (int r = 0; r < R; ++r) x[r] -= l * w[r];
    }
    for (int r = 0; r < R; ++r) work[j * R + r] = x[r];
  }
  for (int k = 0; k < n; ++k)
    for (int r = 0; r < R; ++r) b[r * n + perm[k]] = work[k * R + r];
}

}  // namespace

ACYCLIC_VECTOR_CLONES void solve(int n, const int* perm, const int* Lp, const int* Li, const double* Lx, const double* D,
                         double* b, double* work) {
  solveInterleaved<1>(n, perm, Lp, Li, Lx, D, b, work);
}

ACYCLIC_VECTOR_CLONES void solveMany(int n, int nrhs, const int* perm, const int* Lp, const int* Li, const double* Lx,
                                     const double* D, double* b, double* work) {
  // In groups of at most kMaxSolvedAtOnce (bench_kkt: six at once about
  // twice as fast as one by one; in groups of four, 1.5 times).
  for (int done = 0; done < nrhs;) {
    double* bg = b + static_cast<long>(done) * n;
    switch (std::min(nrhs - done, kMaxSolvedAtOnce)) {
      case 1: solve(n, perm, Lp, Li, Lx, D, bg, work), done += 1; break;
      case 2: solveInterleaved<2>(n, perm, Lp, Li, Lx, D, bg, work), done += 2; break;
      case 3: solveInterleaved<3>(n, perm, Lp, Li, Lx, D, bg, work), done += 3; break;
      case 4: solveInterleaved<4>(n, perm, Lp, Li, Lx, D, bg, work), done += 4; break;
      case 5: solveInterleaved<5>(n, perm, Lp, Li, Lx, D, bg, work), done += 5; break;
      case 6: solveInterleaved<6>(n, perm, Lp, Li, Lx, D, bg, work), done += 6; break;
      case 7: solveInterleaved<7>(n, perm, Lp, Li, Lx, D, bg, work), done += 7; break;
      default: solveInterleaved<8>(n, perm, Lp, Li, Lx, D, bg, work), done += 8; break;
    }
  }
}

}  // namespace acyclic::kkt
