// MUMPS, Ipopt's only linear solver in Debian (sequential build), keeps
// Fortran module state and is not reentrant: two solves on two threads crash
// it (DMUMPS_LOAD_INIT). This shared library interposes dmumps_c, the single
// entry point Ipopt calls, and serializes it with a process-wide lock, so
// that everything else in concurrent posture generators (function and
// derivative evaluations, collision checks) still runs in parallel.
// It must precede libdmumps_seq in the link order (planner/CMakeLists.txt).
#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace {
std::mutex& mumpsMutex() {
  static std::mutex m;
  return m;
}
using DmumpsFn = void (*)(void*);
DmumpsFn realDmumps() {
  static DmumpsFn fn = [] {
    auto f = reinterpret_cast<DmumpsFn>(dlsym(RTLD_NEXT, "dmumps_c"));
    if (!f) {
      std::fprintf(stderr, "acyclic: dmumps_c not found behind the MUMPS lock\n");
      std::abort();
    }
    return f;
  }();
  return fn;
}
}  // namespace

extern "C" void dmumps_c(void* id) {
  const DmumpsFn fn = realDmumps();
  std::lock_guard<std::mutex> lock(mumpsMutex());
  fn(id);
}

extern "C" int acyclic_mumps_lock_linked() { return 1; }
