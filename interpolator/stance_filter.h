#pragma once
// Stance filtering (the paper's open problem, docs/design.md section 10): a stance
// is dropped when its neighbours hold the same contacts and the direct
// transition between them, all contacts held, is valid (knots found, every
// segment's middle valid). Typical drops: a contact touched and left again
// without use, or a support flipped and flipped back. Greedy, left to right.
#include <atomic>
#include <map>
#include <utility>
#include <vector>

#include "interpolator/transition.h"

namespace acyclic {

struct FilterResult {
  std::vector<int> kept;  // plan stance indices, in order
  int dropped = 0;
  long posture_calls = 0;
  double posture_seconds = 0;
  bool cancelled = false;
  // The direct transitions that justified a drop, keyed by (from, to): reused.
  std::map<std::pair<int, int>, TransitionOutcome> solved;
};

FilterResult filterStances(const Plan& plan, TransitionSolver& solver, const std::atomic<bool>* cancel = nullptr);

}  // namespace acyclic
