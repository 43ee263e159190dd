#include "planner/search/refused_plans.h"

#include <stdexcept>

namespace acyclic {

Plan planPiece(const Plan& plan, int from, int to) {
  if (from < 0 || to < from || to >= static_cast<int>(plan.stances.size()))
    throw std::invalid_argument("planPiece: stances " + std::to_string(from) + ".." + std::to_string(to) +
                                " of a plan of " + std::to_string(plan.stances.size()));
  Plan piece = plan;
  piece.stances.assign(plan.stances.begin() + from, plan.stances.begin() + to + 1);
  return piece;
}

std::vector<std::string> writeRefusedPlans(const PlanningResult& r, const Scenario& sc, const std::string& dir) {
  std::vector<std::string> written;
  for (std::size_t i = 0; i < r.refused_plans.size(); ++i) {
    const RefusedPlan& rp = r.refused_plans[i];
    const std::string stem = dir + "/refused_" + std::to_string(i + 1);
    writePlan(rp.plan, sc, stem + ".plan.json");
    written.push_back(stem + ".plan.json");
    const std::string piece = stem + "_stances_" + std::to_string(rp.failed_from) + "-" +
                              std::to_string(rp.failed_to) + ".plan.json";
    writePlan(planPiece(rp.plan, rp.failed_from, rp.failed_to), sc, piece);
    written.push_back(piece);
  }
  return written;
}

}  // namespace acyclic
