#pragma once
// The `planner:` section of a scenario file: PlannerParameters by name.
#include "planner/search/contact_planner.h"

namespace acyclic {

// Defaults, overridden by the scenario's planner section (FormatError naming
// the file and field on a bad value or an unknown name).
PlannerParameters plannerParameters(const Scenario& sc);

// p's portfolio member of that name applied to p, and the portfolio
// dropped: that member planned alone, on all of p's threads
// (std::invalid_argument naming `scenario`, the option and the members when
// there is no such one).
void keepPortfolioMember(PlannerParameters& p, const std::string& name, const std::string& scenario);

}  // namespace acyclic
