#pragma once
// The plans the verification of transitions refused, written out so that a
// refusal can be reproduced (acyclic-planner --keep-refused DIR): each whole
// plan as the search found it, and the piece that fails, its stances A..B,
// ready for `acyclic-interpolator --no-filter --in` (which prints the whole
// reason; the planner's line cuts it at 300 characters). Without them only
// the first refused plan could be had again (--no-verify-transitions
// returns it); the later ones depend on every refusal before them.
#include <string>
#include <vector>

#include "planner/search/contact_planner.h"

namespace acyclic {

// For refused plan i (1-based) of r.refused_plans: DIR/refused_<i>.plan.json
// and DIR/refused_<i>_stances_<A>-<B>.plan.json. Returns the paths written,
// in that order; throws std::runtime_error naming a file it cannot write.
std::vector<std::string> writeRefusedPlans(const PlanningResult& r, const Scenario& sc, const std::string& dir);

// Stances from..to of a plan (inclusive), with its scenario, robot and stats.
Plan planPiece(const Plan& plan, int from, int to);

}  // namespace acyclic
