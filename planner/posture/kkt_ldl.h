#pragma once
// A sparse LDL^T factorization for Ipopt's KKT ("augmented") systems of the
// posture problems, without pivoting, in an order that makes every pivot
// nonzero when Ipopt's own inertia correction has done its part.
//
// Why not MUMPS, Ipopt's only linear solver in Debian: it is not reentrant
// (a process-wide lock serializes the two threads the planner and the
// interpolator run, mumps_lock.cpp), and each of its calls has a fixed cost
// that systems of a few hundred rows do not amortize (perf: MUMPS about 40%
// of a posture call). These systems have a structure that needs no pivoting:
// with a diagonal Hessian block (L-BFGS's sigma*I under Sherman-Morrison, or
// the diagonal option) the graph of the off-diagonal entries is bipartite,
// primal rows (variables x, slacks s) against dual rows (equality rows c,
// inequality rows d). The order used is: each slack (a primal row whose only
// neighbour is one dual row), then that dual row (its diagonal is now
// -1/Sigma_s, nonzero), then the other primal rows (positive definite once
// the inequality rows are condensed onto them), then the remaining dual rows
// (a negative definite Schur complement when the equality Jacobian has full
// rank; a zero pivot otherwise, reported as singular so that Ipopt
// regularizes). The inertia is the count of negative pivots (Sylvester).
//
// The elimination is up-looking and sparse, except for the trailing block of
// columns that are full below the diagonal (most variables and the equality
// rows once the slacks are condensed: 70-120 of 300-400 rows, most of the
// work): its Schur complement is formed from the sparse columns' rows in it
// (the long ones, a torque row's, as two dense symmetric rank updates), then
// it is factorized densely, in the same order, without pivoting. Perf on
// bench_posture: the linear algebra's time a fifth lower than all sparse.
//
// All state lives in caller-owned arrays, as with HSL's MA27, whose calling
// sequence Ipopt's linear-solver loader accepts (ipopt_ldl.cpp), but for
// what a factorization keeps of the last pattern it saw (the pattern-only
// part of its work, replayed while the pattern stays: checked against the
// whole pattern first) and its scratch, both per thread: two solvers on two
// threads share nothing.
#include <string>

namespace acyclic::kkt {

// Symbolic analysis of the pattern of an n x n symmetric matrix given as nz
// 1-based triplets (irn[k], jcn[k]) of one triangle or both, duplicates
// allowed. Writes perm[n] (perm[new] = old row), parent[n] (elimination
// tree) and colcount[n] (entries below the diagonal per column of L).
// Returns the entries of L, or -1 with *why set when the pattern is not one
// this factorization handles (an index out of range, a non-bipartite graph).
long analyse(int n, int nz, const int* irn, const int* jcn, int* perm, int* parent, int* colcount, std::string* why);

// Numeric factorization of the matrix with values a[nz] (same triplets).
// Writes Lp[n+1], Li[lnz] and Lx[lnz] (L by columns, unit diagonal not
// stored), D[n], and *negative (the number of negative pivots). Returns 0, or
// k + 1 when the pivot of row perm[k] is zero (below 1e-13 of the terms it
// is made of: rows dependent up to rounding) or not finite.
int factor(int n, int nz, const int* irn, const int* jcn, const double* a, const int* perm, const int* parent,
           const int* colcount, int* Lp, int* Li, double* Lx, double* D, int* negative);

// Solves A x = b in place with the factors; work[n] is scratch.
void solve(int n, const int* perm, const int* Lp, const int* Li, const double* Lx, const double* D, double* b,
           double* work);

// Solves A x = b for nrhs right-hand sides b + r * n (r < nrhs) in place,
// each to the same result as solve() gives it, bit for bit, but faster than
// one by one (each entry of L is read once for several of them);
// work[n * kMaxSolvedAtOnce] is scratch. Ipopt asks for several at once
// with L-BFGS (the low-rank update's vectors, six with its default
// history): ipopt_ldl.cpp.
constexpr int kMaxSolvedAtOnce = 8;
void solveMany(int n, int nrhs, const int* perm, const int* Lp, const int* Li, const double* Lx, const double* D,
               double* b, double* work);

// Registers this factorization with Ipopt as its linear solver "ma27"
// (through LSL_setMA27, the loader's way to supply the routines). Call before
// an IpoptApplication initializes; idempotent and thread-safe. The options
// that select it are set by PostureGenerator (linear_solver "ldl").
void registerWithIpopt();

// Called with each matrix Ipopt hands to factor() through registerWithIpopt's
// entry, before it is factorized (triplets 1-based, as in factor()): for a
// benchmark that times the factorization on real systems (bench/bench_kkt).
// nullptr: none (the default). Process-wide; the call is on the solving
// thread.
using MatrixObserver = void (*)(int n, int nz, const int* irn, const int* jcn, const double* a);
void observeFactorizations(MatrixObserver observer);

// Whether the blocks of right-hand sides Ipopt's MA27 interface solves
// (ipopt_backsolve.cpp) go to solveMany at once (true, the default) or to
// solve() one by one: the same results either way; for a test that says
// so, and a benchmark. Process-wide.
void solveBlocksAtOnce(bool at_once);

// Right-hand sides that Ipopt's solves have had solved in blocks (solveMany)
// since the process began: a test's way to see that the interposer is in use.
long rightHandSidesSolvedTogether();

}  // namespace acyclic::kkt
