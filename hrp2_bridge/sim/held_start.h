// A trajectory that holds a scenario's start posture and stance: what the
// dynamics simulation plays to ask whether the start itself stands (or sits)
// before any plan moves it. A start whose statics are marginal in the planner's
// rigid model can tip on the simulation's compliant contacts, and then every
// plan from it inherits that lean (docs/design.md section 12).
#pragma once

#include "planner/plan/trajectory.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

// The start configuration at rest for `seconds` (at least one period), sampled
// every `dt`, in one phase whose contacts are the start stance's.
// std::invalid_argument when seconds or dt is not positive and finite, or
// when that is over 2e7 samples.
Trajectory heldStart(const Scenario& sc, double seconds, double dt = 0.005);

}  // namespace acyclic::hrp2
