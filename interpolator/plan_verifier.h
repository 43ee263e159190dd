#pragma once
// The contact planner's lazy verification of transitions
// (PlannerParameters::verify_transitions, docs/design.md section 7): every
// transition of a plan the search found is solved as the interpolator will
// solve it (same designs, every stance kept, same options), and the first
// that cannot be made is reported, so that the search drops the stance it
// leads to and goes on. A plan it accepts interpolates with those options:
// it is verified as its file holds it (written to JSON and read back).
//
// Transitions depend only on their stances: the outcome of each is
// remembered whole in a memo (transition_memo.h), keyed by the stances'
// exact contents, so a plan that shares a prefix with one already verified
// costs only its new transitions, and the interpolator given that memo
// solves none of them again. Solved on
// `threads` workers in order, the first failure in order reported: the
// verdict does not depend on the thread count.
#include <map>
#include <memory>
#include <string>

#include "interpolator/interpolator.h"
#include "interpolator/transition_memo.h"
#include "planner/search/contact_planner.h"

namespace acyclic {

class TransitionVerifier {
 public:
  // Copies the scenario (the verifier outlives the caller's). With a memo of
  // its own, or one shared with other verifiers and with interpolate()
  // (transition_memo.h): the transitions it solves are kept there whole, and
  // it solves with the memo's options.
  TransitionVerifier(const Scenario& sc, const InterpolatorOptions& options);
  TransitionVerifier(const Scenario& sc, std::shared_ptr<TransitionMemo> memo);
  PlanVerdict verify(const Plan& plan, const std::atomic<bool>& stop);
  std::size_t remembered() const { return memo_->size(); }

 private:
  std::shared_ptr<const Scenario> sc_;
  std::shared_ptr<TransitionMemo> memo_;
  std::vector<std::unique_ptr<TransitionSolver>> solvers_;  // one per thread
};

// A PlanVerifier for PlannerParameters::verify_plan around a shared
// TransitionVerifier (the planner may copy it).
PlanVerifier makePlanVerifier(const Scenario& sc, const InterpolatorOptions& options = {});
PlanVerifier makePlanVerifier(const Scenario& sc, std::shared_ptr<TransitionMemo> memo);

// Gives p a verifier when p.verify_transitions is set and it has none:
// with these options, or by default the interpolator's with the scenario's
// margins (withScenarioMargins), as the interpolator will solve them. And,
// unless it has one, a factory of such verifiers (make_verifier): one per
// member of a portfolio. With a memo, every verifier made keeps what it
// solves there, and solves with the memo's options.
void attachPlanVerifier(PlannerParameters& p, const Scenario& sc, const InterpolatorOptions& options);
void attachPlanVerifier(PlannerParameters& p, const Scenario& sc);
void attachPlanVerifier(PlannerParameters& p, const Scenario& sc, std::shared_ptr<TransitionMemo> memo);

}  // namespace acyclic
