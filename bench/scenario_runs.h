#pragma once
// What bench_scenarios and bench_guide share when they plan shipped
// scenarios: the default list of scenarios, the planner's budgets and
// verification from the command line, the independent check's verdict on a
// plan, and the verification's line under a row.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_checks.h"

#ifdef ACYCLIC_HAVE_INTERPOLATOR
#include "interpolator/plan_verifier.h"
#endif
#include "planner/check/plan_check.h"
#include "planner/search/planner_parameters.h"

namespace acyclic::bench {

// Every scenario shipped in models/scenarios, in name order.
inline std::vector<std::string> shippedScenarios() {
  std::vector<std::string> paths;
  for (const auto& e : std::filesystem::directory_iterator(ACYCLIC_SOURCE_DIR "/models/scenarios"))
    if (e.path().extension() == ".yaml") paths.push_back(e.path().string());
  std::sort(paths.begin(), paths.end());
  return paths;
}

// The command line's changes to each scenario's planner parameters.
struct PlannerOverrides {
  double max_seconds = -1;  // not given (<= 0): the scenario's
  long max_nodes = -1;
  long max_posture_calls = -1;
  bool verify = false;  // verify transitions (the planner's default in acyclic-planner)
  std::string member;   // of the scenario's portfolio, alone (empty: the whole portfolio)
  std::vector<std::string> set;  // KEY=VALUE settings of the planner section (setPlannerKeys)

  // --max-seconds, --max-nodes, --max-posture-calls (each per `per`),
  // --set, --member, and --verify-transitions where the interpolator is built.
  void addOptions(CLI::App& app, const std::string& per) {
    app.add_option("--max-seconds", max_seconds, "time budget per " + per + ", s (default: the scenario's)")
        ->check(positive());
    app.add_option("--max-nodes", max_nodes, "nodes generated at most per " + per + " (default: the scenario's)")
        ->check(positive());
    app.add_option("--max-posture-calls", max_posture_calls,
                   "posture-generator calls at most per " + per + " (default: the scenario's)")
        ->check(positive());
    app.add_option("--set", set,
                   "a key of each scenario's planner section, as if its file said so (repeatable; VALUE read as "
                   "YAML, null for the key's default), before --member, as acyclic-planner --set")
        ->type_name("KEY=VALUE");
    app.add_option("--member", member,
                   "of the scenario's portfolio (planner: portfolio), plan with this member alone, by name, as "
                   "acyclic-planner --member (default: the whole portfolio)");
#ifdef ACYCLIC_HAVE_INTERPOLATOR
    app.add_flag("--verify-transitions", verify,
                 "verify each plan's transitions with the interpolator's solver, as acyclic-planner does by default "
                 "(default here: the search alone, or the scenario's planner key verify_transitions)");
#endif
  }

  // Whether every scenario loads and takes these changes (an unknown
  // --member, a bad scenario): false, with the reason on stderr, if not.
  bool acceptedBy(const std::vector<std::string>& paths, const char* bench) const {
    try {
      for (const auto& path : paths) settings(Scenario::load(path));
      return true;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s\n", bench, e.what());
      return false;
    }
  }

  // The scenario with --set's keys in its planner section.
  Scenario withSet(const Scenario& sc) const {
    Scenario s = sc;
    setPlannerKeys(s, set);
    return s;
  }

  // The scenario's parameters with these changes, without a verifier.
  PlannerParameters settings(const Scenario& sc) const { return settingsOf(withSet(sc)); }

  // settings(), and a verifier when they verify transitions.
  PlannerParameters parameters(const Scenario& sc) const {
    const Scenario set = withSet(sc);
    PlannerParameters p = settingsOf(set);
#ifdef ACYCLIC_HAVE_INTERPOLATOR
    attachPlanVerifier(p, set);  // its margins and oracle as --set gives them
#endif
    return p;
  }

 private:
  // settings() of a scenario that already has --set's keys.
  PlannerParameters settingsOf(const Scenario& sc) const {
    PlannerParameters p = plannerParameters(sc);
    if (max_seconds > 0) p.max_seconds = max_seconds;
    if (max_nodes > 0) p.max_nodes = max_nodes;
    if (max_posture_calls > 0) p.max_posture_calls = max_posture_calls;
    if (verify) p.verify_transitions = true;
    if (!member.empty()) keepPortfolioMember(p, member, sc.path);
    return p;
  }
};

// The independent check's verdict on a result's plan: valid, INVALID, or -
// when there is no plan.
inline std::string planVerdict(const PlanningResult& r, const Scenario& sc) {
  if (!r.solved()) return "-";
  ValidityChecker checker(sc.robot, sc.scene);
  return checkPlan(r.plan, sc, checker).valid() ? "valid" : "INVALID";
}

// Under a row: what the verification of transitions did, if it ran.
inline void printVerification(const PlanningResult& r) {
  if (r.stats.plans_verified == 0) return;
  std::printf("%-14s   transitions verified: %ld plans, %ld refused, %ld transitions solved, %.2f s of the %.2f s\n", "",
              r.stats.plans_verified, r.stats.plans_refused, r.stats.transitions_solved, r.stats.verify_seconds,
              r.stats.seconds);
}

}  // namespace acyclic::bench
