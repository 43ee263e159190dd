#include "planner/posture/heap_tuning.h"

#include <malloc.h>

namespace acyclic {

void keepSolverWorkspaceInHeap() {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);  // blocks up to 256 MB come from the heap, not mmap
  mallopt(M_TRIM_THRESHOLD, 256 << 20);  // and the heap is not trimmed below that
  mallopt(M_TOP_PAD, 64 << 20);          // grown 64 MB at a time
}

}  // namespace acyclic
