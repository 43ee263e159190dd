#pragma once
// Transitions solved once, kept whole (their motion pieces), for one set of
// interpolator options: the plan verifier (plan_verifier.h) stores every
// transition it solves there, and interpolate() given the same memo takes a
// transition from it instead of solving it again. So a plan verified by the
// planner is interpolated in the same process without solving its
// transitions twice (acyclic-planner --trajectory).
//
// A transition's outcome depends only on the stances it reads and the
// options: the interpolator's result does not depend on which solver solved
// what before, nor on the number of threads (bench_interpolator checks it).
// Keyed by the stances' exact contents (transitionKey), a memo's outcome is
// the one solving it again would give, bit for bit. The options travel with
// the memo, so that nothing can look a transition up under other options.
//
// A memo can also be filled from elsewhere: the transitions another process
// solved (the planner's, sent on ACYCLIC_TRANSITIONS). Such a memo checks
// each outcome before it is used (check_on_use): it must join its stances'
// witnesses, hold only their contacts, and every sample its pieces make
// must pass the validity check; one that does not is solved instead.
#include <cstddef>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "interpolator/interpolator.h"

namespace acyclic {

class TransitionMemo {
 public:
  // `keep_motion`: keep each outcome's motion pieces (for interpolate());
  // without, only whether it was made and why not (what a verifier alone
  // needs: a search that verifies on expansion solves thousands).
  // `check_on_use`: its outcomes come from elsewhere, and interpolate()
  // checks each before using it (TransitionSolver::check).
  explicit TransitionMemo(InterpolatorOptions options, bool keep_motion = true, bool check_on_use = false)
      : options_(std::move(options)), keep_motion_(keep_motion), check_on_use_(check_on_use) {}
  bool keepsMotion() const { return keep_motion_; }
  bool checksOnUse() const { return check_on_use_; }
  // The options every transition here was solved with.
  const InterpolatorOptions& options() const { return options_; }
  // Thread-safe: a portfolio's members verify at once.
  std::optional<TransitionOutcome> find(const std::string& key) const;
  // A cancelled solve is not an outcome: not stored.
  void store(const std::string& key, const TransitionOutcome& outcome);
  std::size_t size() const;

 private:
  const InterpolatorOptions options_;
  const bool keep_motion_;
  const bool check_on_use_;
  mutable std::mutex mutex_;
  std::map<std::string, TransitionOutcome> known_;
};

// The exact contents of the stances transition `d` of `plan` reads (its
// kind, and from its first stance to its last each witness's coordinates
// and contacts, bit for bit): its key in a memo.
std::string transitionKey(const Plan& plan, const TransitionDesign& d);

// The options a transition's outcome depends on, as text, every number to
// the bit: all of InterpolatorOptions but the thread count and the stance
// filter (which choose what is solved, not how). Outcomes solved elsewhere
// are used only under options with the same text. A field added to
// InterpolatorOptions that changes outcomes must be added here
// (test_interpolator checks every field).
std::string outcomeOptionsText(const InterpolatorOptions& o);

// A transition of a plan and the memo's outcome for it.
struct RememberedTransition {
  TransitionDesign design;
  TransitionOutcome outcome;
};

// The transitions of `plan`, every stance kept (as the plan verifier
// designs them), that the memo holds solved, in the plan's order: what the
// planner sends the interpolator (ACYCLIC_TRANSITIONS).
std::vector<RememberedTransition> rememberedTransitions(const Plan& plan, const TransitionMemo& memo);

}  // namespace acyclic
