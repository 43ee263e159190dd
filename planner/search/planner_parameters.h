#pragma once
// The `planner:` section of a scenario file: PlannerParameters by name.
#include "planner/search/contact_planner.h"

namespace acyclic {

// Defaults, overridden by the scenario's planner section (FormatError naming
// the file and field on a bad value or an unknown name).
PlannerParameters plannerParameters(const Scenario& sc);

}  // namespace acyclic
