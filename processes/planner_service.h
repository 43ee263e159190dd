#pragma once
// The contact planner on LCM: ACYCLIC_REQUEST in, ACYCLIC_PLAN out, with
// progress, status and cancellation (docs/design.md section 2).
#include <memory>
#include <string>
#include <vector>

#include "planner/search/contact_planner.h"

namespace acyclic {

class TransitionMemo;  // interpolator/transition_memo.h

// Command-line overrides of a scenario's planner parameters (both modes).
struct PlannerOverrides {
  long seed = -1;
  double max_seconds = -1;
  long max_nodes = -1, max_posture_calls = -1;
  int threads = -1;
  bool eager_sons = false, random_candidates = false, distance_to_goal = false, no_failure_memory = false, no_swing_check = false;
  int verify_transitions = -1;  // -1: the scenario's (planner: verify_transitions), 0 off, 1 on
  int verify_on_expansion = -1;  // -1: the scenario's (planner: verify_on_expansion), 0 off, 1 on
  bool verbose = false;  // one line per expanded node on stderr
  std::string member;    // of the scenario's portfolio, planned alone (empty: the whole portfolio)
  // KEY=VALUE settings of the scenario's planner section (setPlannerKeys),
  // applied before everything above.
  std::vector<std::string> set;
  // The scenario's parameters with these overrides; a request's time budget
  // (> 0) applies unless --max-seconds is given. Also sets sc.seed. With
  // verify_transitions, the interpolator's verifier (built only with it).
  // `memo` (file mode's --trajectory): given, a memo of the interpolator's
  // options for this scenario (withScenarioMargins) is made there, keeping
  // motion, and the verification keeps every transition it solves in it, so
  // that interpolate(plan, sc, *memo) solves none of them again.
  PlannerParameters apply(Scenario& sc, double request_budget_s,
                          std::shared_ptr<TransitionMemo>* memo = nullptr) const;
};

// Serves until SIGINT/SIGTERM. Returns the process's exit status.
int servePlanner(const std::string& lcm_url, const PlannerOverrides& overrides);

}  // namespace acyclic
