// The trajectory interpolator on a plan: wall time (and its share in the
// posture generator), posture calls, repairs, filtered stances, samples, for
// n = 10 and 20 steps, with every sample verified (the default) and without
// (knots and segment middles only: what the verification costs), on one
// thread and on two (whether both give the same trajectory is printed), and
// on one thread with the repairs in their fixed order instead of the one a
// first failure names (InterpolatorOptions::order_by_failure: the ratio of
// wall times, and whether the trajectory is the same); then the independent
// trajectory check of the default n = 20 run. Each run starts from the
// options acyclic-interpolator gives the plan: the scenario's margins and
// knots' barrier oracle (withScenarioMargins), after the planner settings
// the plan file recorded; before, chair_paper's plan was benchmarked
// without them and its transition 66 -> 67 failed. Last, the default run's
// transitions interpolated again as the interpolator over LCM takes the
// planner's (ACYCLIC_TRANSITIONS: a memo from elsewhere, each transition
// checked before use): its wall time against solving them, and whether the
// trajectory is the same. Figures in docs/figures.md.
// Usage: bench_interpolator [PLAN.json [SCENARIO]] [OPTIONS]; --help lists the options.
//   Without a plan: plans models/scenarios/step_forward.yaml first. The
//   scenario defaults to the plan's "scenario" field (relative to the plan's
//   folder, the current directory or the source tree).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_checks.h"

#include "interpolator/interpolator.h"
#include "interpolator/transition_memo.h"
#include "planner/posture/heap_tuning.h"
#include "planner/check/trajectory_check.h"
#include "planner/common/format_error.h"
#include "planner/plan/scenario_reference.h"
#include "planner/search/planner_parameters.h"

using namespace acyclic;

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  // Positional: plan, scenario; --ipopt name=value (repeatable) and --cutoff M for tuning.
  std::vector<std::string> ipopt;
  double cutoff = InterpolatorOptions{}.collision_cutoff;
  std::string plan_path, scenario_path;
  CLI::App app{"The trajectory interpolator on a plan: wall time (and its share in the posture generator), posture\n"
               "calls, repairs, filtered stances, samples, for n = 10 and 20 steps, with every sample verified and\n"
               "without, on one thread and on two, and on one thread with the repairs in their fixed order; then the\n"
               "independent trajectory check of the default n = 20 run."};
  app.add_option("plan", plan_path,
                 "plan file (acyclic.plan/1, JSON; default: plan models/scenarios/step_forward.yaml first)");
  app.add_option("scenario", scenario_path,
                 "scenario file (default: the plan's \"scenario\" field, relative to the plan's folder, the current "
                 "directory or the source tree)");
  app.add_option("--ipopt", ipopt, "further Ipopt option name=value for the posture generator (repeatable)")
      ->allow_extra_args(false);  // one value per --ipopt: a word after it is a positional
  app.add_option("--cutoff", cutoff, "collision pairs farther than this at the warm start are left out, m")
      ->check(acyclic::bench::nonNegative())
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  Plan plan;
  Scenario sc;
  if (plan_path.empty()) {
    sc = Scenario::load(ACYCLIC_SOURCE_DIR "/models/scenarios/step_forward.yaml");
    const PlanningResult r = ContactPlanner(sc, plannerParameters(sc)).plan();
    if (!r.solved()) {
      std::printf("bench_interpolator: the planner did not solve %s: %s\n", sc.name.c_str(), r.reason.c_str());
      return 1;
    }
    plan = r.plan;
    plan_path = "(planned: " + sc.path + ")";
  } else {
    if (scenario_path.empty()) {
      try {
        scenario_path = scenarioNamedBy(plan_path);
      } catch (const FormatError&) {
        // The bench also runs from its build folder: the source tree last.
        std::ifstream in(plan_path);
        scenario_path = std::string(ACYCLIC_SOURCE_DIR "/") + nlohmann::json::parse(in).at("scenario").get<std::string>();
      }
    }
    try {
      sc = Scenario::load(scenario_path);
      plan = readPlan(plan_path, sc);
    } catch (const FormatError& e) {
      std::fprintf(stderr, "bench_interpolator: %s\n", e.what());
      return 2;
    }
  }
  Scenario planned_with = sc;
  try {
    setPlannerKeys(planned_with, plan.planner_settings, plan_path + " (planner_settings)");
  } catch (const FormatError& e) {
    std::fprintf(stderr, "bench_interpolator: %s\n", e.what());
    return 2;
  }
  std::printf("plan %s: scenario %s, %zu stances\n", plan_path.c_str(), sc.name.c_str(), plan.stances.size());
  if (!plan.planner_settings.empty()) {
    std::string keys;
    for (const std::string& k : plan.planner_settings) keys += (keys.empty() ? "" : ", ") + k;
    std::printf("planned with --set %s: applied\n", keys.c_str());
  }
  {
    const InterpolatorOptions m = withScenarioMargins(planned_with, {});
    std::printf("knots' margins (the scenario's planner section): support inset %.3f m, friction share %.2f, zmp "
                "shift cap %.3f m, barrier oracle %s\n",
                m.support_inset, m.friction_share, m.zmp_shift_cap, m.posture_mu_oracle.c_str());
  }
  std::printf("%3s %7s %7s %-7s %-16s %9s %9s %7s %8s %8s %8s %8s %9s\n", "n", "verify", "threads", "order",
              "result", "wall s", "posture s", "calls", "repairs", "filtered", "refined", "samples", "motion s");
  InterpolationResult keep, one_thread, fixed_order;
  std::unique_ptr<TransitionMemo> solved;  // the default run's transitions
  struct Variant {
    int n;
    bool verify;
    int threads;
    bool by_failure;  // InterpolatorOptions::order_by_failure
  };
  for (const Variant v : {Variant{10, true, 2, true}, Variant{20, true, 1, true}, Variant{20, true, 1, false},
                          Variant{20, true, 2, true}, Variant{20, false, 2, true}}) {
    const int n = v.n;
    const bool verify = v.verify;
    // As acyclic-interpolator reads the plan: the scenario's margins and
    // knots' oracle, after the settings the plan file recorded (the
    // planner's --set), so that the plan is interpolated as it was verified.
    InterpolatorOptions o = withScenarioMargins(planned_with, {});
    o.steps = n;
    o.verify_samples = verify;
    o.threads = v.threads;
    o.order_by_failure = v.by_failure;
    o.posture_ipopt_options = ipopt;
    o.collision_cutoff = cutoff;
    const bool is_default = n == 20 && verify && v.threads == 2 && v.by_failure;
    if (is_default) solved = std::make_unique<TransitionMemo>(o);
    // An empty memo changes nothing but keeps what is solved (transition_memo.h).
    InterpolationResult r = is_default ? interpolate(plan, sc, *solved) : interpolate(plan, sc, o);
    const auto& s = r.trajectory.stats;
    std::printf("%3d %7s %7d %-7s %-16s %9.2f %9.2f %7ld %8d %8d %8d %8zu %9.2f\n", n, verify ? "yes" : "no",
                v.threads, v.by_failure ? "failure" : "fixed", toString(r.status), s.seconds, r.posture_seconds,
                s.posture_calls, s.repairs, r.filtered, r.refinements, r.trajectory.samples.size(),
                r.trajectory.duration());
    if (!r.success()) std::printf("    reason: %s\n", r.reason.c_str());
    std::fflush(stdout);
    if (n == 20 && verify && v.threads == 1) (v.by_failure ? one_thread : fixed_order) = std::move(r);
    else if (n == 20 && verify) keep = std::move(r);
  }
  auto same = [](const InterpolationResult& a, const InterpolationResult& b) {
    bool same = a.trajectory.samples.size() == b.trajectory.samples.size();
    for (std::size_t i = 0; same && i < a.trajectory.samples.size(); ++i)
      same = a.trajectory.samples[i].q.joints == b.trajectory.samples[i].q.joints &&
             a.trajectory.samples[i].q.base_position == b.trajectory.samples[i].q.base_position;
    return same;
  };
  if (keep.success() && one_thread.success())
    std::printf("same trajectory on 1 and 2 threads (n = 20): %s\n", same(keep, one_thread) ? "yes" : "NO");
  if (one_thread.success() && fixed_order.success())
    std::printf("repairs in the order a first failure names against their fixed order (n = 20, 1 thread): %.2f times "
                "the wall time, %.2f times the posture calls, same trajectory: %s\n",
                one_thread.trajectory.stats.seconds / fixed_order.trajectory.stats.seconds,
                static_cast<double>(one_thread.trajectory.stats.posture_calls) /
                    static_cast<double>(fixed_order.trajectory.stats.posture_calls),
                same(one_thread, fixed_order) ? "yes" : "no (each valid: another repair made a transition first)");
  if (keep.success() && solved) {
    TransitionMemo received(solved->options(), true, /*check_on_use=*/true);
    const std::vector<RememberedTransition> sent = rememberedTransitions(plan, *solved);
    for (const RememberedTransition& t : sent) received.store(transitionKey(plan, t.design), t.outcome);
    const InterpolationResult r = interpolate(plan, sc, received);
    std::printf("the default run's %zu transitions taken as the planner's are over LCM (each checked before use): %s, "
                "%.2f s, %.3f times the wall time of solving them; %d taken, %d refused, same trajectory: %s\n",
                sent.size(), toString(r.status), r.trajectory.stats.seconds,
                r.trajectory.stats.seconds / keep.trajectory.stats.seconds, r.reused, r.refused,
                r.success() && same(r, keep) ? "yes" : "NO");
  }
  if (keep.success()) {
    ValidityChecker checker(sc.robot, sc.scene);
    const TrajectoryReport rep = checkTrajectory(keep.trajectory, sc, checker);
    std::printf("trajectory check (n = 20): %s, %d of %d samples valid, worst joint speed %.0f%% of its limit\n",
                rep.valid() ? "valid" : "INVALID", rep.samples - rep.invalid_samples, rep.samples,
                100 * rep.worst_velocity_ratio);
  }
  return 0;
}
