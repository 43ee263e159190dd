// The OMPL guide author: its time on each scenario (median over seeds), then
// each scenario planned with the hand-written key postures and with the OMPL
// guide only, side by side in one run: wall time, nodes, plan length, and the
// independent check's verdict on each plan (planner/check/plan_check.h).
// With --verify-transitions the plans are verified as acyclic-planner does;
// --max-nodes and --max-posture-calls widen the scenarios' budgets (the
// OMPL guide may need more than the hand-written one).
// Usage: bench_guide [SCENARIO...] [OPTIONS]; --help lists the options.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "scenario_runs.h"

#include "planner/guide/guide_author.h"
#include "planner/posture/heap_tuning.h"

using namespace acyclic;

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  std::vector<std::string> paths;
  int seeds = 5;
  bench::PlannerOverrides overrides;
  CLI::App app{"The OMPL guide author: its time on each scenario (median over seeds), then each scenario planned\n"
               "with the hand-written key postures and with the OMPL guide only, side by side in one run: wall time,\n"
               "nodes, plan length, and the independent check's verdict on each plan."};
  app.add_option("scenario", paths, "scenario files (acyclic.scenario/1; default: every models/scenarios/*.yaml)");
  app.add_option("--seeds", seeds, "the guide author is timed with seeds 1..N (median and max printed)")
      ->check(acyclic::bench::positive())
      ->capture_default_str();
  overrides.addOptions(app, "planning run");
  bool ompl_only = false;
  app.add_flag("--ompl-only", ompl_only, "plan with the OMPL guide only, not also with the hand-written key postures");
  CLI11_PARSE(app, argc, argv);
  if (paths.empty()) paths = bench::shippedScenarios();
  if (!overrides.acceptedBy(paths, "bench_guide")) return 2;
  std::printf("%-14s %-18s %12s %12s %8s\n", "scenario", "guide", "median s", "max s", "keys");
  std::vector<Guide> guides;
  for (const auto& path : paths) {
    const Scenario sc = Scenario::load(path);
    std::vector<double> t;
    GuideResult first;
    for (int s = 1; s <= seeds; ++s) {
      GuideOptions o;
      o.seed = static_cast<unsigned>(s);
      const GuideResult r = authorGuide(sc, o);
      if (s == static_cast<int>(sc.seed) || s == 1) first = r;
      t.push_back(r.success() ? r.guide.seconds : r.goal_seconds + r.path_seconds);
      if (!r.success()) std::printf("  seed %d: %s: %s\n", s, toString(r.status), r.reason.c_str());
    }
    std::sort(t.begin(), t.end());
    std::printf("%-14s %-18s %12.3f %12.3f %8zu\n", sc.name.c_str(), toString(first.status), t[t.size() / 2],
                t.back(), first.guide.key_postures.size());
    guides.push_back(first.guide);
  }
  std::printf("\n%-14s %-12s %-22s %9s %7s %9s %8s %s\n", "scenario", "guide", "result", "seconds", "nodes", "calls",
              "stances", "check");
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const Scenario base = Scenario::load(paths[i]);
    for (const bool ompl : {false, true}) {
      if (ompl_only && !ompl) continue;
      Scenario sc = base;
      if (ompl) sc.key_postures = guides[i].key_postures;
      if (sc.key_postures.size() < 2) {
        std::printf("%-14s %-12s %-22s\n", sc.name.c_str(), ompl ? "OMPL" : "hand", "no key postures");
        continue;
      }
      const PlanningResult r = ContactPlanner(sc, overrides.parameters(sc)).plan();
      const std::string verdict = bench::planVerdict(r, sc);
      std::printf("%-14s %-12s %-22s %9.2f %7ld %9ld %8zu %s\n", sc.name.c_str(), ompl ? "OMPL" : "hand",
                  toString(r.status), r.stats.seconds, r.stats.nodes_generated, r.stats.posture_calls,
                  r.plan.stances.size(), verdict.c_str());
      bench::printVerification(r);
      std::fflush(stdout);
    }
  }
  return 0;
}
