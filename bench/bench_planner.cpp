// The contact planner with each of the paper's ideas switched off in turn,
// side by side in one run: wall time, nodes, posture calls and failures, plan
// length. Usage: bench_planner [SCENARIO] [OPTIONS]; --help lists the options.
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "cli_checks.h"

#include "planner/search/planner_parameters.h"
#include "planner/posture/heap_tuning.h"

using namespace acyclic;

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  std::string path = ACYCLIC_SOURCE_DIR "/models/scenarios/chair_table.yaml";
  double max_seconds = -1;  // not given: the scenario's budget
  CLI::App app{"The contact planner with each of the paper's ideas switched off in turn, side by side in one run:\n"
               "wall time, nodes, posture calls and failures, plan length."};
  app.add_option("scenario", path, "scenario file (acyclic.scenario/1)")->capture_default_str();
  app.add_option("--max-seconds", max_seconds, "time budget per run, s (default: the scenario's)")
      ->check(acyclic::bench::positive());
  CLI11_PARSE(app, argc, argv);
  const Scenario sc = Scenario::load(path);
  struct Variant {
    const char* name;
    bool lazy, optimized, guide, memory;
  };
  const Variant variants[] = {{"full planner (lazy sons, optimized candidates, f_T)", true, true, true, true},
                              {"no failure memory", true, true, true, false},
                              {"eager sons", false, true, true, true},
                              {"random candidates", true, false, true, true},
                              {"distance to goal instead of f_T", true, true, false, true}};
  std::printf("scenario %s, budget per run: %s\n", sc.name.c_str(),
              max_seconds > 0 ? (std::to_string(max_seconds) + " s").c_str() : "the scenario's");
  std::printf("%-52s %-22s %9s %7s %9s %9s %10s %8s\n", "variant", "result", "seconds", "nodes", "calls", "failed",
              "remembered", "stances");
  for (const auto& v : variants) {
    PlannerParameters p = plannerParameters(sc);
    if (max_seconds > 0) p.max_seconds = max_seconds;
    p.lazy_sons = v.lazy;
    p.optimized_candidates = v.optimized;
    p.guide_potential = v.guide;
    p.failure_memory = v.memory;
    const PlanningResult r = ContactPlanner(sc, p).plan();
    std::printf("%-52s %-22s %9.2f %7ld %9ld %9ld %10ld %8zu\n", v.name, toString(r.status), r.stats.seconds,
                r.stats.nodes_generated, r.stats.posture_calls, r.stats.posture_failures, r.stats.pairs_remembered,
                r.plan.stances.size());
    std::fflush(stdout);
  }
  return 0;
}
