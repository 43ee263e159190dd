// acyclic-planner: plans a scenario's contacts.
//   File mode (--in SCENARIO --out PLAN): writes acyclic.plan/1. Progress on
//   stderr on a terminal, nothing when not. Exit: 0 solved, 1 not solved
//   (reason printed) or a refused plan not written (--keep-refused), 2 bad input.
//   --trajectory T: the plan interpolated too, reusing the transitions its
//   verification solved (exit 1 when no trajectory is made; the plan stays).
//   LCM mode (--lcm): serves ACYCLIC_REQUEST, answers ACYCLIC_PLAN (preceded by
//   ACYCLIC_TRANSITIONS, the transitions it verified), reports on
//   ACYCLIC_PROGRESS and ACYCLIC_STATUS, obeys ACYCLIC_CANCEL (planner_service).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "processes/command_line.h"
#include "planner/common/format_error.h"
#include "planner/posture/heap_tuning.h"
#include "planner/plan/guide.h"
#include "planner/search/planner_parameters.h"
#include "planner/search/refused_plans.h"
#include "processes/lcm_process.h"
#include "processes/planner_service.h"

#ifdef ACYCLIC_HAVE_INTERPOLATOR
#include "interpolator/transition_memo.h"
#include "planner/plan/trajectory.h"

namespace {

// --trajectory: the plan file just written, read back as acyclic-interpolator
// reads it (the JSON round trip that the verification also made, so its
// transitions are found in the memo), interpolated with the memo's options
// (the scenario's margins and oracle, after --set: what acyclic-interpolator
// applies from the plan's planner_settings), written to `path`. False, with
// the reason printed, when no trajectory is made; the plan stays written.
// `sc`: the planner's (its robot and scene are what the interpolation reads;
// its planner keys are in the memo's options; its path is the trajectory's
// scenario, as acyclic-interpolator writes the path it was given).
bool writeTrajectoryOf(const std::string& plan_path, const acyclic::Scenario& sc, const std::string& path,
                       acyclic::TransitionMemo& memo, bool tty) {
  const acyclic::Plan plan = acyclic::readPlan(plan_path, sc);
  auto progress = [&](const acyclic::InterpolationProgress& p) {
    if (!tty) return;
    std::fprintf(stderr, "\r%7.1f s  interpolating: %-11s transition %d of %d   ", p.seconds, p.stage.c_str(),
                 p.transition, p.transitions);
  };
  acyclic::InterpolationResult r = acyclic::interpolate(plan, sc, memo, progress, &acyclic::proc::stopFlag());
  if (tty) std::fprintf(stderr, "\n");
  if (!r.success()) {
    std::printf("acyclic-planner: no trajectory: %s: %s (the plan is written: acyclic-interpolator --in %s)\n",
                acyclic::toString(r.status), r.reason.c_str(), plan_path.c_str());
    return false;
  }
  r.trajectory.plan = plan_path;
  r.trajectory.scenario = sc.path;
  acyclic::writeTrajectory(r.trajectory, sc, path);
  const auto& s = r.trajectory.stats;
  std::printf("acyclic-planner: trajectory: %d stances (%d filtered), %d transitions (%d of them verified by the "
              "search, not solved again), %d repaired, %ld posture calls, %.2f s\n",
              s.stances_in, r.filtered, s.transitions, r.reused, s.repairs, s.posture_calls, s.seconds);
  std::printf("acyclic-planner: %zu samples (%.2f s of motion at dt %.3f s), %zu phases written to %s\n",
              r.trajectory.samples.size(), r.trajectory.duration(), r.trajectory.dt, r.trajectory.phases.size(),
              path.c_str());
  return true;
}

}  // namespace
#endif

int main(int argc, char** argv) {
  CLI::App app{
      "Plans the contacts of a scenario (Escande et al., ISER 2008): best-first search over sets of\n"
      "contacts driven by the guide potential of the scenario's key postures.\n"
      "File mode: --in SCENARIO --out PLAN writes acyclic.plan/1; exit status 0 solved, 1 not solved\n"
      "(reason printed), 2 bad input.\n"
      "LCM mode: --lcm serves ACYCLIC_REQUEST and answers ACYCLIC_PLAN (with the request id), with\n"
      "ACYCLIC_PROGRESS during the search, ACYCLIC_STATUS at 1 Hz and on every error, and ACYCLIC_CANCEL.\n"
      "One request at a time: a request that arrives while one runs is refused (ACYCLIC_PLAN with\n"
      "status ERROR and the reason, and a status error). A plan is preceded by ACYCLIC_TRANSITIONS, the\n"
      "transitions its verification solved, so that the interpolator need not solve them again.\n"
      "Exits 0 on SIGINT/SIGTERM."};
  std::string in, out, guide_path, url = acyclic::proc::defaultLcmUrl();
  bool lcm_mode = false;
  acyclic::PlannerOverrides o;
  bool quiet = false;
  app.add_option("--in", in, "scenario file (acyclic.scenario/1), file mode");
  app.add_option("--out", out, "plan file to write (acyclic.plan/1), file mode")
      ->check(acyclic::proc::InWritableDirectory());
  app.add_option("--guide", guide_path,
                 "key postures from this guide file (acyclic.guide/1, e.g. from acyclic-guide) instead of the "
                 "scenario's, file mode");
  app.add_flag("--lcm", lcm_mode, "serve requests on LCM instead of the file mode");
  app.add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  app.add_option("--seed", o.seed, "overrides the scenario's (and the request's) seed");
  app.add_option("--max-seconds", o.max_seconds,
                 "wall-time budget (default: the request's, else the scenario's planner section, else 60)");
  app.add_option("--max-nodes", o.max_nodes, "nodes generated at most (default: scenario, else 1000)");
  app.add_option("--max-posture-calls", o.max_posture_calls, "posture-generator calls at most (default: scenario, else 20000)");
  app.add_option("--threads", o.threads,
                 "posture generators run at once, shared among the scenario's portfolio members (default: "
                 "scenario, else 2); the plan does not depend on it");
  app.add_option("--member", o.member,
                 "of the scenario's portfolio (planner: portfolio), plan with this member alone, on every thread "
                 "(default: the whole portfolio; its plan is the winning member's)");
  app.add_option("--set", o.set,
                 "a key of the scenario's planner section, as if its file said so (repeatable; VALUE read as YAML, "
                 "null for the key's default; e.g. --set posture_mu_oracle=probing --set portfolio=null). The "
                 "verification of transitions reads them too, and the plan file records them (planner_settings), "
                 "which acyclic-interpolator applies: the plan is interpolated as it was verified")
      ->type_name("KEY=VALUE");
  app.add_flag("--eager-sons", o.eager_sons, "ablation: every son of a node at once instead of lazy sons (paper 2.8)");
  app.add_flag("--random-candidates", o.random_candidates,
               "ablation: random (x, y, theta) samples instead of optimized candidates (paper 2.6)");
  app.add_flag("--distance-to-goal", o.distance_to_goal, "ablation: distance to the goal instead of the guide potential");
  app.add_flag("--no-failure-memory", o.no_failure_memory,
               "ablation: try every pair at every node, even where it just failed from the same place");
  app.add_flag("--no-swing-check", o.no_swing_check,
               "ablation: accept sons whose limb hanging from a shared contact cannot swing to its new place");
  bool verify = false, no_verify = false;
  auto* verify_flag = app.add_flag(
      "--verify-transitions", verify,
      "solve every transition of a plan found as the interpolator will, and drop the stance of the first that "
      "cannot be made and search on (default: the scenario's planner key verify_transitions, else on when "
      "built with the interpolator)");
  app.add_flag("--no-verify-transitions", no_verify, "no verification of transitions, whatever the scenario says")
      ->excludes(verify_flag);
  bool on_expansion = false, no_on_expansion = false;
  auto* on_expansion_flag = app.add_flag(
      "--verify-on-expansion", on_expansion,
      "with the verification of transitions: verify the transitions into each stance before building on it, not "
      "only when a plan reaches the goal (default: the scenario's planner key verify_on_expansion, else off)");
  app.add_flag("--no-verify-on-expansion", no_on_expansion, "verify transitions only when a plan reaches the goal")
      ->excludes(on_expansion_flag);
  std::string keep_refused;
  app.add_option("--keep-refused", keep_refused,
                 "file mode: write each plan the verification refuses to DIR/refused_N.plan.json and its failing "
                 "stances A..B to DIR/refused_N_stances_A-B.plan.json (give that to acyclic-interpolator --no-filter "
                 "for the whole reason); DIR is created")
      ->type_name("DIR");
  std::string trajectory_out;
#ifdef ACYCLIC_HAVE_INTERPOLATOR
  app.add_option("--trajectory", trajectory_out,
                 "file mode: also interpolate the plan written, as acyclic-interpolator --in PLAN would with no "
                 "options (the same trajectory, bit for bit), and write acyclic.trajectory/1 here; the transitions "
                 "the verification solved are not solved again")
      ->type_name("TRAJECTORY")
      ->check(acyclic::proc::InWritableDirectory());
#endif
  app.add_flag("-q,--quiet", quiet, "no progress, even on a terminal");
  app.add_flag("-v,--verbose", o.verbose, "one line per expanded node on stderr (its contacts, key, goal link)");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)
  if (verify) o.verify_transitions = 1;
  if (no_verify) o.verify_transitions = 0;
  if (on_expansion) o.verify_on_expansion = 1;
  if (no_on_expansion) o.verify_on_expansion = 0;
  acyclic::keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  try {  // said now, not at the first request
    acyclic::checkPlannerSettings(o.set);
  } catch (const acyclic::FormatError& e) {
    std::fprintf(stderr, "acyclic-planner: %s\n", e.what());
    return 2;
  }

  acyclic::proc::installSignalHandlers();
  if (lcm_mode) {
    if (!in.empty() || !out.empty() || !keep_refused.empty() || !trajectory_out.empty()) {
      std::fprintf(stderr, "acyclic-planner: --lcm and --in/--out/--keep-refused/--trajectory exclude each other\n");
      return 2;
    }
    return acyclic::servePlanner(url, o);
  }
  if (in.empty() || out.empty()) {
    std::fprintf(stderr, "acyclic-planner: give --in SCENARIO --out PLAN (file mode) or --lcm; see --help\n");
    return 2;
  }
  if (!trajectory_out.empty() &&
      std::filesystem::weakly_canonical(trajectory_out) == std::filesystem::weakly_canonical(out)) {
    std::fprintf(stderr, "acyclic-planner: --trajectory %s is the plan file (--out): give another\n",
                 trajectory_out.c_str());
    return 2;
  }
  try {
    acyclic::Scenario sc = acyclic::Scenario::load(in);
    if (!guide_path.empty()) sc.key_postures = acyclic::readGuide(guide_path, sc).key_postures;
    if (sc.key_postures.size() < 2 && !o.distance_to_goal) {
      std::fprintf(stderr, "acyclic-planner: %s: no key postures (at least two): give --guide GUIDE "
                   "(acyclic-guide writes one) or write them in the scenario\n", in.c_str());
      return 2;
    }
#ifdef ACYCLIC_HAVE_INTERPOLATOR
    std::shared_ptr<acyclic::TransitionMemo> memo;
    acyclic::PlannerParameters p = o.apply(sc, -1, trajectory_out.empty() ? nullptr : &memo);
#else
    acyclic::PlannerParameters p = o.apply(sc, -1);
#endif
    if (!keep_refused.empty()) {
      // Made before the search, so that a bad path is said now, not after it.
      std::error_code ec;
      std::filesystem::create_directories(keep_refused, ec);
      if (ec || !std::filesystem::is_directory(keep_refused)) {
        std::fprintf(stderr, "acyclic-planner: --keep-refused %s: cannot make that directory%s%s\n",
                     keep_refused.c_str(), ec ? ": " : "", ec ? ec.message().c_str() : "");
        return 2;
      }
      p.keep_refused_plans = true;
    }
    acyclic::ContactPlanner planner(sc, p);
    const bool tty = !quiet && isatty(STDERR_FILENO);
    auto progress = [&](const acyclic::PlanningStats& s) {
      if (!tty) return;
      std::fprintf(stderr, "\r%7.1f s  nodes %ld (expanded %ld)  posture calls %ld (failed %ld)  best f_T %.3f   ",
                   s.seconds, s.nodes_generated, s.nodes_expanded, s.posture_calls, s.posture_failures,
                   s.best_potential);
      if (s.verifying)
        std::fprintf(stderr, "\n%7.1f s  a plan found: verifying its transitions (%ld plans refused so far)\n",
                     s.seconds, s.plans_refused);
    };
    acyclic::PlanningResult r = planner.plan(&acyclic::proc::stopFlag(), progress);
    // The plan files say which keys the command line set, so that the
    // interpolator applies them without being told again.
    r.plan.planner_settings = o.set;
    for (acyclic::RefusedPlan& rp : r.refused_plans) rp.plan.planner_settings = o.set;
    if (tty) std::fprintf(stderr, "\n");
    const auto& s = r.stats;
    std::printf("acyclic-planner: %s: %s in %.2f s; %ld nodes generated (%ld dropped as duplicates of a node), "
                "%ld expanded, %ld posture calls (%ld failed), %ld pairs skipped by the failure memory, %ld calls "
                "solved ahead and not used, %ld stopped early\n",
                sc.name.c_str(), acyclic::toString(r.status), s.seconds, s.nodes_generated, s.duplicates,
                s.nodes_expanded, s.posture_calls, s.posture_failures, s.pairs_remembered, s.calls_ahead_unused,
                s.calls_stopped);
    if (s.limb_retries > 0)
      std::printf("acyclic-planner: %ld added contacts tried again with the guide's limb, %ld made so\n",
                  s.limb_retries, s.limb_retry_successes);
    // A portfolio's stats are its winner's: said so, since the refusal lines
    // below name every member's.
    const std::string verifier = r.winner >= 0 && r.winner < static_cast<int>(r.members.size())
                                     ? " by member \"" + r.members[r.winner].name + "\" (the winner)"
                                     : std::string();
    if (s.plans_verified > 0)
      std::printf("acyclic-planner: transitions verified: %ld plans checked, %ld refused, %ld transitions solved, "
                  "%.2f s%s\n", s.plans_verified, s.plans_refused, s.transitions_solved, s.verify_seconds,
                  verifier.c_str());
    if (s.nodes_verified > 0)
      std::printf("acyclic-planner: verified before expansion: %ld stances, %ld of them dropped (a transition into "
                  "them cannot be made)\n", s.nodes_verified, s.nodes_refused);
    for (std::size_t i = 0; i < r.refusals.size(); ++i)
      std::printf("acyclic-planner: plan %zu refused%s at %s\n", i + 1,
                  i < r.refusal_members.size() ? (" by member \"" + r.refusal_members[i] + "\"").c_str() : "",
                  r.refusals[i].c_str());
    // A portfolio: the lines above are its winner's; each member's outcome.
    for (std::size_t i = 0; i < r.members.size(); ++i) {
      const auto& m = r.members[i];
      const std::string refused =
          m.stats.plans_refused > 0 ? ", " + std::to_string(m.stats.plans_refused) + " plans refused" : "";
      // Its posture calls are what the members are compared by (the plan of
      // the fewest; exporting plans not counted).
      std::printf("acyclic-planner: portfolio member %zu \"%s\"%s: %s, %ld nodes generated, %ld posture calls%s, "
                  "%.2f s%s%s\n", i + 1, m.name.c_str(), static_cast<int>(i) == r.winner ? " (its plan)" : "",
                  acyclic::toString(m.status), m.stats.nodes_generated, m.stats.searchCalls(), refused.c_str(),
                  m.stats.seconds, m.reason.empty() ? "" : ": ", m.reason.c_str());
    }
    if (!r.members.empty())
      std::printf("acyclic-planner: portfolio: %ld nodes generated by the %zu member%s that ran\n", r.portfolioNodes(),
                  r.members.size(), r.members.size() == 1 ? "" : "s");
    bool trajectory_made = true;
    if (r.solved()) {
      acyclic::writePlan(r.plan, sc, out);
      std::printf("acyclic-planner: %zu stances written to %s\n", r.plan.stances.size(), out.c_str());
#ifdef ACYCLIC_HAVE_INTERPOLATOR
      if (memo) trajectory_made = writeTrajectoryOf(out, sc, trajectory_out, *memo, tty);
#endif
    } else {
      std::printf("acyclic-planner: no plan: %s\n", r.reason.c_str());
    }
    // After the plan: a refused plan that cannot be written costs the answer nothing.
    bool kept_all = true;
    if (!keep_refused.empty()) {
      try {
        const std::vector<std::string> kept = acyclic::writeRefusedPlans(r, sc, keep_refused);
        for (std::size_t i = 0; i + 1 < kept.size(); i += 2)
          std::printf("acyclic-planner: refused plan %zu written to %s, its failing stances to %s\n", i / 2 + 1,
                      kept[i].c_str(), kept[i + 1].c_str());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "acyclic-planner: --keep-refused: %s\n", e.what());
        kept_all = false;
      }
    }
    return r.solved() && kept_all && trajectory_made ? 0 : 1;
  } catch (const acyclic::FormatError& e) {
    std::fprintf(stderr, "acyclic-planner: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-planner: error: %s\n", e.what());
    return 2;
  }
}
