#include "interpolator/stance_filter.h"

namespace acyclic {

FilterResult filterStances(const Plan& plan, TransitionSolver& solver, const std::atomic<bool>* cancel) {
  FilterResult fr;
  const int n = static_cast<int>(plan.stances.size());
  if (n == 0) return fr;
  fr.kept.push_back(0);
  for (int k = 1; k + 1 < n; ++k) {
    const int prev = fr.kept.back();
    std::vector<TransitionDesign> d;
    // Only a stance whose neighbours hold the same contacts (support included) can go.
    if (diffStances(plan.stances[prev].specs(), plan.stances[k + 1].specs()).changes() == 0 &&
        designTransitions(plan, {prev, k + 1}, d).empty() && d.size() == 1 &&
        d[0].kind == TransitionDesign::Kind::Fixed) {
      TransitionOutcome o = solver.solve(plan, d[0], cancel);
      fr.posture_calls += o.posture_calls;
      fr.posture_seconds += o.posture_seconds;
      if (o.cancelled) {
        fr.cancelled = true;
        return fr;
      }
      if (o.ok) {
        ++fr.dropped;
        fr.solved[{prev, k + 1}] = std::move(o);
        continue;
      }
    }
    fr.kept.push_back(k);
  }
  if (n > 1) fr.kept.push_back(n - 1);
  return fr;
}

}  // namespace acyclic
