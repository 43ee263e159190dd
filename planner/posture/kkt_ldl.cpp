#include "planner/posture/kkt_ldl.h"

#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace acyclic::kkt {

namespace {

// Relative size under which a pivot counts as zero: a few hundred roundings.
constexpr double kZeroPivot = 1e-13;
// A trailing block smaller than this is left to the sparse elimination.
constexpr int kMinDense = 8;
// A column with this many rows in the trailing block updates it densely.
constexpr int kHeavyColumn = 12;

// Scratch reused across calls on one thread (never state between calls).
struct Scratch {
  std::vector<int> pinv, colptr, rows, src;  // the permuted upper triangle (permutedUpper)
  std::vector<int> next;                     // permutedUpper's fill positions
  std::vector<int> work;                     // factor's flag, filled and pattern
  std::vector<double> y;                     // factor's row being eliminated
  std::vector<double> schur, scale;          // the dense trailing block, its pivots' scales
  std::vector<std::pair<int, int>> heavy;    // columns whose block rows are gathered densely, where those start
  Eigen::MatrixXd g_pos, g_neg;              // those rows times sqrt|D|, by the sign of D
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// Column k of the permuted upper triangle, as CSC: colptr[n+1], rows and
// the triplet each entry comes from (so that values map without a copy).
void permutedUpper(int n, int nz, const int* irn, const int* jcn, const int* pinv, std::vector<int>& colptr,
                   std::vector<int>& rows, std::vector<int>& src) {
  colptr.assign(n + 1, 0);
  for (int k = 0; k < nz; ++k) {
    const int i = pinv[irn[k] - 1], j = pinv[jcn[k] - 1];
    ++colptr[(i > j ? i : j) + 1];
  }
  for (int j = 0; j < n; ++j) colptr[j + 1] += colptr[j];
  rows.resize(nz);
  src.resize(nz);
  std::vector<int>& next = scratch().next;
  next.assign(colptr.begin(), colptr.end() - 1);
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
  std::vector<int> pinv(n);
  for (int i = 0; i < n; ++i) pinv[perm[i]] = i;
  std::vector<int> colptr, rows, src;
  permutedUpper(n, nz, irn, jcn, pinv.data(), colptr, rows, src);
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

int factor(int n, int nz, const int* irn, const int* jcn, const double* a, const int* perm, const int* parent,
           const int* colcount, int* Lp, int* Li, double* Lx, double* D, int* negative) {
  Scratch& s = scratch();
  std::vector<int>& pinv = s.pinv;
  pinv.resize(n);
  for (int i = 0; i < n; ++i) pinv[perm[i]] = i;
  std::vector<int>& colptr = s.colptr;
  std::vector<int>& rows = s.rows;
  std::vector<int>& src = s.src;
  permutedUpper(n, nz, irn, jcn, pinv.data(), colptr, rows, src);

  Lp[0] = 0;
  for (int c = 0; c < n; ++c) Lp[c + 1] = Lp[c] + colcount[c];
  const int t = denseStart(n, [colcount](int c) { return colcount[c]; }), m = n - t;
  std::vector<int>& work = s.work;  // flag[n], filled[n], pattern[n]
  work.assign(3 * static_cast<std::size_t>(n), 0);
  int* flag = work.data();
  int* filled = flag + n;
  int* pattern = filled + n;
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
  for (int k = 0; k < n; ++k) {
    // Nonzero pattern of row k of L left of the trailing block: the paths up
    // the elimination tree from the entries of column k of the upper
    // triangle, as far as the block (inside it every column is full).
    int top = n;
    flag[k] = k;
    for (int p = colptr[k]; p < colptr[k + 1]; ++p) {
      int i = rows[p];
      if (i >= t) {  // inside the block: straight into it (k >= t too)
        S[static_cast<std::size_t>(i - t) * m + (k - t)] += a[src[p]];
        continue;
      }
      y[i] += a[src[p]];
      int len = 0;
      for (; i < t && flag[i] != k; i = parent[i]) {
        pattern[len++] = i;
        flag[i] = k;
      }
      while (len > 0) pattern[--top] = pattern[--len];
    }
    double dk = 0, sc = 0;
    if (k < t) {
      dk = y[k];
      sc = std::abs(dk);
      y[k] = 0.0;
    }
    for (; top < n; ++top) {
      const int i = pattern[top];
      const double yi = y[i];
      y[i] = 0.0;
      // Column i's entries above the block (those below it, filled by the
      // block's earlier rows, go to the block through the update below).
      const int end = Lp[i] + filled[i];
      for (int p = Lp[i]; p < end && Li[p] < t; ++p) y[Li[p]] -= Lx[p] * yi;
      const double lki = yi / D[i];
      if (k < t) {
        dk -= lki * yi;
        sc += std::abs(lki * yi);
      }
      Li[end] = k;
      Lx[end] = lki;
      ++filled[i];
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
  auto& heavy = s.heavy;
  heavy.clear();
  for (int i = 0; i < t; ++i) {
    int b = Lp[i + 1];
    while (b > Lp[i] && Li[b - 1] >= t) --b;
    const int e = Lp[i + 1];
    for (int p = b; p < e; ++p) scale[Li[p] - t] += std::abs(Lx[p] * D[i] * Lx[p]);
    if (e - b >= kHeavyColumn) {
      heavy.emplace_back(i, b);
      continue;
    }
    for (int p = b; p < e; ++p) {
      const int c = Li[p] - t;
      const double w = Lx[p] * D[i];
      double* col = S.data() + static_cast<std::size_t>(c) * m;
      for (int q = p; q < e; ++q) col[Li[q] - t] -= w * Lx[q];
    }
  }
  if (!heavy.empty()) {
    int npos = 0, nneg = 0;
    for (const auto& [i, b] : heavy) (D[i] > 0 ? npos : nneg)++;
    Eigen::MatrixXd& Gp = s.g_pos;
    Eigen::MatrixXd& Gn = s.g_neg;
    Gp.setZero(m, npos);
    Gn.setZero(m, nneg);
    int ip = 0, in = 0;
    for (const auto& [i, b] : heavy) {
      const double r = std::sqrt(std::abs(D[i]));
      double* g = D[i] > 0 ? Gp.col(ip++).data() : Gn.col(in++).data();
      for (int p = b; p < Lp[i + 1]; ++p) g[Li[p] - t] = Lx[p] * r;
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
    const double inv = 1.0 / dj;
    for (int r = j + 1; r < m; ++r) colj[r] *= inv;  // now L's column
    for (int c = j + 1; c < m; ++c) {
      const double w = colj[c] * dj;
      double* colc = S.data() + static_cast<std::size_t>(c) * m;
      for (int r = c; r < m; ++r) colc[r] -= w * colj[r];
      scale[c] += std::abs(w * colj[c]);
    }
    int p = Lp[t + j];
    for (int r = j + 1; r < m; ++r, ++p) {
      Li[p] = t + r;
      Lx[p] = colj[r];
    }
  }
  return 0;
}

void solve(int n, const int* perm, const int* Lp, const int* Li, const double* Lx, const double* D, double* b,
           double* work) {
  // Columns from t on are the dense trailing block (factor): each holds every
  // row below its diagonal, contiguously in Lx, and is swept without indices.
  const int t = denseStart(n, [Lp](int c) { return Lp[c + 1] - Lp[c]; });
  for (int k = 0; k < n; ++k) work[k] = b[perm[k]];
  for (int j = 0; j < t; ++j) {
    const double xj = work[j];
    for (int p = Lp[j]; p < Lp[j + 1]; ++p) work[Li[p]] -= Lx[p] * xj;
  }
  for (int j = t; j < n; ++j) {
    const int len = n - 1 - j;
    Eigen::Map<Eigen::VectorXd>(work + j + 1, len) -= work[j] * Eigen::Map<const Eigen::VectorXd>(Lx + Lp[j], len);
  }
  for (int j = 0; j < n; ++j) work[j] /= D[j];
  for (int j = n - 1; j >= t; --j) {
    const int len = n - 1 - j;
    work[j] -= Eigen::Map<const Eigen::VectorXd>(Lx + Lp[j], len).dot(Eigen::Map<const Eigen::VectorXd>(work + j + 1, len));
  }
  for (int j = t - 1; j >= 0; --j) {
    double xj = work[j];
    for (int p = Lp[j]; p < Lp[j + 1]; ++p) xj -= Lx[p] * work[Li[p]];
    work[j] = xj;
  }
  for (int k = 0; k < n; ++k) b[perm[k]] = work[k];
}

}  // namespace acyclic::kkt
