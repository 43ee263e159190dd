#include "interpolator/plan_verifier.h"

#include <algorithm>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <mutex>
#include <optional>
#include <thread>

namespace acyclic {

TransitionVerifier::TransitionVerifier(const Scenario& sc, const InterpolatorOptions& options)
    : TransitionVerifier(sc, std::make_shared<TransitionMemo>(options, false)) {}

TransitionVerifier::TransitionVerifier(const Scenario& sc, std::shared_ptr<TransitionMemo> memo)
    : sc_(std::make_shared<const Scenario>(sc)), memo_(std::move(memo)) {
  const TransitionOptions options = transitionOptions(memo_->options());
  for (int t = 0; t < std::max(1, memo_->options().threads); ++t)
    solvers_.push_back(std::make_unique<TransitionSolver>(*sc_, options));
}

PlanVerdict TransitionVerifier::verify(const Plan& found, const std::atomic<bool>& stop) {
  // The plan as the interpolator will read it from the planner's file: the
  // JSON round trip normalizes the base's quaternion, and a last bit is
  // enough to change the outcome of a solve at the margins (a plan accepted
  // in memory failed to interpolate from its file).
  const Plan plan = planFromJson(planToJson(found, *sc_), "the plan being verified", *sc_);
  PlanVerdict v;
  std::vector<TransitionDesign> designs;
  if (std::string why = designTransitions(plan, designs); !why.empty()) {
    // Consecutive stances the planner wrote always differ by one contact: a
    // plan the interpolator cannot design is the planner's bug.
    throw std::logic_error("the plan's sequence cannot be interpolated: " + why);
  }
  v.transitions = static_cast<int>(designs.size());
  const std::size_t nd = designs.size();
  struct Known {
    bool ok = false;
    std::string reason;
  };
  std::vector<std::string> keys(nd);
  std::vector<Known> outcome(nd);
  std::vector<char> have(nd, 0);
  for (std::size_t i = 0; i < nd; ++i) {
    keys[i] = transitionKey(plan, designs[i]);
    if (const std::optional<TransitionOutcome> o = memo_->find(keys[i])) outcome[i] = {o->ok, o->reason}, have[i] = 1;
  }
  // The unknown ones, in order, on every solver; none after the first failure.
  std::atomic<std::size_t> next{0}, first_failed{nd};
  for (std::size_t i = 0; i < nd; ++i)
    if (have[i] && !outcome[i].ok) {
      first_failed = i;
      break;
    }
  std::mutex m;
  auto work = [&](TransitionSolver& s) {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= nd || i > first_failed.load() || stop.load()) return;
      if (have[i]) continue;
      const TransitionOutcome o = s.solve(plan, designs[i], &stop);
      if (o.cancelled) return;
      Known k{o.ok, o.reason};
      if (!o.ok) {
        std::size_t f = first_failed.load();
        while (i < f && !first_failed.compare_exchange_weak(f, i)) {
        }
      }
      memo_->store(keys[i], o);
      std::lock_guard<std::mutex> lock(m);
      outcome[i] = std::move(k);
      have[i] = 1;
      ++v.solved;
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < solvers_.size(); ++t) pool.emplace_back(work, std::ref(*solvers_[t]));
  work(*solvers_[0]);
  for (auto& th : pool) th.join();
  for (std::size_t i = 0; i < nd; ++i) {
    if (!have[i]) {
      v.stopped = true;
      return v;
    }
    if (!outcome[i].ok) {
      v.failed_from = designs[i].from;
      v.failed_to = designs[i].to;
      v.reason = outcome[i].reason;
      return v;
    }
  }
  return v;
}

PlanVerifier makePlanVerifier(const Scenario& sc, const InterpolatorOptions& options) {
  return makePlanVerifier(sc, std::make_shared<TransitionMemo>(options, false));
}

PlanVerifier makePlanVerifier(const Scenario& sc, std::shared_ptr<TransitionMemo> memo) {
  auto verifier = std::make_shared<TransitionVerifier>(sc, std::move(memo));
  return [verifier](const Plan& plan, const std::atomic<bool>& stop) { return verifier->verify(plan, stop); };
}

namespace {

// Gives p its verifier and, unless it has one, a factory of verifiers (a
// portfolio's members each get their own, with its own solvers): each made
// by `make` on a copy of the scenario that outlives the caller's.
void attachMade(PlannerParameters& p, const Scenario& sc, std::function<PlanVerifier(const Scenario&)> make) {
  if (!p.verify_transitions) return;
  if (!p.make_verifier) {
    auto scenario = std::make_shared<const Scenario>(sc);
    p.make_verifier = [scenario, make] { return make(*scenario); };
  }
  if (!p.verify_plan) p.verify_plan = p.make_verifier();
}

}  // namespace

void attachPlanVerifier(PlannerParameters& p, const Scenario& sc, const InterpolatorOptions& options) {
  attachMade(p, sc, [options](const Scenario& s) { return makePlanVerifier(s, options); });
}

void attachPlanVerifier(PlannerParameters& p, const Scenario& sc, std::shared_ptr<TransitionMemo> memo) {
  // Every member's verifier keeps what it solves in the one memo.
  attachMade(p, sc, [memo](const Scenario& s) { return makePlanVerifier(s, memo); });
}

void attachPlanVerifier(PlannerParameters& p, const Scenario& sc) {
  attachPlanVerifier(p, sc, withScenarioMargins(sc, {}));
}

}  // namespace acyclic
