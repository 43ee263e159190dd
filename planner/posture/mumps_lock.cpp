// MUMPS, Ipopt's only linear solver in Debian (sequential build), keeps
// Fortran module state and is not reentrant: two solves on two threads crash
// it (DMUMPS_LOAD_INIT). This shared library interposes dmumps_c, the single
// entry point Ipopt calls, and serializes it with a process-wide lock, so
// that everything else in concurrent posture generators (function and
// derivative evaluations, collision checks) still runs in parallel.
// It must precede libdmumps_seq in the link order (planner/CMakeLists.txt).
//
// It also replaces one MUMPS internal that costs more than the solves:
// MUMPS 5.5 computes, at the end of every call (each factorization and each
// one-vector solve, of which Ipopt makes a dozen per iteration with L-BFGS),
// how many bytes a save of the instance would take (JOB=7), by walking the
// 186 fields of its structure through string SELECT CASEs. perf on
// bench_posture: about 20% of all CPU. The figure only fills RINFO(7:8) and
// RINFOG(17:18), which Ipopt never reads and no save ever uses here. The
// call goes through libdmumps_seq's PLT, so a definition here wins.
#include <mutex>

#include "planner/posture/next_definition.h"

namespace {
std::mutex& mumpsMutex() {
  static std::mutex m;
  return m;
}
using DmumpsFn = void (*)(void*);
DmumpsFn realDmumps() {
  static const DmumpsFn fn = acyclic::nextDefinition<DmumpsFn>("dmumps_c", "dmumps_c (the MUMPS lock's)");
  return fn;
}
}  // namespace

extern "C" void dmumps_c(void* id) {
  const DmumpsFn fn = realDmumps();
  std::lock_guard<std::mutex> lock(mumpsMutex());
  fn(id);
}

// SUBROUTINE DMUMPS_COMPUTE_MEMORY_SAVE(id, TOTAL_FILE_SIZE, TOTAL_STRUC_SIZE)
// of module DMUMPS_SAVE_RESTORE (MUMPS 5.5), all three by reference; the two
// sizes are INTEGER(8) outputs.
extern "C" void __dmumps_save_restore_MOD_dmumps_compute_memory_save(void* /*id*/, long long* file_size,
                                                                      long long* struc_size) {
  *file_size = 0;
  *struc_size = 0;
}

extern "C" int acyclic_mumps_lock_linked() { return 1; }
