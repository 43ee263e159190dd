#include "processes/planner_service.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include "acyclic/cancel_t.hpp"
#include "acyclic/guide_t.hpp"
#include "acyclic/plan_t.hpp"
#include "acyclic/progress_t.hpp"
#include "acyclic/request_t.hpp"
#include "lcmtypes/channels.hpp"
#ifdef ACYCLIC_HAVE_INTERPOLATOR
#include "interpolator/plan_verifier.h"
#include "processes/transitions_message.h"
#endif
#include "planner/search/planner_parameters.h"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"

namespace acyclic {

namespace {
#ifdef ACYCLIC_HAVE_INTERPOLATOR
constexpr bool kVerifyTransitionsByDefault = true;
#else
constexpr bool kVerifyTransitionsByDefault = false;  // nothing to verify with
#endif
}  // namespace

PlannerParameters PlannerOverrides::apply(Scenario& sc, double request_budget_s,
                                          std::shared_ptr<TransitionMemo>* memo) const {
  setPlannerKeys(sc, set);
  if (seed >= 0) sc.seed = static_cast<std::uint64_t>(seed);
  PlannerParameters p = plannerParameters(sc);
  if (!member.empty()) keepPortfolioMember(p, member, sc.name);
  if (request_budget_s > 0) p.max_seconds = request_budget_s;
  if (max_seconds > 0) p.max_seconds = max_seconds;
  if (max_nodes > 0) p.max_nodes = max_nodes;
  if (max_posture_calls > 0) p.max_posture_calls = max_posture_calls;
  if (threads > 0) p.threads = threads;
  p.lazy_sons = !eager_sons;
  p.optimized_candidates = !random_candidates;
  p.guide_potential = !distance_to_goal;
  if (no_failure_memory) p.failure_memory = false;
  if (no_swing_check) p.swing_check = false;
  // Verification is on unless the scenario (planner: verify_transitions) or
  // the command line says otherwise: a plan the interpolator cannot
  // interpolate is no answer for the pipeline.
  const bool scenario_says = sc.planner_section && sc.planner_section->has("verify_transitions");
  if (verify_transitions >= 0) p.verify_transitions = verify_transitions == 1;
  else if (!scenario_says) p.verify_transitions = kVerifyTransitionsByDefault;
  if (verify_on_expansion >= 0) p.verify_on_expansion = verify_on_expansion == 1;
#ifdef ACYCLIC_HAVE_INTERPOLATOR
  if (memo) {
    *memo = std::make_shared<TransitionMemo>(withScenarioMargins(sc, {}));
    attachPlanVerifier(p, sc, *memo);
  } else {
    attachPlanVerifier(p, sc);
  }
#else
  if (p.verify_transitions)
    throw std::invalid_argument("verify_transitions: this build has no interpolator to verify transitions with");
  if (memo) throw std::invalid_argument("this build has no interpolator to make a trajectory with");
#endif
  if (verbose) p.trace = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  return p;
}

namespace {

const char* kProcess = "acyclic-planner";

int8_t planStatus(PlanningResult::Status s) {
  switch (s) {
    case PlanningResult::Status::Solved: return plan_t::OK;
    case PlanningResult::Status::NoSolution: return plan_t::NO_SOLUTION;
    case PlanningResult::Status::NodeBudget:
    case PlanningResult::Status::PostureBudget: return plan_t::BUDGET_EXHAUSTED;
    case PlanningResult::Status::TimeLimit: return plan_t::TIMEOUT;
    case PlanningResult::Status::Cancelled: return plan_t::CANCELLED;
    case PlanningResult::Status::InvalidInput: return plan_t::INVALID_INPUT;
  }
  return plan_t::ERROR;
}

class PlannerService : public proc::Service {
 public:
  PlannerService(proc::Bus& bus, PlannerOverrides o) : proc::Service(bus, kProcess), overrides_(o) {
    bus.lcm().subscribe(channels::kRequest, &PlannerService::onRequest, this);
    bus.lcm().subscribe(channels::kCancel, &PlannerService::onCancel, this);
    bus.lcm().subscribe(channels::kGuide, &PlannerService::onGuide, this);
    status_.ready();
  }
  void tick() override {
    proc::Service::tick();
    if (waiting_ && proc::nowMicros() - waiting_->since_us > kGuideTimeoutUs) {
      const request_t req = waiting_->req;
      const std::string early = waiting_->early_guide;
      waiting_.reset();
      refuse(req, plan_t::NO_SOLUTION,
             "no ACYCLIC_GUIDE arrived within " + std::to_string(kGuideTimeoutUs / 1000000) +
                 " s for a scenario without key postures (is acyclic-guide running?)" +
                 (early.empty() ? "" : "; one with its id came before the request and was not used: " + early));
      status_.idle();
    }
  }
  void stop() override {
    if (worker_.busy()) proc::log(kProcess, "stopping: cancelling request " + std::to_string(worker_.current()));
    proc::Service::stop();
  }

 private:
  // A request's parameters, and the memo its verification keeps the motion
  // of what it solves in (none without the interpolator): sent with the plan.
  struct Setup {
    PlannerParameters params;
    std::shared_ptr<TransitionMemo> memo;
  };

  // An answer without a plan: refused, invalid input, error.
  void refuse(const request_t& req, int8_t code, const std::string& reason) {
    status_.error(req.request_id, reason);
    plan_t m{};
    m.utime = proc::nowMicros();
    m.request_id = req.request_id;
    m.status = code;
    m.reason = reason;
    m.scenario_name = req.scenario_name;
    bus_.publish(channels::kPlan, m);
  }

  void onRequest(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    request_t req;
    if (!proc::decode(rb, channel, req, status_)) return;
    if (worker_.busy() || waiting_) {
      refuse(req, plan_t::ERROR,
             proc::busyRefusal(worker_.busy() ? worker_.current() : waiting_->req.request_id, "request"));
      return;
    }
    // "<= 0: the scenario's" must not swallow a NaN, nor inf buy an endless search.
    if (!std::isfinite(req.time_budget_s) || req.time_budget_s > kMaxBudgetS) {
      refuse(req, plan_t::INVALID_INPUT,
             "time_budget_s " + std::to_string(req.time_budget_s) +
                 ": expected a finite number of seconds, at most " + std::to_string(static_cast<long>(kMaxBudgetS)) +
                 " (<= 0: the scenario's)");
      return;
    }
    auto sc = std::make_shared<Scenario>();
    Setup setup;
    PlannerParameters& params = setup.params;
    try {
      *sc = Scenario::loadText(req.scenario_yaml,
                               "request " + std::to_string(req.request_id) + " (" + req.scenario_name + ")",
                               req.base_path);
      if (req.seed >= 0) sc->seed = static_cast<std::uint64_t>(req.seed);
#ifdef ACYCLIC_HAVE_INTERPOLATOR
      // The verification keeps the motion of what it solves, for the interpolator.
      params = overrides_.apply(*sc, req.time_budget_s, &setup.memo);
#else
      params = overrides_.apply(*sc, req.time_budget_s);
#endif
    } catch (const std::exception& e) {
      refuse(req, plan_t::INVALID_INPUT, std::string("the scenario does not load: ") + e.what());
      return;
    }
    if (sc->key_postures.size() < 2 && params.guide_potential) {
      // No hand-written guide: the guide process authors one (ACYCLIC_GUIDE).
      status_.busy(req.request_id);
      // A guide that came before its request is used only when it is a
      // guide of this request's robot: another sender's message with the same
      // id (a stale run, a fuzzer: CI once planned request 8 on a mangled
      // guide of 2 joints) must not answer it. Otherwise wait for the guide
      // process's own answer, keeping the early one's word for the timeout.
      std::string early;
      const auto g = guides_.find(req.request_id);
      if (g != guides_.end()) {
        const guide_t guide = std::move(g->second);
        guides_.erase(g);
        std::vector<Configuration> postures;
        early = earlyGuideProblem(guide, *sc, postures);
        if (early.empty()) {
          planOnGuide(req, sc, setup, guide, postures);
          return;
        }
        status_.error(req.request_id, "an ACYCLIC_GUIDE with its id came before it and is not used: " + early);
      }
      proc::log(kProcess, "request " + std::to_string(req.request_id) + ": " + sc->name +
                              " has no key postures: waiting for its ACYCLIC_GUIDE");
      waiting_ = Waiting{req, sc, setup, proc::nowMicros(), early};
      return;
    }
    startPlanning(req, sc, setup);
  }

  // A guide's key postures for the scenario; throws FormatError naming the field.
  static std::vector<Configuration> guidePostures(const guide_t& g, const Scenario& sc) {
    std::vector<Configuration> out;
    for (const auto& m : g.postures)
      out.push_back(convert::fromMessage(m, sc, "ACYCLIC_GUIDE (request " + std::to_string(g.request_id) + ")"));
    return out;
  }
  // Why a guide received before its request is not taken as its answer
  // (empty: it is, its key postures in `q`): not OK, key postures that are
  // not the scenario's robot's, or that do not start at the scenario's start
  // (the guide author's first key posture is the start exactly).
  static std::string earlyGuideProblem(const guide_t& g, const Scenario& sc, std::vector<Configuration>& q) {
    if (g.status != guide_t::OK) return "status " + std::to_string(g.status) + ": " + g.reason;
    try {
      q = guidePostures(g, sc);
    } catch (const std::exception& e) {
      return e.what();
    }
    if (q.size() < 2) return "fewer than 2 key postures";
    const Configuration& a = q.front();
    if ((a.base_position - sc.start.base_position).norm() > 1e-9 ||
        a.base_orientation.angularDistance(sc.start.base_orientation) > 1e-9 ||
        (a.joints - sc.start.joints).norm() > 1e-9)
      return "its first key posture is not the scenario's start";
    return "";
  }

  void useGuide(const request_t& req, const std::shared_ptr<Scenario>& sc, const Setup& setup, const guide_t& g) {
    if (g.status != guide_t::OK) {
      refuse(req, plan_t::NO_SOLUTION, "no guide: " + g.reason);
      status_.idle();
      return;
    }
    std::vector<Configuration> q;
    try {
      q = guidePostures(g, *sc);
    } catch (const std::exception& e) {
      refuse(req, plan_t::INVALID_INPUT, std::string("the guide cannot be read: ") + e.what());
      status_.idle();
      return;
    }
    planOnGuide(req, sc, setup, g, q);
  }
  // The guide's key postures (read from g) into the scenario, then the search.
  void planOnGuide(const request_t& req, const std::shared_ptr<Scenario>& sc, const Setup& setup, const guide_t& g,
                   const std::vector<Configuration>& postures) {
    sc->key_postures.insert(sc->key_postures.end(), postures.begin(), postures.end());
    proc::log(kProcess, "request " + std::to_string(req.request_id) + ": guide of " +
                            std::to_string(g.num_postures) + " key postures (" + g.source + ")");
    startPlanning(req, sc, setup);
  }

  void onGuide(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    guide_t g;
    if (!proc::decode(rb, channel, g, status_)) return;
    if (waiting_ && waiting_->req.request_id == g.request_id) {
      const Waiting w = *waiting_;
      waiting_.reset();
      useGuide(w.req, w.sc, w.setup, g);
      return;
    }
    guides_[g.request_id] = g;  // it may come before its request
    while (guides_.size() > 16) guides_.erase(guides_.begin());
  }

  void startPlanning(const request_t& req, const std::shared_ptr<Scenario>& sc, const Setup& setup) {
    proc::log(kProcess, "request " + std::to_string(req.request_id) + ": planning " + sc->name);
    status_.busy(req.request_id);
    const PlannerParameters params = setup.params;
    const std::shared_ptr<TransitionMemo> memo = setup.memo;
    worker_.start(req.request_id, [this, req, sc, params, memo](const std::atomic<bool>& cancel) {
      plan_t m{};
#ifdef ACYCLIC_HAVE_INTERPOLATOR
      std::optional<transitions_t> transitions;  // sent just before the plan
#endif
      try {
        ContactPlanner planner(*sc, params);
        std::int64_t last_progress = 0;
        auto progress = [&](const PlanningStats& s) {
          const std::int64_t now = proc::nowMicros();
          if (now - last_progress < 250000 && !s.verifying) return;  // 4 Hz at most
          last_progress = now;
          progress_t p{};
          p.utime = now;
          p.request_id = req.request_id;
          p.source = kProcess;
          p.stage = s.verifying ? "verifying transitions" : "search";
          p.fraction = params.max_seconds > 0 ? std::min(1.0, s.seconds / params.max_seconds) : -1;
          p.nodes_generated = s.nodes_generated;
          p.posture_calls = s.posture_calls;
          p.best_potential = s.best_potential;
          p.elapsed_s = s.seconds;
          p.message = std::to_string(s.nodes_expanded) + " nodes expanded, " + std::to_string(s.posture_failures) +
                      " posture calls failed";
          bus_.publish(channels::kProgress, p);
        };
        const PlanningResult r = planner.plan(&cancel, progress);
        if (r.solved()) {
          Plan plan = r.plan;
          plan.scenario = req.scenario_name;
          m = convert::toMessage(plan, *sc);
#ifdef ACYCLIC_HAVE_INTERPOLATOR
          if (memo) {
            const auto known = convert::transitionsToSend(m, *sc, *memo);
            if (!known.empty()) transitions = convert::toMessage(known, memo->options(), *sc);
          }
#endif
        }
        m.status = planStatus(r.status);
        m.reason = r.reason;
        m.nodes_generated = r.stats.nodes_generated;
        m.nodes_expanded = r.stats.nodes_expanded;
        m.posture_calls = r.stats.posture_calls;
        m.posture_failures = r.stats.posture_failures;
        m.seconds = r.stats.seconds;
        proc::log(kProcess, "request " + std::to_string(req.request_id) + ": " + toString(r.status) + " in " +
                                std::to_string(r.stats.seconds) + " s, " + std::to_string(r.stats.nodes_generated) +
                                " nodes" + (r.solved() ? ", " + std::to_string(m.num_stances) + " stances" : ""));
        // A cancellation was asked for: not an error.
        if (!r.solved() && r.status != PlanningResult::Status::Cancelled)
          status_.error(req.request_id, std::string(toString(r.status)) + ": " + r.reason);
      } catch (const std::exception& e) {
        m = plan_t{};
        m.status = plan_t::ERROR;
        m.reason = e.what();
        status_.error(req.request_id, e.what());
      }
      m.utime = proc::nowMicros();
      m.request_id = req.request_id;
      m.scenario_name = req.scenario_name;
      m.scenario_yaml = req.scenario_yaml;
      m.base_path = req.base_path;
      if (worker_.abandoned()) return;  // stopping: no answer for unfinished work
#ifdef ACYCLIC_HAVE_INTERPOLATOR
      // Before the plan, so that the interpolator has them when the plan comes.
      if (transitions && m.status == plan_t::OK) {
        transitions->utime = proc::nowMicros();
        transitions->request_id = req.request_id;
        proc::log(kProcess, "request " + std::to_string(req.request_id) + ": " +
                                std::to_string(transitions->num_transitions) + " verified transitions sent");
        bus_.publish(channels::kTransitions, *transitions);
      }
#endif
      bus_.publish(channels::kPlan, m);
      status_.served();
      status_.idle();
    });
  }

  void onCancel(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    cancel_t c;
    if (!proc::decode(rb, channel, c, status_)) return;
    if (waiting_ && (c.request_id == -1 || c.request_id == waiting_->req.request_id)) {
      const request_t req = waiting_->req;
      waiting_.reset();
      refuse(req, plan_t::CANCELLED, "cancelled while waiting for its guide");
      status_.idle();
      return;
    }
    if (worker_.cancel(c.request_id))
      proc::log(kProcess, "request " + std::to_string(worker_.current()) + ": cancelled (" + c.reason + ")");
    else
      status_.error(c.request_id, "cancel: request " + std::to_string(c.request_id) + " is not running");
  }

  struct Waiting {
    request_t req;
    std::shared_ptr<Scenario> sc;
    Setup setup;
    std::int64_t since_us;
    std::string early_guide;  // why a guide with its id that came before it was not used
  };
  static constexpr std::int64_t kGuideTimeoutUs = 60'000'000;
  static constexpr double kMaxBudgetS = 7 * 24 * 3600.0;  // a week

  PlannerOverrides overrides_;
  std::optional<Waiting> waiting_;            // a request waiting for its guide
  std::map<std::int64_t, guide_t> guides_;    // guides received before their request
};

}  // namespace

int servePlanner(const std::string& lcm_url, const PlannerOverrides& overrides) {
  return proc::serve<PlannerService>(lcm_url, kProcess, channels::kRequest, overrides);
}

}  // namespace acyclic
