#pragma once
// The validity contract for a whole plan (docs/design.md section 9): every stance's
// witness posture, the first stance is the scenario's start stance, the last
// meets the goal, consecutive stances differ by one contact. The contact
// forces a plan reports, where it reports them, are checked on their own
// (checkReportedForces).
#include <string>
#include <vector>

#include "planner/check/validity.h"
#include "planner/plan/plan.h"

namespace acyclic {

struct PlanReport {
  std::vector<ValidityReport> stances;
  std::vector<std::string> sequence_violations;
  // The worst ||f_t|| / (mu f_n) of the forces the plan reports, and its stance (-1: none reported).
  double worst_cone_ratio = 0;
  int worst_cone_stance = -1;
  bool valid() const;
};

// Each stance's report has the contract's parts (validity.h) and "reported
// forces".
PlanReport checkPlan(const Plan& plan, const Scenario& sc, ValidityChecker& checker);

// The forces a stance reports, as a robot's controller would use them: on
// the corners of each supporting contact's spot (within 2 mm), each inside
// the true Coulomb cone (||f_t|| <= mu f_n, slack 1e-6 relative and 1e-6 of the
// weight), together
// balancing gravity (force and moment about the centre of mass, 1e-6 of the
// weight and of the weight times a metre). Not checked (the part's `checked`
// false) when the stance reports no force at all.
// `worst`, if given, receives the worst ratio ||f_t|| / (mu f_n).
CheckPart checkReportedForces(const PlanStance& stance, const Scenario& sc, Kinematics& kin, double* worst = nullptr);

}  // namespace acyclic
