#pragma once
// The trajectory interpolator on LCM: ACYCLIC_PLAN in, ACYCLIC_TRAJECTORY out,
// with progress, status and cancellation (docs/design.md section 2).
#include <functional>
#include <string>

#include "interpolator/interpolator.h"

namespace acyclic {

// The options for a plan of this scenario (the command line's, with the
// scenario's stability margins where the command line gives none).
using InterpolatorOptionsFor = std::function<InterpolatorOptions(const Scenario&)>;

// Serves until SIGINT/SIGTERM. Returns the process's exit status.
// `planner_transitions`: take the planner's ACYCLIC_TRANSITIONS (checked)
// instead of solving them; off, every transition is solved here.
int serveInterpolator(const std::string& lcm_url, const InterpolatorOptionsFor& options,
                      bool planner_transitions = true);

}  // namespace acyclic
