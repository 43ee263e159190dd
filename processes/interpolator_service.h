#pragma once
// The trajectory interpolator on LCM: ACYCLIC_PLAN in, ACYCLIC_TRAJECTORY out,
// with progress, status and cancellation (docs/design.md section 2).
#include <string>

#include "interpolator/interpolator.h"

namespace acyclic {

// Serves until SIGINT/SIGTERM. Returns the process's exit status.
int serveInterpolator(const std::string& lcm_url, const InterpolatorOptions& options);

}  // namespace acyclic
