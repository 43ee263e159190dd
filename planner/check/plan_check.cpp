#include "planner/check/plan_check.h"

#include <cmath>

namespace acyclic {

bool PlanReport::valid() const {
  for (const auto& s : stances)
    if (!s.valid()) return false;
  return sequence_violations.empty();
}

PlanReport checkPlan(const Plan& plan, const Scenario& sc, ValidityChecker& checker) {
  PlanReport rep;
  for (const auto& s : plan.stances) rep.stances.push_back(checker.checkPosture(s.configuration, s.specs()));
  if (plan.stances.empty()) {
    rep.sequence_violations.push_back("the plan has no stance");
    return rep;
  }
  // The first stance is the scenario's start stance: the same contacts, placed and supporting alike.
  const StanceDiff first = diffStances(sc.start_stance, plan.stances.front().specs());
  if (first.changes() != 0)
    rep.sequence_violations.push_back("the first stance is not the scenario's start stance (" +
                                      std::to_string(first.added) + " contacts added, " + std::to_string(first.removed) +
                                      " missing, " + std::to_string(first.flipped) + " with another support)");
  Kinematics k(sc.robot);
  k.setConfiguration(plan.stances.back().configuration);
  if (!sc.goal.satisfied(k, plan.stances.back().specs()))
    rep.sequence_violations.push_back("the last stance does not meet the goal (" + sc.goal.describe(*sc.robot) + ")");
  for (std::size_t i = 1; i < plan.stances.size(); ++i) {
    const std::string why = checkStep(plan.stances[i - 1], plan.stances[i], sc);
    if (!why.empty())
      rep.sequence_violations.push_back("stances " + std::to_string(i - 1) + " -> " + std::to_string(i) + ": " + why);
  }
  return rep;
}

}  // namespace acyclic
