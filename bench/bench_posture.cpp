// The posture generator on a fixed, seeded set of problems from the chair
// scene (random contact subsets, start guesses, floating contacts; some
// infeasible): success rate, time per call for successes and for failures,
// iterations, and how many successes the independent check accepts.
// Usage: bench_posture --help.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>

#include <CLI/CLI.hpp>

#include "cli_checks.h"
#include "posture_problems.h"

#include "planner/check/validity.h"
#include "planner/posture/heap_tuning.h"
#include "planner/posture/posture_generator.h"

using namespace acyclic;
using acyclic::bench::Problem;
using acyclic::bench::makeProblems;

namespace {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  int n = 100;
  unsigned seed = 1;
  PostureGeneratorOptions opt;
  CLI::App app{"The posture generator on a fixed, seeded set of problems from the chair scene (random contact\n"
               "subsets, start guesses, floating contacts; some infeasible): success rate, time per call for\n"
               "successes and for failures (median, 90th percentile), iterations, and how many successes the\n"
               "independent check accepts."};
  app.add_option("--problems", n, "number of problems")->check(acyclic::bench::positive())->capture_default_str();
  app.add_option("--seed", seed, "seed of the problem set")->capture_default_str();
  app.add_option("--max-seconds", opt.max_seconds, "CPU time limit per call, s")->capture_default_str();
  app.add_option("--max-iterations", opt.max_iterations, "iteration limit per call")->capture_default_str();
  app.add_option("--cutoff", opt.problem.collision_cutoff, "collision pairs farther than this at the start are left out, m")
      ->capture_default_str();
  app.add_option("--hessian", opt.hessian, "lbfgs, analytic or diagonal")->capture_default_str();
  app.add_option("--linear-solver", opt.linear_solver, "ldl or mumps")->capture_default_str();
  app.add_option("--lbfgs-rows", opt.lbfgs_in_kkt, "L-BFGS's low-rank part as rows of the KKT system (else Sherman-Morrison)")
      ->capture_default_str();
  app.add_option("--stop-at-restoration", opt.stop_at_restoration,
                 "give up when Ipopt enters its restoration phase (the planner's setting)")
      ->capture_default_str();
  app.add_option("--mu-oracle", opt.mu_oracle, "Ipopt's barrier-parameter oracle: quality-function, probing or loqo")
      ->capture_default_str();
  std::string engine = "convex";
  app.add_option("--distance-engine", engine, "pair distances: convex (GJK on the primitives' cores) or fcl")
      ->check([](const std::string& v) { return distanceEngineNamed(v) ? std::string() : "expected convex or fcl"; })
      ->capture_default_str();
  app.add_option("--ipopt", opt.ipopt_options, "further Ipopt option name=value (repeatable)");
  CLI11_PARSE(app, argc, argv);
  opt.distance_engine = *distanceEngineNamed(engine);
  const Scenario sc = Scenario::load(ACYCLIC_SOURCE_DIR "/models/scenarios/chair_table.yaml");
  std::unique_ptr<PostureGenerator> made;
  try {
    made = std::make_unique<PostureGenerator>(sc.robot, sc.scene, opt);
  } catch (const std::invalid_argument& e) {  // a bad option: said, not aborted on
    std::fprintf(stderr, "bench_posture: %s\n", e.what());
    return 2;
  }
  PostureGenerator& pg = *made;
  ValidityChecker checker(sc.robot, sc.scene);
  const auto problems = makeProblems(sc, n, seed);

  std::vector<double> t_ok, t_fail, it_ok, it_fail;
  int checked_ok = 0, by_status[5] = {0, 0, 0, 0, 0};
  for (const auto& p : problems) {
    const PostureResult r = pg.solve(p.request);
    ++by_status[static_cast<int>(r.status)];
    if (r.success()) {
      t_ok.push_back(r.seconds * 1e3);
      it_ok.push_back(r.iterations);
      std::vector<ContactSpec> stance = p.stance;
      if (p.request.floating) {
        ContactSpec c;
        c.spot = p.request.floating->spot;
        c.surface = p.request.floating->surface;
        c.supporting = false;
        c.placement = r.floating;
        stance.push_back(c);
      }
      const ValidityReport rep = checker.checkPosture(r.configuration, stance);
      if (rep.valid()) {
        ++checked_ok;
      } else {
        for (const auto& part : rep.parts)
          if (!part.ok()) std::printf("  check refuses a success (%s): %s\n", p.label.c_str(), part.violations[0].c_str());
      }
    } else {
      t_fail.push_back(r.seconds * 1e3);
      it_fail.push_back(r.iterations);
    }
  }
  std::printf("posture generator, %d seeded problems from the chair scene (seed %u)\n", n, seed);
  std::printf("  success %zu (%.0f%%); failures: infeasible %d, iteration limit %d, time limit %d, bad input %d\n",
              t_ok.size(), 100.0 * t_ok.size() / n, by_status[1], by_status[2], by_status[3], by_status[4]);
  std::printf("  successes: median %.1f ms, p90 %.1f ms, median %.0f iterations\n", percentile(t_ok, 0.5),
              percentile(t_ok, 0.9), percentile(it_ok, 0.5));
  std::printf("  failures:  median %.1f ms, p90 %.1f ms, median %.0f iterations\n", percentile(t_fail, 0.5),
              percentile(t_fail, 0.9), percentile(it_fail, 0.5));
  std::printf("  independent check (limits, contacts, collisions, quasi-static LP): %d of %zu successes valid\n",
              checked_ok, t_ok.size());
  return checked_ok == static_cast<int>(t_ok.size()) ? 0 : 1;
}
