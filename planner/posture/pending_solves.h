#pragma once
// The block of right-hand sides Ipopt's Ma27TSolverInterface::Backsolve is
// solving on this thread (ipopt_backsolve.cpp records it, ipopt_ldl.cpp
// solves it at once on the first MA27CD call of the block). C linkage: it
// crosses from libacyclic_ipopt_interposers.so to the posture library.
extern "C" {
struct acyclic_pending_solves {
  double* rhs;  // the block: nrhs vectors of the system's size, one after the other
  int nrhs;     // 0: no block (a solve outside Backsolve)
  int solved;   // the block was solved by its first MA27CD call
};
acyclic_pending_solves* acyclic_pending_solves_of_thread();
}
