#pragma once
// MUMPS allocates and frees its workspace on every factorization and solve,
// and glibc by default returns such blocks to the kernel each time (mmap for
// large ones, trimming the heap's top): every posture-generator call then
// pays page faults. Measured in the interpolator: a fifth of the wall time.
// Call once at the start of a program that runs posture generators; it
// changes only where memory comes from, never a result.
namespace acyclic {
void keepSolverWorkspaceInHeap();
}
