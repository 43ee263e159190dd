// acyclic-interpolator: turns a contact plan into a whole-body trajectory.
//   File mode (--in PLAN --out TRAJECTORY): writes acyclic.trajectory/1.
//   Progress on stderr on a terminal, nothing when not (or with -q).
//   Exit: 0 written, 1 not interpolated (reason printed: a transition that
//   cannot be repaired, or cancelled by SIGINT/SIGTERM), 2 bad input (a file,
//   a field, an option, or a plan whose witnesses or sequence are not valid).
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <unistd.h>

#include "processes/command_line.h"
#include "interpolator/interpolator.h"
#include "planner/posture/heap_tuning.h"
#include "planner/common/format_error.h"
#include "planner/plan/scenario_reference.h"
#include "planner/search/planner_parameters.h"
#include "processes/lcm_process.h"
#include "processes/interpolator_service.h"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  acyclic::InterpolatorOptions o;
  CLI::App app{
      "Interpolates a contact plan (acyclic.plan/1) into a whole-body trajectory (acyclic.trajectory/1):\n"
      "the moving body's path between stances (straight along the surface normals, a spline between,\n"
      "raised automatically where it collides), a posture at each of n steps, useless stances filtered,\n"
      "timed within the joint velocity limits and a speed cap, at rest wherever a contact is made or\n"
      "broken, sampled every dt.\n"
      "File mode: --in PLAN --out TRAJECTORY; exit status 0 written, 1 not interpolated (reason printed,\n"
      "or cancelled), 2 bad input.\n"
      "LCM mode: --lcm interpolates every ACYCLIC_PLAN with status OK and answers ACYCLIC_TRAJECTORY (same\n"
      "request id), with ACYCLIC_PROGRESS, ACYCLIC_STATUS at 1 Hz and on errors, and ACYCLIC_CANCEL. One\n"
      "plan at a time: a plan that arrives while one is interpolated is refused (ACYCLIC_TRAJECTORY with\n"
      "status ERROR and the reason). The planner's ACYCLIC_TRANSITIONS for the same request, solved under\n"
      "this interpolator's options, are taken instead of solved, each checked first (the same trajectory).\n"
      "Exits 0 on SIGINT/SIGTERM."};
  std::string in, out, scenario_path;
  bool no_filter = false, quiet = false, verbose = false;
  bool lcm_mode = false;
  std::string url = acyclic::proc::defaultLcmUrl();
  app.add_option("--in", in, "plan file (acyclic.plan/1), file mode");
  app.add_option("--out", out, "trajectory file to write (acyclic.trajectory/1), file mode")
      ->check(acyclic::proc::InWritableDirectory());
  app.add_flag("--lcm", lcm_mode, "serve ACYCLIC_PLAN on LCM instead of the file mode");
  bool solve_all = false;
  app.add_flag("--no-planner-transitions", solve_all,
               "LCM mode: ignore the planner's ACYCLIC_TRANSITIONS and solve every transition here");
  app.add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  app.add_option("--scenario", scenario_path,
                 "scenario file (default: the plan's 'scenario' field, beside the plan, else in the current directory)");
  app.add_option("-n,--steps", o.steps, "posture-generator steps per transition")->capture_default_str();
  app.add_option("--dt", o.dt, "sample period, s (the controller's)")->capture_default_str();
  app.add_option("--speed-cap", o.speed_cap, "largest speed of any link origin, m/s")->capture_default_str();
  app.add_option("--velocity-share", o.velocity_share, "share of each joint's velocity limit used")->capture_default_str();
  app.add_option("--pyramid-edges", o.pyramid_edges,
                 "edges of the knots' friction pyramid: 4 (every other edge of the contract's) or 8 (all)")
      ->capture_default_str();
  auto* inset_flag = app.add_option("--support-inset", o.support_inset,
                 "stability margin of the knots: each supporting contact's forces applied this far (m) inside "
                 "its spot's edges (default: the scenario's planner key posture_support_inset, else 0)");
  auto* inset_y_flag = app.add_option("--support-inset-y", o.support_inset_y,
                 "the same along each spot's y axis (across a sole) instead, m (negative: --support-inset; default: "
                 "the scenario's posture_support_inset_y, else -1)");
  auto* share_flag = app.add_option("--friction-share", o.friction_share,
                 "stability margin of the knots: the share of each surface's friction coefficient used, in (0, 1] "
                 "(default: the scenario's planner key posture_friction_share, else 1)");
  auto* zmp_flag = app.add_option("--zmp-shift-cap", o.zmp_shift_cap,
                 "largest shift of the zero-moment point by the motion's accelerations, m (0: no such bound; 0.01 "
                 "slows a whole-body sway to about 0.12 m/s^2; default: the scenario's planner key zmp_shift_cap, "
                 "else 0)");
  auto* mu_flag = app.add_option("--mu-oracle", o.posture_mu_oracle,
                 "Ipopt's barrier oracle for the knots' posture solves: quality-function, probing or loqo (default: "
                 "the scenario's planner key transition_mu_oracle, else quality-function)")
                     ->check(CLI::IsMember(acyclic::muOracles()));
  app.add_option("--link-acceleration-cap", o.link_acceleration_cap,
                 "largest acceleration of any link origin, m/s^2 (joints: the robot file's acceleration_limits)")
      ->capture_default_str();
  app.add_option("--lift", o.lift, "straight motion along the surface normal on leaving and reaching, m")
      ->capture_default_str();
  std::vector<std::string> settings;
  app.add_option("--set", settings,
                 "a key of the scenario's planner section, as if its file said so (repeatable; as acyclic-planner "
                 "--set): the margins and oracle above read posture_support_inset, posture_support_inset_y, "
                 "posture_friction_share, zmp_shift_cap and transition_mu_oracle from it; their own options still "
                 "come first. File mode: a plan's own planner_settings (the planner's --set) apply first, these "
                 "after them; --lcm: give the planner's here too (acyclic-launch --set does)")
      ->type_name("KEY=VALUE");
  app.add_flag("--no-filter", no_filter, "keep every stance of the plan");
  app.add_option("--threads", o.threads, "transitions solved at once (the result does not depend on it)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("-q,--quiet", quiet, "no progress, even on a terminal");
  app.add_flag("-v,--verbose", verbose,
               "file mode: one line per transition solved on stderr, in the plan's order (its stances, the attempt "
               "that made it or none, attempts, posture calls, seconds), to see which needed repairs and what they "
               "cost");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)
  o.filter = !no_filter;
  // The scenario's margins unless the command line gives them.
  const bool inset_given = inset_flag->count() > 0, inset_y_given = inset_y_flag->count() > 0,
             share_given = share_flag->count() > 0, zmp_given = zmp_flag->count() > 0,
             mu_given = mu_flag->count() > 0;
  try {  // said now, not at the first plan
    acyclic::checkPlannerSettings(settings);
  } catch (const acyclic::FormatError& e) {
    std::fprintf(stderr, "acyclic-interpolator: %s\n", e.what());
    return 2;
  }
  // plan_settings: those the plan file recorded (the planner's --set), which
  // the command line's follow.
  const auto options_with = [=](const acyclic::Scenario& sc, const std::vector<std::string>& plan_settings,
                                const std::string& plan_path) {
    acyclic::Scenario set = sc;
    acyclic::setPlannerKeys(set, plan_settings, plan_path + " (planner_settings)");
    acyclic::setPlannerKeys(set, settings);
    acyclic::InterpolatorOptions r = acyclic::withScenarioMargins(set, o);
    if (inset_given) r.support_inset = o.support_inset;
    if (inset_y_given) r.support_inset_y = o.support_inset_y;
    if (share_given) r.friction_share = o.friction_share;
    if (zmp_given) r.zmp_shift_cap = o.zmp_shift_cap;
    if (mu_given) r.posture_mu_oracle = o.posture_mu_oracle;
    return r;
  };
  const acyclic::InterpolatorOptionsFor options_for = [=](const acyclic::Scenario& sc) {
    return options_with(sc, {}, "");
  };
  acyclic::keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  if (lcm_mode) {
    if (!in.empty() || !out.empty()) {
      std::fprintf(stderr, "acyclic-interpolator: --lcm and --in/--out exclude each other\n");
      return 2;
    }
    acyclic::proc::installSignalHandlers();
    return acyclic::serveInterpolator(url, options_for, !solve_all);
  }
  if (in.empty() || out.empty()) {
    std::fprintf(stderr, "acyclic-interpolator: give --in PLAN --out TRAJECTORY (file mode) or --lcm; see --help\n");
    return 2;
  }

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  try {
    if (scenario_path.empty()) scenario_path = acyclic::scenarioNamedBy(in);
    const acyclic::Scenario sc = acyclic::Scenario::load(scenario_path);
    const acyclic::Plan plan = acyclic::readPlan(in, sc);
    const bool tty = !quiet && isatty(STDERR_FILENO);
    auto progress = [&](const acyclic::InterpolationProgress& p) {
      if (!tty) return;
      std::fprintf(stderr, "\r%7.1f s  %-11s transition %d of %d  posture calls %ld   ", p.seconds, p.stage.c_str(),
                   p.transition, p.transitions, p.posture_calls);
    };
    const acyclic::InterpolatorOptions options = options_with(sc, plan.planner_settings, in);
    if (!plan.planner_settings.empty() && !quiet) {
      std::string keys;
      for (const std::string& k : plan.planner_settings) keys += (keys.empty() ? "" : ", ") + k;
      std::fprintf(stderr, "acyclic-interpolator: %s was planned with --set %s: applied\n", in.c_str(), keys.c_str());
    }
    acyclic::InterpolationResult r = acyclic::interpolate(plan, sc, options, progress, &g_stop);
    if (tty) std::fprintf(stderr, "\n");
    if (verbose)
      for (const acyclic::TransitionRecord& t : r.transitions)
        std::fprintf(stderr,
                     "acyclic-interpolator: transition %d -> %d (%s): %s; %d attempt%s, %ld posture call%s, %.2f s\n",
                     t.from, t.to,
                     t.still  ? "a body already touching where it goes, its contacts fixed"
                     : t.move ? "a body moves"
                              : "contacts fixed",
                     t.ok ? t.how.c_str() : "not made",
                     t.attempts, t.attempts == 1 ? "" : "s", t.posture_calls, t.posture_calls == 1 ? "" : "s",
                     t.seconds);
    if (!r.success()) {
      std::printf("acyclic-interpolator: %s: %s: %s\n", in.c_str(), acyclic::toString(r.status), r.reason.c_str());
      return r.status == acyclic::InterpolationResult::Status::InvalidInput ? 2 : 1;
    }
    r.trajectory.plan = in;
    r.trajectory.scenario = scenario_path;
    acyclic::writeTrajectory(r.trajectory, sc, out);
    const auto& s = r.trajectory.stats;
    std::printf(
        "acyclic-interpolator: %s: %d stances (%d filtered), %d transitions, %d repaired, %ld posture calls, "
        "%.2f s\n",
        sc.name.c_str(), s.stances_in, r.filtered, s.transitions, s.repairs, s.posture_calls, s.seconds);
    std::printf("acyclic-interpolator: %zu samples (%.2f s of motion at dt %.3f s), %zu phases written to %s\n",
                r.trajectory.samples.size(), r.trajectory.duration(), r.trajectory.dt, r.trajectory.phases.size(),
                out.c_str());
    return 0;
  } catch (const acyclic::FormatError& e) {
    std::fprintf(stderr, "acyclic-interpolator: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-interpolator: error: %s\n", e.what());
    return 2;
  }
}
