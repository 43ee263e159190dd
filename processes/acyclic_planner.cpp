// acyclic-planner: plans a scenario's contacts (file mode) and writes an
// acyclic.plan/1 file. Progress goes to stderr on a terminal, nothing when not.
// Exit status: 0 solved, 1 not solved (the reason is printed), 2 bad input.
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <unistd.h>

#include "planner/common/format_error.h"
#include "planner/search/planner_parameters.h"

namespace {
std::atomic<bool> g_cancel{false};
void onSignal(int) { g_cancel = true; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Plans the contacts of a scenario (Escande et al., ISER 2008): best-first search over sets of\n"
               "contacts driven by the guide potential of the scenario's key postures. Writes acyclic.plan/1.\n"
               "Exit status: 0 solved, 1 not solved (reason printed), 2 bad input."};
  std::string in, out;
  long seed = -1;
  double max_seconds = -1;
  long max_nodes = -1, max_calls = -1;
  bool eager = false, random_candidates = false, goal_distance = false, quiet = false;
  app.add_option("--in", in, "scenario file (acyclic.scenario/1)")->required();
  app.add_option("--out", out, "plan file to write (acyclic.plan/1)")->required();
  app.add_option("--seed", seed, "overrides the scenario's seed");
  app.add_option("--max-seconds", max_seconds, "wall-time budget (default: the scenario's planner section, else 60)");
  app.add_option("--max-nodes", max_nodes, "nodes generated at most (default: scenario, else 1000)");
  app.add_option("--max-posture-calls", max_calls, "posture-generator calls at most (default: scenario, else 20000)");
  app.add_flag("--eager-sons", eager, "ablation: every son of a node at once instead of lazy sons (paper 2.8)");
  app.add_flag("--random-candidates", random_candidates,
               "ablation: random (x, y, theta) samples instead of optimized candidates (paper 2.6)");
  app.add_flag("--distance-to-goal", goal_distance, "ablation: distance to the goal instead of the guide potential");
  app.add_flag("-q,--quiet", quiet, "no progress, even on a terminal");
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  try {
    acyclic::Scenario sc = acyclic::Scenario::load(in);
    if (seed >= 0) sc.seed = static_cast<std::uint64_t>(seed);
    acyclic::PlannerParameters p = acyclic::plannerParameters(sc);
    if (max_seconds > 0) p.max_seconds = max_seconds;
    if (max_nodes > 0) p.max_nodes = max_nodes;
    if (max_calls > 0) p.max_posture_calls = max_calls;
    p.lazy_sons = !eager;
    p.optimized_candidates = !random_candidates;
    p.guide_potential = !goal_distance;
    acyclic::ContactPlanner planner(sc, p);
    const bool tty = !quiet && isatty(STDERR_FILENO);
    auto progress = [&](const acyclic::PlanningStats& s) {
      if (!tty) return;
      std::fprintf(stderr, "\r%7.1f s  nodes %ld (expanded %ld)  posture calls %ld (failed %ld)  best f_T %.3f   ",
                   s.seconds, s.nodes_generated, s.nodes_expanded, s.posture_calls, s.posture_failures,
                   s.best_potential);
    };
    const acyclic::PlanningResult r = planner.plan(&g_cancel, progress);
    if (tty) std::fprintf(stderr, "\n");
    const auto& s = r.stats;
    std::printf("acyclic-planner: %s: %s in %.2f s; %ld nodes generated, %ld expanded, %ld posture calls (%ld failed)\n",
                sc.name.c_str(), acyclic::toString(r.status), s.seconds, s.nodes_generated, s.nodes_expanded,
                s.posture_calls, s.posture_failures);
    if (!r.solved()) {
      std::printf("acyclic-planner: no plan: %s\n", r.reason.c_str());
      return 1;
    }
    acyclic::writePlan(r.plan, sc, out);
    std::printf("acyclic-planner: %zu stances written to %s\n", r.plan.stances.size(), out.c_str());
    return 0;
  } catch (const acyclic::FormatError& e) {
    std::fprintf(stderr, "acyclic-planner: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-planner: error: %s\n", e.what());
    return 2;
  }
}
