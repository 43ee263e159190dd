// The dynamics simulation's speed: simulated seconds per wall second (median
// over --runs runs) executing step_forward's, sit_down's and chair_feet's
// trajectories (planned here first, transitions verified, then interpolated
// with the scenarios' margins and time law; chair_feet's plan takes about
// 50 s) and any trajectory files given, with the verdict, the integrator's
// steps and mean step.
// Usage: bench_simulation [--trajectory T]... [--runs N]; --help lists the options.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_checks.h"

#include "hrp2_bridge/sim/dynamics_simulation.h"
#include "hrp2_bridge/trajectory_file.h"
#include "interpolator/interpolator.h"
#include "interpolator/plan_verifier.h"
#include "planner/search/planner_parameters.h"

using namespace acyclic;

namespace {

void run(const std::string& name, const Scenario& sc, const Trajectory& tr, int runs) {
  std::vector<double> speed;
  hrp2::SimulationReport r;
  for (int i = 0; i < runs; ++i) {
    r = hrp2::simulate(sc, tr, {});
    speed.push_back(r.motion_time / r.wall_time);
  }
  std::sort(speed.begin(), speed.end());
  std::printf("%-22s %8.2f %8.2f %8.2f %9.2f %9ld %9.3f  %s\n", name.c_str(), r.motion_time, r.wall_time,
              speed[speed.size() / 2], speed.front(), r.integrator_steps, 1e3 * r.mean_step, hrp2::toString(r.verdict));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  int runs = 3;
  CLI::App app{"The dynamics simulation's speed: simulated seconds per wall second (median over the runs) on\n"
               "step_forward's, sit_down's and chair_feet's trajectories (planned and interpolated first) and on each trajectory\n"
               "file given."};
  app.add_option("--trajectory", files, "also this trajectory file (its scenario from its 'scenario' field); repeatable");
  app.add_option("--runs", runs, "runs per trajectory (default 3)")->check(acyclic::bench::positive());
  CLI11_PARSE(app, argc, argv);

  std::printf("%-22s %8s %8s %8s %9s %9s %9s  %s\n", "trajectory", "sim s", "wall s", "sim/wall", "min", "steps",
              "mean ms", "verdict");
  for (const char* name : {"step_forward", "sit_down", "chair_feet"}) {
    const Scenario sc = Scenario::load(std::string(ACYCLIC_SOURCE_DIR "/models/scenarios/") + name + ".yaml");
    // Transitions verified as acyclic-planner does by default: the search
    // alone gives chair_feet a plan with a transition that cannot be made.
    PlannerParameters params = plannerParameters(sc);
    params.verify_transitions = true;
    attachPlanVerifier(params, sc);
    const PlanningResult p = ContactPlanner(sc, params).plan();
    if (!p.solved()) {
      std::printf("bench_simulation: %s not planned: %s\n", name, p.reason.c_str());
      return 1;
    }
    const InterpolationResult t = interpolate(p.plan, sc, withScenarioMargins(sc, {}));
    if (!t.success()) {
      std::printf("bench_simulation: %s not interpolated: %s\n", name, t.reason.c_str());
      return 1;
    }
    run(name, sc, t.trajectory, runs);
  }
  for (const auto& f : files) {
    const hrp2::LoadedTrajectory l = hrp2::loadTrajectoryFile(f);
    run(l.scenario.name, l.scenario, l.trajectory, runs);
  }
  return 0;
}
