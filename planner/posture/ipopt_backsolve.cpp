// Ipopt 3.11's Ma27TSolverInterface::Backsolve(nrhs, rhs) solves its nrhs
// right-hand sides one by one, calling MA27CD (kkt_ldl's solve, through
// ipopt_ldl.cpp) for each. With L-BFGS, Sherman-Morrison asks for six at a
// time at every iteration (the update's vectors): 62% of the solves in the
// chair's search. This definition, in the library linked before libipopt
// (libipopt calls Backsolve through its PLT), records which block Ipopt is
// solving and then runs Ipopt's own Backsolve; the first MA27CD call of the
// block solves all of it at once (kkt::solveMany, the same results bit for
// bit) and the others find theirs done. Nothing about Ipopt's object is
// read: it is passed through.
#include "planner/posture/next_definition.h"
#include "planner/posture/pending_solves.h"

namespace {
// Ipopt::ESymSolverStatus Ipopt::Ma27TSolverInterface::Backsolve(Index nrhs, double* rhs_vals),
// a non-virtual member: `this` is its first argument.
constexpr const char* kBacksolve = "_ZN5Ipopt20Ma27TSolverInterface9BacksolveEiPd";
using BacksolveFn = int (*)(void*, int, double*);

BacksolveFn realBacksolve() {
  static const BacksolveFn fn =
      acyclic::nextDefinition<BacksolveFn>(kBacksolve, "Ipopt's Ma27TSolverInterface::Backsolve");
  return fn;
}
}  // namespace

extern "C" acyclic_pending_solves* acyclic_pending_solves_of_thread() {
  thread_local acyclic_pending_solves pending{nullptr, 0, 0};
  return &pending;
}

extern "C" int _ZN5Ipopt20Ma27TSolverInterface9BacksolveEiPd(void* self, int nrhs, double* rhs_vals) {
  const BacksolveFn fn = realBacksolve();
  acyclic_pending_solves* pending = acyclic_pending_solves_of_thread();
  const acyclic_pending_solves outer = *pending;
  *pending = {rhs_vals, nrhs, 0};
  struct Restore {  // whatever happens inside Ipopt
    acyclic_pending_solves* p;
    acyclic_pending_solves saved;
    ~Restore() { *p = saved; }
  } restore{pending, outer};
  return fn(self, nrhs, rhs_vals);
}
