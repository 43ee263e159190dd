#pragma once
// ACYCLIC_TRANSITIONS (transitions_t): the transitions the planner's
// verification solved for a plan, sent with it so that the interpolator does
// not solve them again (docs/design.md section 2). Built only with the
// interpolator library.
#include <vector>

#include "acyclic/plan_t.hpp"
#include "acyclic/transitions_t.hpp"
#include "interpolator/transition_memo.h"

namespace acyclic::convert {

// The transitions and the options they were solved with; utime and
// request_id are the caller's. Knots go as the solver made them (their
// quaternions not normalized again), so that a trajectory made of them is
// the one the interpolator would solve, bit for bit.
transitions_t toMessage(const std::vector<RememberedTransition>& transitions, const InterpolatorOptions& options,
                        const Scenario& sc);

// The message's transitions into `memo`, each keyed against `plan` (the plan
// of the same request) by its stances. Throws FormatError naming the field
// for a transition whose stances are not the plan's, or a name or knot the
// scenario's robot and scene do not know. Returns how many were stored.
std::size_t fillMemo(const transitions_t& m, const Plan& plan, const Scenario& sc, TransitionMemo& memo);

// The transitions of the plan message `sent` that the memo holds, keyed as
// the interpolator will key them in the plan it reads from that message. A
// transition whose stances changed on the way (a quaternion normalized
// again) is left out: its outcome was solved for other bits.
std::vector<RememberedTransition> transitionsToSend(const plan_t& sent, const Scenario& sc, const TransitionMemo& memo);

}  // namespace acyclic::convert
