#pragma once
// The `planner:` section of a scenario file: PlannerParameters by name.
#include <string>
#include <vector>

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

// Settings of the planner section given on a command line (`--set
// KEY=VALUE`): each VALUE read as YAML (0.1, true, convex, [0.1, 0.1, 0.35],
// a list of maps for `portfolio`), null (or ~) dropping the key so that its default
// applies. checkPlannerSettings reads each on its own, as the scenario's own
// keys are read: a setting that is not KEY=VALUE, names no planner key, or
// holds a bad value is a FormatError naming `origin` ("--set", or the plan
// file that recorded them) and the field. setPlannerKeys (which checks them
// first) puts them in the scenario's planner section, in order, as if its
// file said so: every reader of the section (the search, the verification
// of transitions, the interpolator's margins) sees them.
void checkPlannerSettings(const std::vector<std::string>& settings, const std::string& origin = "--set");
void setPlannerKeys(Scenario& sc, const std::vector<std::string>& settings, const std::string& origin = "--set");

}  // namespace acyclic
