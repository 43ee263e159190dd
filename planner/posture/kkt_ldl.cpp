#include "planner/posture/kkt_ldl.h"

#include <cmath>
#include <vector>

namespace acyclic::kkt {

namespace {

// Relative size under which a pivot counts as zero: a few hundred roundings.
constexpr double kZeroPivot = 1e-13;

// Scratch reused across calls on one thread (never state between calls).
struct Scratch {
  std::vector<int> pinv, colptr, rows, src;  // the permuted upper triangle (permutedUpper)
  std::vector<int> next;                     // permutedUpper's fill positions
  std::vector<int> work;                     // factor's flag, filled and pattern
  std::vector<double> y;                     // factor's row being eliminated
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
  std::vector<int>& work = s.work;  // flag[n], filled[n], pattern[n]
  work.assign(3 * static_cast<std::size_t>(n), 0);
  int* flag = work.data();
  int* filled = flag + n;
  int* pattern = filled + n;
  std::vector<double>& y = s.y;
  y.assign(n, 0.0);
  *negative = 0;
  for (int k = 0; k < n; ++k) {
    // Nonzero pattern of row k of L: the paths up the elimination tree from
    // the entries of column k of the upper triangle.
    int top = n;
    flag[k] = k;
    for (int p = colptr[k]; p < colptr[k + 1]; ++p) {
      int i = rows[p];
      y[i] += a[src[p]];
      int len = 0;
      for (; flag[i] != k; i = parent[i]) {
        pattern[len++] = i;
        flag[i] = k;
      }
      while (len > 0) pattern[--top] = pattern[--len];
    }
    double dk = y[k];
    double scale = std::abs(dk);  // of the terms that make the pivot: what it cancels against
    y[k] = 0.0;
    for (; top < n; ++top) {
      const int i = pattern[top];
      const double yi = y[i];
      y[i] = 0.0;
      const int end = Lp[i] + filled[i];
      for (int p = Lp[i]; p < end; ++p) y[Li[p]] -= Lx[p] * yi;
      const double lki = yi / D[i];
      dk -= lki * yi;
      scale += std::abs(lki * yi);
      Li[end] = k;
      Lx[end] = lki;
      ++filled[i];
    }
    // A pivot lost in rounding (dependent equality rows) is a zero pivot.
    if (!(std::abs(dk) > kZeroPivot * scale) || !std::isfinite(dk)) return k + 1;
    D[k] = dk;
    if (dk < 0) ++*negative;
  }
  return 0;
}

void solve(int n, const int* perm, const int* Lp, const int* Li, const double* Lx, const double* D, double* b,
           double* work) {
  for (int k = 0; k < n; ++k) work[k] = b[perm[k]];
  for (int j = 0; j < n; ++j) {
    const double xj = work[j];
    for (int p = Lp[j]; p < Lp[j + 1]; ++p) work[Li[p]] -= Lx[p] * xj;
  }
  for (int j = 0; j < n; ++j) work[j] /= D[j];
  for (int j = n - 1; j >= 0; --j) {
    double xj = work[j];
    for (int p = Lp[j]; p < Lp[j + 1]; ++p) xj -= Lx[p] * work[Li[p]];
    work[j] = xj;
  }
  for (int k = 0; k < n; ++k) b[perm[k]] = work[k];
}

}  // namespace acyclic::kkt
