// kkt_ldl.h's factorization behind HSL MA27's calling sequence, which
// Ipopt 3.11's linear-solver loader takes from whoever supplies it
// (LSL_setMA27) instead of a libhsl.so. Ipopt's Ma27TSolverInterface then
// drives it: MA27AD once per problem structure, MA27BD per matrix, MA27CD
// per right-hand side. Everything it needs between the calls is in the arrays
// Ipopt owns per solver instance:
//   IKEEP[3N] = perm | elimination tree | column counts   (from MA27AD)
//   IW        = perm | Lp[N+1] | Li                        (from MA27BD)
//   A         = D[N] | Lx   (on entry to MA27BD: the matrix's values)
// MA27's pivot tolerance (CNTL(1)) has no meaning here: there is no pivoting.
#include <algorithm>
#include <atomic>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include "planner/posture/kkt_ldl.h"
#include "planner/posture/pending_solves.h"

extern "C" {
typedef void (*ma27ad_t)(int* N, int* NZ, const int* IRN, const int* ICN, int* IW, int* LIW, int* IKEEP, int* IW1,
                         int* NSTEPS, int* IFLAG, int* ICNTL, double* CNTL, int* INFO, double* OPS);
typedef void (*ma27bd_t)(int* N, int* NZ, const int* IRN, const int* ICN, double* A, int* LA, int* IW, int* LIW,
                         int* IKEEP, int* NSTEPS, int* MAXFRT, int* IW1, int* ICNTL, double* CNTL, int* INFO);
typedef void (*ma27cd_t)(int* N, double* A, int* LA, int* IW, int* LIW, double* W, int* MAXFRT, double* RHS, int* IW1,
                         int* NSTEPS, int* ICNTL, double* CNTL);
typedef void (*ma27id_t)(int* ICNTL, double* CNTL);
// Ipopt's HSL loader (libipopt.so.1, Ipopt 3.11).
void LSL_setMA27(ma27ad_t, ma27bd_t, ma27cd_t, ma27id_t);
}

namespace acyclic::kkt {

namespace {

std::atomic<MatrixObserver> observer{nullptr};
std::atomic<long> solved_together{0};
std::atomic<bool> blocks_at_once{true};

// MA27's INFO(1) codes that Ipopt's interface acts on.
constexpr int kOk = 0, kFatal = -1, kIwTooSmall = -3, kATooSmall = -4, kSingular = 3;

long entriesOfL(int n, const int* colcount) {
  long total = 0;
  for (int i = 0; i < n; ++i) total += colcount[i];
  return total;
}

void initialize(int* icntl, double* cntl) {
  std::fill(icntl, icntl + 30, 0);
  std::fill(cntl, cntl + 5, 0.0);
}

void analyseEntry(int* N, int* NZ, const int* IRN, const int* ICN, int*, int*, int* IKEEP, int*, int* NSTEPS,
                  int*, int*, double*, int* INFO, double* OPS) {
  std::fill(INFO, INFO + 20, 0);
  const int n = *N;
  const long lnz = analyse(n, *NZ, IRN, ICN, IKEEP, IKEEP + n, IKEEP + 2 * n, nullptr);
  *NSTEPS = 1;
  *OPS = 0;
  if (lnz < 0) {
    INFO[0] = kFatal;
    return;
  }
  INFO[4] = static_cast<int>(std::max<long>(*NZ, n + lnz));  // reals needed
  INFO[5] = static_cast<int>(2 * n + 1 + lnz);               // integers needed
}

void factorEntry(int* N, int* NZ, const int* IRN, const int* ICN, double* A, int* LA, int* IW, int* LIW, int* IKEEP,
                 int*, int* MAXFRT, int*, int*, double*, int* INFO) {
  std::fill(INFO, INFO + 20, 0);
  const int n = *N, nz = *NZ;
  const int* perm = IKEEP;
  const long lnz = entriesOfL(n, IKEEP + 2 * n);
  const long reals = std::max<long>(nz, n + lnz), ints = 2 * n + 1 + lnz;
  if (*LIW < ints) {
    INFO[0] = kIwTooSmall;
    INFO[1] = static_cast<int>(ints);
    return;
  }
  if (*LA < reals) {
    INFO[0] = kATooSmall;
    INFO[1] = static_cast<int>(reals);
    return;
  }
  if (const MatrixObserver o = observer.load()) o(n, nz, IRN, ICN, A);
  thread_local std::vector<double> values;
  values.assign(A, A + nz);  // the factors overwrite them
  std::copy(perm, perm + n, IW);
  int* Lp = IW + n;
  int negative = 0;
  const int zero = factor(n, nz, IRN, ICN, values.data(), perm, IKEEP + n, IKEEP + 2 * n, Lp, Lp + n + 1, A + n, A,
                          &negative);
  *MAXFRT = n;  // the length of W in MA27CD: our scratch vector
  INFO[0] = zero ? kSingular : kOk;
  INFO[14] = negative;
}

// MA27CD: one right-hand side. Inside a block of them (Backsolve's loop,
// ipopt_backsolve.cpp) the first call solves the whole block at once and
// the others find theirs solved; the loop hands them in order, each n after
// the previous one, and reads none before it has called MA27CD for all.
void solveEntry(int* N, double* A, int*, int* IW, int*, double* W, int*, double* RHS, int*, int*, int*, double*) {
  const int n = *N;
  const int* Lp = IW + n;
  acyclic_pending_solves* block = acyclic_pending_solves_of_thread();
  if (block->nrhs > 1 && blocks_at_once.load(std::memory_order_relaxed)) {
    const long offset = RHS - block->rhs;
    if (offset == 0 && !block->solved) {
      thread_local std::vector<double> work;
      bool have_work = true;
      try {  // nothing may throw through Ipopt's C loader: without scratch, one by one
        work.resize(static_cast<std::size_t>(n) * kMaxSolvedAtOnce);
      } catch (const std::bad_alloc&) {
        have_work = false;
      }
      if (have_work) {
        solveMany(n, block->nrhs, IW, Lp, Lp + n + 1, A + n, A, RHS, work.data());
        block->solved = 1;
        solved_together.fetch_add(block->nrhs, std::memory_order_relaxed);
        return;
      }
    }
    if (block->solved && offset > 0 && offset % n == 0 && offset / n < block->nrhs) return;
  }
  solve(n, IW, Lp, Lp + n + 1, A + n, A, RHS, W);
}

}  // namespace

void observeFactorizations(MatrixObserver o) { observer.store(o); }

long rightHandSidesSolvedTogether() { return solved_together.load(); }

void solveBlocksAtOnce(bool at_once) { blocks_at_once.store(at_once); }

void registerWithIpopt() {
  static std::once_flag once;
  std::call_once(once, [] { LSL_setMA27(analyseEntry, factorEntry, solveEntry, initialize); });
}

}  // namespace acyclic::kkt
