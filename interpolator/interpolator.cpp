#include "interpolator/interpolator.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <optional>
#include <thread>

#include "interpolator/stance_filter.h"
#include "interpolator/transition_memo.h"
#include "interpolator/time_law.h"
#include "planner/scene/friction.h"

namespace acyclic {

const char* toString(InterpolationResult::Status s) {
  switch (s) {
    case InterpolationResult::Status::Success: return "success";
    case InterpolationResult::Status::InvalidInput: return "invalid input";
    case InterpolationResult::Status::Unrepairable: return "unrepairable transition";
    case InterpolationResult::Status::TransitionFailed: return "transition failed";
    case InterpolationResult::Status::Cancelled: return "cancelled";
  }
  return "?";
}

namespace {

bool sameContacts(const std::vector<ContactSpec>& a, const std::vector<ContactSpec>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].spot != b[i].spot || a[i].surface != b[i].surface || a[i].supporting != b[i].supporting ||
        a[i].placement.x != b[i].placement.x || a[i].placement.y != b[i].placement.y ||
        a[i].placement.theta != b[i].placement.theta)
      return false;
  return true;
}

std::string validateOptions(const InterpolatorOptions& o) {
  if (o.steps < 1) return "steps must be at least 1";
  if (!(o.fixed_step >= 0)) return "the fixed-contact step must be non-negative";
  if (!(o.dt > 0)) return "dt must be positive";
  if (!(o.speed_cap > 0)) return "the speed cap must be positive";
  if (o.pyramid_edges != 4 && o.pyramid_edges != kFrictionPyramidEdges)
    return "the friction pyramid's edges must be 4 or " + std::to_string(kFrictionPyramidEdges);
  if (!(o.support_inset >= 0 && o.support_inset < 0.1)) return "the support inset must be in [0, 0.1) m";
  if (!(o.support_inset_y < 0.1)) return "the support inset across must be below 0.1 m (negative: the support inset)";
  if (!(o.friction_share > 0 && o.friction_share <= 1)) return "the friction share must be in (0, 1]";
  if (!(o.zmp_shift_cap >= 0 && std::isfinite(o.zmp_shift_cap))) return "the ZMP shift cap must be >= 0 m and finite";
  if (!(o.link_acceleration_cap > 0 && std::isfinite(o.link_acceleration_cap)))
    return "the link acceleration cap must be positive and finite";
  if (!(o.velocity_share > 0 && o.velocity_share <= 1)) return "the velocity share must be in (0, 1]";
  if (!(o.lift > o.touch_clearance && o.touch_clearance > 0 && o.touch_clearance < 1e-3))
    return "expected 0 < touch clearance < 1 mm and lift > touch clearance";
  if (!(o.air_orientation_tolerance >= 0 && o.air_orientation_tolerance < 1))
    return "the orientation tolerance in the air must be in [0, 1)";
  if (o.repair_attempts < 0 || !(o.repair_step > 0) || o.refine_depth < 0 || o.posture_iterations < 1)
    return "repair attempts, refinement depth and posture iterations must be non-negative, the repair step positive";
  if (!(o.wide_clearance >= 0 && o.wide_clearance < 0.05)) return "the wide clearance must be in [0, 0.05) m";
  if (o.threads < 1) return "threads must be at least 1";
  if (!isMuOracle(o.posture_mu_oracle))
    return "the barrier oracle must be " + muOracleChoices() + ", not '" + o.posture_mu_oracle + "'";
  return "";
}

// interpolate(), with a memo or none (nullptr).
InterpolationResult interpolateWith(const Plan& plan, const Scenario& sc, const InterpolatorOptions& opt,
                                    TransitionMemo* memo,
                                    const std::function<void(const InterpolationProgress&)>& progress,
                                    const std::atomic<bool>* cancel);

}  // namespace

InterpolatorOptions withScenarioMargins(const Scenario& sc, InterpolatorOptions o) {
  if (!sc.planner_section) return o;
  const YamlField& f = *sc.planner_section;
  if (f.has("posture_support_inset")) o.support_inset = f["posture_support_inset"].number();
  if (f.has("posture_support_inset_y")) o.support_inset_y = f["posture_support_inset_y"].number();
  if (f.has("posture_friction_share")) o.friction_share = f["posture_friction_share"].number();
  if (f.has("zmp_shift_cap")) o.zmp_shift_cap = f["zmp_shift_cap"].number();
  if (f.has("transition_mu_oracle")) {
    o.posture_mu_oracle = f["transition_mu_oracle"].string();
    if (!isMuOracle(o.posture_mu_oracle)) f["transition_mu_oracle"].fail(muOracleChoices());
  }
  return o;
}

TransitionOptions transitionOptions(const InterpolatorOptions& opt) {
  TransitionOptions to;
  to.steps = opt.steps;
  to.fixed_step = opt.fixed_step;
  to.lift = opt.lift;
  to.touch_clearance = opt.touch_clearance;
  to.air_orientation_tolerance = opt.air_orientation_tolerance;
  to.repair_attempts = opt.repair_attempts;
  to.repair_step = opt.repair_step;
  to.plan_body_path = opt.plan_body_path;
  to.free_limb_paths = opt.free_limb_paths;
  to.limb_joint_paths = opt.limb_joint_paths;
  to.bridge_jumps = opt.bridge_jumps;
  to.refine_depth = opt.refine_depth;
  to.wide_clearance = opt.wide_clearance;
  to.posture.max_iterations = opt.posture_iterations;
  to.posture.max_seconds = 1e6;  // bounded by iterations: deterministic under any load
  to.posture.problem.collision_cutoff = opt.collision_cutoff;
  to.posture.problem.pyramid_sides = opt.pyramid_edges;
  to.posture.problem.support_inset = opt.support_inset;
  to.posture.problem.support_inset_y = opt.support_inset_y;
  to.posture.problem.friction_share = opt.friction_share;
  to.posture.ipopt_options = opt.posture_ipopt_options;
  to.posture.lbfgs_in_kkt = opt.posture_lbfgs_in_kkt;
  to.posture.mu_oracle = opt.posture_mu_oracle;
  to.timing = TimeLawOptions{opt.dt, opt.velocity_share, opt.speed_cap, opt.link_acceleration_cap};
  to.timing.zmp_shift_cap = opt.zmp_shift_cap;
  to.verify_samples = opt.verify_samples;
  to.order_by_failure = opt.order_by_failure;
  return to;
}

InterpolationResult interpolate(const Plan& plan, const Scenario& sc, const InterpolatorOptions& options,
                                const std::function<void(const InterpolationProgress&)>& progress,
                                const std::atomic<bool>* cancel) {
  return interpolateWith(plan, sc, options, nullptr, progress, cancel);
}

InterpolationResult interpolate(const Plan& plan, const Scenario& sc, TransitionMemo& memo,
                                const std::function<void(const InterpolationProgress&)>& progress,
                                const std::atomic<bool>* cancel) {
  if (!memo.keepsMotion())
    throw std::invalid_argument("interpolate: the memo keeps no motion (TransitionMemo's keep_motion)");
  return interpolateWith(plan, sc, memo.options(), &memo, progress, cancel);
}

namespace {

InterpolationResult interpolateWith(const Plan& plan, const Scenario& sc, const InterpolatorOptions& opt,
                                    TransitionMemo* memo,
                                    const std::function<void(const InterpolationProgress&)>& progress,
                                    const std::atomic<bool>* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  InterpolationResult res;
  using Status = InterpolationResult::Status;
  auto fail = [&](Status s, std::string why) {
    res.status = s;
    res.reason = std::move(why);
    res.trajectory = Trajectory{};
    return res;
  };
  if (std::string why = validateOptions(opt); !why.empty()) return fail(Status::InvalidInput, why);
  if (plan.stances.empty()) return fail(Status::InvalidInput, "the plan has no stance");
  {
    // Every witness must itself be valid: the interpolation starts and ends on them.
    ValidityChecker checker(sc.robot, sc.scene);
    for (std::size_t k = 0; k < plan.stances.size(); ++k) {
      if (plan.stances[k].configuration.joints.size() != sc.robot->numJoints())
        return fail(Status::InvalidInput, "stance " + std::to_string(k) + ": the configuration has " +
                                              std::to_string(plan.stances[k].configuration.joints.size()) + " joints");
      const ValidityReport r = checker.checkPosture(plan.stances[k].configuration, plan.stances[k].specs());
      for (const auto& p : r.parts)
        if (p.checked && !p.ok())
          return fail(Status::InvalidInput,
                      "stance " + std::to_string(k) + "'s witness posture is not valid: " + p.name + ": " + p.violations[0]);
    }
  }

  const TransitionOptions to = transitionOptions(opt);
  TransitionSolver solver(sc, to);
  Trajectory& tr = res.trajectory;
  tr.scenario = plan.scenario;
  tr.dt = opt.dt;
  tr.stats.stances_in = static_cast<int>(plan.stances.size());

  InterpolationProgress pr;
  auto report = [&](const char* stage) {
    pr.stage = stage;
    pr.posture_calls = tr.stats.posture_calls;
    pr.seconds = elapsed();
    if (progress) progress(pr);
  };

  FilterResult fr;
  if (opt.filter) {
    report("filtering");
    fr = filterStances(plan, solver, cancel);
    tr.stats.posture_calls += fr.posture_calls;
    res.posture_seconds += fr.posture_seconds;
    if (fr.cancelled) return fail(Status::Cancelled, "cancelled while filtering stances");
  } else {
    for (int k = 0; k < static_cast<int>(plan.stances.size()); ++k) fr.kept.push_back(k);
  }
  res.filtered = fr.dropped;
  tr.stats.stances_kept = static_cast<int>(fr.kept.size());

  std::vector<TransitionDesign> designs;
  if (std::string why = designTransitions(plan, fr.kept, designs); !why.empty())
    return fail(Status::InvalidInput, "the plan's sequence cannot be interpolated: " + why);
  tr.stats.transitions = static_cast<int>(designs.size());
  pr.transitions = tr.stats.transitions;

  // Transitions depend only on their two stances: they are solved on
  // `threads` workers, each with its own solver (posture generator and
  // checker), and used in order, so the result is the same for any number of
  // threads. A failure stops the workers from taking later transitions; the
  // first failing transition in order is the one reported.
  const std::size_t nd = designs.size();
  std::vector<TransitionOutcome> outcomes(nd);
  std::vector<char> done(nd, 0);
  {
    std::atomic<std::size_t> next{0};
    std::atomic<std::size_t> first_failed{nd};
    std::atomic<bool> stop{false};  // the caller's cancel, seen by any worker
    std::mutex m;                   // progress and statistics
    std::size_t finished = 0;
    auto work = [&](TransitionSolver& s) {
      for (;;) {
        const std::size_t i = next.fetch_add(1);
        if (i >= nd || i > first_failed.load() || stop.load()) return;
        if (cancel && cancel->load()) {
          stop = true;
          return;
        }
        const TransitionDesign& d = designs[i];
        auto cached = fr.solved.find({d.from, d.to});
        // Keyed only where the memo is read: not for the filter's own solves.
        const std::string key = memo && cached == fr.solved.end() ? transitionKey(plan, d) : std::string();
        std::optional<TransitionOutcome> remembered;
        if (!key.empty()) remembered = memo->find(key);
        std::string refused;  // why a remembered outcome from elsewhere is not used
        if (remembered && memo->checksOnUse()) {
          refused = s.check(plan, d, *remembered);
          if (!refused.empty()) remembered.reset();
        }
        TransitionOutcome o = cached != fr.solved.end() ? cached->second
                              : remembered                ? std::move(*remembered)
                                                          : s.solve(plan, d, cancel);
        const bool counted = cached == fr.solved.end() && !remembered;
        if (counted && memo) memo->store(key, o);
        if (o.cancelled) stop = true;
        if (!o.ok && !o.cancelled) {  // first_failed = min(first_failed, i)
          std::size_t f = first_failed.load();
          while (i < f && !first_failed.compare_exchange_weak(f, i)) {
          }
        }
        std::lock_guard<std::mutex> lock(m);
        if (counted) tr.stats.posture_calls += o.posture_calls, res.posture_seconds += o.posture_seconds;
        if (remembered) ++res.reused;
        if (!refused.empty() && res.refused++ == 0)
          res.refused_reason = "stances " + std::to_string(d.from) + " -> " + std::to_string(d.to) + ": " + refused;
        outcomes[i] = std::move(o);
        done[i] = 1;
        pr.transition = static_cast<int>(++finished);
        report("transitions");
      }
    };
    const int nthreads = std::max(1, std::min<int>(opt.threads, static_cast<int>(nd)));
    std::vector<std::unique_ptr<TransitionSolver>> extra;
    std::vector<std::thread> pool;
    for (int t = 1; t < nthreads; ++t) {
      extra.push_back(std::make_unique<TransitionSolver>(sc, to));
      pool.emplace_back(work, std::ref(*extra.back()));
    }
    work(solver);
    for (auto& th : pool) th.join();
  }
  std::vector<MotionPiece> pieces;
  for (std::size_t i = 0; i < nd; ++i) {
    const TransitionDesign& d = designs[i];
    if (!done[i] || outcomes[i].cancelled) return fail(Status::Cancelled, "cancelled");
    TransitionOutcome& o = outcomes[i];
    res.transitions.push_back({d.from, d.to, d.kind == TransitionDesign::Kind::Move, o.still, o.ok, o.how,
                               o.attempts, o.posture_calls, o.seconds});
    if (!o.ok) {
      res.failed_stances = {d.from, d.to};
      const std::string where = "stances " + std::to_string(d.from) + " -> " + std::to_string(d.to) + ": ";
      return fail(d.kind == TransitionDesign::Kind::Move ? Status::Unrepairable : Status::TransitionFailed,
                  where + o.reason);
    }
    tr.stats.repairs += o.repaired;
    res.refinements += o.refinements;
    for (auto& p : o.pieces) pieces.push_back(std::move(p));
  }
  pr.transition = pr.transitions;
  report("timing");

  // Time each piece rest to rest (time_law.h); consecutive pieces with the same contacts form one phase.
  const TimeLawOptions& tl = to.timing;
  Kinematics kin(sc.robot);
  std::vector<TimedPiece> timed;
  std::vector<int> piece_phase, piece_start;
  int total = 0;
  for (const auto& p : pieces) {
    TimedPiece t(p.knots, *sc.robot, kin, tl);
    if (t.steps() == 0) continue;  // no motion
    if (tr.phases.empty() || !sameContacts(tr.phases.back().contacts, p.contacts)) {
      TrajectoryPhase ph;
      ph.t_start = total * opt.dt;
      ph.contacts = p.contacts;
      ph.stance = p.stance;
      tr.phases.push_back(ph);
    }
    piece_phase.push_back(static_cast<int>(tr.phases.size()) - 1);
    piece_start.push_back(total);
    total += t.steps();
    tr.phases.back().t_end = total * opt.dt;
    timed.push_back(std::move(t));
  }
  if (timed.empty()) {  // nothing moves: one sample at the first witness
    TrajectoryPhase ph;
    ph.contacts = plan.stances.front().specs();
    ph.stance = 0;
    tr.phases.push_back(ph);
    TrajectorySample s;
    s.q = plan.stances.front().configuration;
    s.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
    tr.samples.push_back(s);
  } else {
    std::size_t p = 0;
    for (int i = 0; i <= total; ++i) {
      // A sample on a boundary belongs to the piece that starts there (both are at rest on it).
      while (p + 1 < timed.size() && i >= piece_start[p + 1]) ++p;
      TrajectorySample s;
      s.t = i * opt.dt;
      s.q = timed[p].at((i - piece_start[p]) * opt.dt, &s.dq);
      s.phase = piece_phase[p];
      tr.samples.push_back(std::move(s));
    }
  }
  tr.stats.seconds = elapsed();
  res.status = Status::Success;
  report("done");
  return res;
}

}  // namespace

}  // namespace acyclic
