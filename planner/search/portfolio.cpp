#include "planner/search/portfolio.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace acyclic {

namespace {

// What a caller's progress sees while members run: their counts summed,
// the longest time, the best key.
PlanningStats combined(const std::vector<PlanningStats>& all) {
  PlanningStats s;
  bool first = true;
  for (const PlanningStats& m : all) {
    s.nodes_generated += m.nodes_generated;
    s.nodes_expanded += m.nodes_expanded;
    s.posture_calls += m.posture_calls;
    s.posture_failures += m.posture_failures;
    s.check_refusals += m.check_refusals;
    s.pairs_remembered += m.pairs_remembered;
    s.duplicates += m.duplicates;
    s.calls_ahead_unused += m.calls_ahead_unused;
    s.calls_stopped += m.calls_stopped;
    s.export_calls += m.export_calls;
    s.limb_retries += m.limb_retries;
    s.limb_retry_successes += m.limb_retry_successes;
    s.plans_verified += m.plans_verified;
    s.plans_refused += m.plans_refused;
    s.transitions_solved += m.transitions_solved;
    s.nodes_verified += m.nodes_verified;
    s.nodes_refused += m.nodes_refused;
    s.verify_seconds += m.verify_seconds;
    s.seconds = std::max(s.seconds, m.seconds);
    s.verifying = s.verifying || m.verifying;
    if (m.nodes_generated > 0 && (first || m.best_potential < s.best_potential)) {
      s.best_potential = m.best_potential;
      first = false;
    }
  }
  return s;
}

}  // namespace

struct PortfolioState {
  std::mutex lock;
  std::condition_variable changed;  // a cap lowered, a verification ended, a member finished
  // Counts of posture calls. goals: the count of a goal being verified, LONG_MAX: none.
  std::vector<long> caps, goals;
  explicit PortfolioState(std::size_t n) : caps(n, LONG_MAX), goals(n, LONG_MAX) {}
  // Member j's bound from member i's count n: an earlier member wins a tie.
  static long bound(std::size_t j, std::size_t i, long n) { return n == LONG_MAX ? LONG_MAX : j < i ? n : n - 1; }
  // Another member than j verifies a goal j, at `calls`, cannot beat (under lock).
  bool beaten(std::size_t j, long calls) const;
};

long ContactPlanner::MemberLink::cap() const {
  std::lock_guard<std::mutex> hold(state->lock);
  return state->caps[index];
}

void ContactPlanner::MemberLink::verifying(long calls) {
  {
    std::lock_guard<std::mutex> hold(state->lock);
    state->goals[index] = calls < 0 ? LONG_MAX : calls;
  }
  state->changed.notify_all();
}

bool PortfolioState::beaten(std::size_t j, long calls) const {
  for (std::size_t i = 0; i < goals.size(); ++i)
    if (i != j && calls > bound(j, i, goals[i])) return true;
  return false;
}

bool ContactPlanner::MemberLink::beaten(long calls) const {
  std::lock_guard<std::mutex> hold(state->lock);
  return state->beaten(index, calls);
}

void ContactPlanner::MemberLink::gate(long calls, const std::function<bool()>& give_up) {
  std::unique_lock<std::mutex> hold(state->lock);
  while (state->beaten(index, calls) && calls <= state->caps[index]) {
    state->changed.wait_for(hold, std::chrono::milliseconds(50));
    if (give_up()) return;
  }
}

ContactPlanner::Portfolio::Portfolio(const Scenario& scenario, const PlannerParameters& params)
    : mode(params.portfolio_mode), max_seconds(params.max_seconds) {
  const int n = static_cast<int>(params.portfolio.size());
  const bool in_turn = mode == PlannerParameters::PortfolioMode::Sequence;
  // Shared by the members when there is no factory of verifiers, and for
  // the caller's trace: one call at a time.
  auto verify_lock = std::make_shared<std::mutex>();
  auto trace_lock = std::make_shared<std::mutex>();
  for (const PlannerVariant& v : params.portfolio) {
    for (const std::string& other : names)
      if (other == v.name) throw std::invalid_argument("portfolio: two members named \"" + v.name + "\"");
    PlannerParameters p = params;
    p.portfolio.clear();
    // The verifier before the member's changes, so that a member may bring its own.
    if (p.verify_transitions && p.make_verifier) {
      p.verify_plan = p.make_verifier();
    } else if (p.verify_plan) {
      PlanVerifier shared = p.verify_plan;
      p.verify_plan = [verify_lock, shared](const Plan& plan, const std::atomic<bool>& stop) {
        std::lock_guard<std::mutex> hold(*verify_lock);
        return shared(plan, stop);
      };
    }
    if (v.apply) v.apply(p);
    if (!p.portfolio.empty())
      throw std::invalid_argument("portfolio member \"" + v.name + "\": a member cannot hold a portfolio");
    p.threads = in_turn ? params.threads : std::max(1, params.threads / n);
    if (p.trace) {
      auto trace = p.trace;
      const std::string prefix = "[" + v.name + "] ";
      p.trace = [trace_lock, trace, prefix](const std::string& line) {
        std::lock_guard<std::mutex> hold(*trace_lock);
        trace(prefix + line);
      };
    }
    names.push_back(v.name);
    members.push_back(std::make_unique<ContactPlanner>(scenario, std::move(p)));
  }
}

std::vector<PlanningResult> ContactPlanner::Portfolio::race(const std::atomic<bool>* cancel,
                                                           const Progress& progress) {
  const std::size_t n = members.size();
  PortfolioState state(n);
  std::atomic<bool> stop_all{false};
  std::vector<PlanningResult> results(n);
  std::vector<PlanningStats> latest(n);
  std::mutex report_lock;  // latest, the caller's progress
  std::size_t done = 0;    // under state.lock

  auto run = [&](std::size_t i) {
    auto report = [&, i](const PlanningStats& s) {
      std::lock_guard<std::mutex> hold(report_lock);
      latest[i] = s;
      if (progress) progress(combined(latest));
    };
    MemberLink link{&state, i};
    PlanningResult r = members[i]->search(&stop_all, report, &link);
    {
      std::lock_guard<std::mutex> hold(state.lock);
      if (r.solved())
        for (std::size_t j = 0; j < n; ++j)
          if (j != i) state.caps[j] = std::min(state.caps[j], PortfolioState::bound(j, i, r.stats.searchCalls()));
      state.goals[i] = LONG_MAX;
      ++done;
    }
    state.changed.notify_all();
    std::lock_guard<std::mutex> hold(report_lock);
    latest[i] = r.stats;
    results[i] = std::move(r);
  };
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < n; ++i) threads.emplace_back(run, i);
  {
    // The caller's cancel, passed on to every member.
    std::unique_lock<std::mutex> hold(state.lock);
    while (done < n) {
      state.changed.wait_for(hold, std::chrono::milliseconds(50));
      if (cancel && cancel->load()) stop_all = true;
    }
  }
  for (auto& t : threads) t.join();
  return results;
}

std::vector<PlanningResult> ContactPlanner::Portfolio::inTurn(const std::atomic<bool>* cancel,
                                                             const Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<PlanningResult> results;
  std::vector<PlanningStats> latest(members.size());
  for (std::size_t i = 0; i < members.size(); ++i) {
    const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // A member after one that spent the time budget (or was cancelled) is not run.
    if (i > 0 && (spent >= max_seconds || (cancel && cancel->load()))) break;
    // Earlier members' time is spent: each starts with what is left.
    members[i]->setTimeBudget(max_seconds - spent);
    auto report = [&, i](const PlanningStats& s) {
      latest[i] = s;
      latest[i].seconds += spent;  // the caller's clock: the sequence's
      if (progress) progress(combined(latest));
    };
    results.push_back(members[i]->search(cancel, report, nullptr));
    latest[i] = results.back().stats;
    if (results.back().solved()) break;
  }
  return results;
}

PlanningResult ContactPlanner::Portfolio::plan(const std::atomic<bool>* cancel, const Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<PlanningResult> results =
      mode == PlannerParameters::PortfolioMode::Sequence ? inTurn(cancel, progress) : race(cancel, progress);
  const std::size_t n = results.size();
  std::vector<PlanningStats> latest;
  for (const PlanningResult& r : results) latest.push_back(r.stats);

  int winner = -1;
  for (std::size_t i = 0; i < n; ++i)
    if (results[i].solved() &&
        (winner < 0 || results[i].stats.searchCalls() < results[winner].stats.searchCalls()))
      winner = static_cast<int>(i);
  std::vector<PlanningResult::Member> outcomes;
  for (std::size_t i = 0; i < n; ++i)
    outcomes.push_back({names[i], results[i].status, results[i].reason, results[i].stats});
  PlanningResult out;
  if (winner >= 0) {
    out = std::move(results[winner]);
  } else {
    // None solved: the first member's status in a race (a cancel is every
    // member's), the last one's in a sequence (its budget, the time, a
    // cancel), every member's reason, their counts summed.
    out.status = mode == PlannerParameters::PortfolioMode::Sequence ? results.back().status : results[0].status;
    for (std::size_t i = 0; i < n; ++i)
      out.reason += (i ? "; " : "") + names[i] + ": " + results[i].reason;
    out.stats = combined(latest);
  }
  // Every member's refused plans, the winner's first, each with its
  // member's name: a refusal is worth reading whichever member met it (a
  // refused plan of a member that lost, or of members none of which solved,
  // was lost before, --keep-refused included).
  out.refusal_members.assign(out.refusals.size(), winner >= 0 ? names[winner] : std::string());
  for (std::size_t i = 0; i < n; ++i) {
    if (static_cast<int>(i) == winner) continue;
    for (const std::string& s : results[i].refusals) {
      out.refusals.push_back(s);
      out.refusal_members.push_back(names[i]);
    }
    for (RefusedPlan& rp : results[i].refused_plans) out.refused_plans.push_back(std::move(rp));
  }
  out.members = std::move(outcomes);
  out.winner = winner;
  // The wall time the caller waited: every member stopped.
  out.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (winner >= 0) out.plan.stats.seconds = out.stats.seconds;
  if (progress) progress(out.stats);
  return out;
}

}  // namespace acyclic
