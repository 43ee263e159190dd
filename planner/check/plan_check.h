#pragma once
// The validity contract for a whole plan (DESIGN.md section 9): every stance's
// witness posture, the first stance is the scenario's start stance, the last
// meets the goal, consecutive stances differ by one contact.
#include <string>
#include <vector>

#include "planner/check/validity.h"
#include "planner/plan/plan.h"

namespace acyclic {

struct PlanReport {
  std::vector<ValidityReport> stances;
  std::vector<std::string> sequence_violations;
  bool valid() const;
};

PlanReport checkPlan(const Plan& plan, const Scenario& sc, ValidityChecker& checker);

}  // namespace acyclic
