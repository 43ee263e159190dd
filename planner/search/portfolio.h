#pragma once
// The contact planner's portfolio (PlannerParameters::portfolio): one search
// per member, each on its own thread, and the plan of the member that solved
// in the fewest nodes. Private to the planner (contact_planner.cpp).
//
// Why the winner does not depend on timing: a member i that solves with n_i
// nodes lowers every other member j's cap to n_i (j listed before i, which
// wins a tie) or n_i - 1 (j after). A search checks its cap only at the top
// of its loop, where alone it would check its goal, so up to its cap each
// member makes exactly the search it makes alone. A member is stopped only
// past a count at which another has already solved, so it cannot have been
// the winner; the winner is never stopped (its own count never passes a cap
// set by a worse member).
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "planner/search/contact_planner.h"

namespace acyclic {

struct ContactPlanner::Portfolio {
  std::vector<std::string> names;
  std::vector<std::unique_ptr<ContactPlanner>> members;
  Portfolio(const Scenario& scenario, const PlannerParameters& params);
  PlanningResult plan(const std::atomic<bool>* cancel, const Progress& progress);
};

}  // namespace acyclic
