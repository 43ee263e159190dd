#include "processes/interpolator_service.h"

#include <algorithm>
#include <deque>
#include <memory>
#include <optional>

#include "acyclic/cancel_t.hpp"
#include "acyclic/plan_t.hpp"
#include "acyclic/progress_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "acyclic/transitions_t.hpp"
#include "interpolator/transition_memo.h"
#include "lcmtypes/channels.hpp"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"
#include "processes/transitions_message.h"

namespace acyclic {

namespace {

const char* kProcess = "acyclic-interpolator";

int8_t trajectoryStatus(InterpolationResult::Status s) {
  switch (s) {
    case InterpolationResult::Status::Success: return trajectory_t::OK;
    case InterpolationResult::Status::InvalidInput: return trajectory_t::INVALID_INPUT;
    case InterpolationResult::Status::Unrepairable:
    case InterpolationResult::Status::TransitionFailed: return trajectory_t::NO_SOLUTION;
    case InterpolationResult::Status::Cancelled: return trajectory_t::CANCELLED;
  }
  return trajectory_t::ERROR;
}

class InterpolatorService : public proc::Service {
 public:
  struct Setup {
    InterpolatorOptionsFor options;
    bool planner_transitions;
  };
  InterpolatorService(proc::Bus& bus, const Setup& setup) : proc::Service(bus, kProcess), options_(setup.options) {
    bus.lcm().subscribe(channels::kPlan, &InterpolatorService::onPlan, this);
    if (setup.planner_transitions) bus.lcm().subscribe(channels::kTransitions, &InterpolatorService::onTransitions, this);
    bus.lcm().subscribe(channels::kCancel, &InterpolatorService::onCancel, this);
    status_.ready();
  }

 private:
  void answerError(std::int64_t request_id, int8_t code, const std::string& reason) {
    status_.error(request_id, reason);
    trajectory_t m{};
    m.utime = proc::nowMicros();
    m.request_id = request_id;
    m.status = code;
    m.reason = reason;
    bus_.publish(channels::kTrajectory, m);
  }

  // Kept until the plan of the same request comes (the planner sends them
  // just before it): the last few to arrive, whatever their ids, within a
  // bound on their bytes (anyone on the bus can send them).
  void onTransitions(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    transitions_t m;
    if (!proc::decode(rb, channel, m, status_)) return;
    take(m.request_id);  // a second message for a request replaces the first
    kept_.push_back(Kept{std::move(m), rb->data_size});
    auto bytes = [&] {
      std::size_t n = 0;
      for (const Kept& k : kept_) n += k.bytes;
      return n;
    };
    while (kept_.size() > kKeptTransitions || (kept_.size() > 1 && bytes() > kKeptBytes)) kept_.pop_front();
  }
  // The transitions kept for request `id`, no longer kept (none: empty).
  std::optional<transitions_t> take(std::int64_t id) {
    const auto k = std::find_if(kept_.begin(), kept_.end(), [&](const Kept& x) { return x.message.request_id == id; });
    if (k == kept_.end()) return std::nullopt;
    std::optional<transitions_t> m = std::move(k->message);
    kept_.erase(k);
    return m;
  }

  // A memo of the planner's transitions for this plan, under these options;
  // none when it sent none, or solved them with other options, or sent a
  // message that does not read (said on ACYCLIC_STATUS: the plan is then
  // interpolated without them, to the same result).
  std::shared_ptr<TransitionMemo> plannersTransitions(std::int64_t id, const Plan& plan, const Scenario& sc,
                                                      const InterpolatorOptions& options) {
    const std::optional<transitions_t> kept = take(id);
    if (!kept) return nullptr;
    const transitions_t& m = *kept;
    const std::string what = "request " + std::to_string(id) + ": the planner's " +
                             std::to_string(m.num_transitions) + " transitions (ACYCLIC_TRANSITIONS)";
    if (m.options != outcomeOptionsText(options)) {
      proc::log(kProcess, what + " were solved with other options than this interpolator's: solving them here");
      return nullptr;
    }
    auto memo = std::make_shared<TransitionMemo>(options, true, /*check_on_use=*/true);
    try {
      convert::fillMemo(m, plan, sc, *memo);
    } catch (const std::exception& e) {
      status_.error(id, what + " not used: " + e.what());
      return nullptr;
    }
    return memo;
  }

  void onPlan(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    plan_t m;
    if (!proc::decode(rb, channel, m, status_)) return;
    if (m.status != plan_t::OK) return;  // no plan to interpolate: the planner has said why
    if (worker_.busy()) {
      answerError(m.request_id, trajectory_t::ERROR, proc::busyRefusal(worker_.current(), "plan"));
      return;
    }
    auto sc = std::make_shared<Scenario>();
    auto plan = std::make_shared<Plan>();
    try {
      *sc = Scenario::loadText(m.scenario_yaml,
                               "plan of request " + std::to_string(m.request_id) + " (" + m.scenario_name + ")",
                               m.base_path);
      *plan = convert::fromMessage(m, *sc);
    } catch (const std::exception& e) {
      answerError(m.request_id, trajectory_t::INVALID_INPUT, std::string("the plan cannot be read: ") + e.what());
      return;
    }
    const InterpolatorOptions options = options_(*sc);
    const std::shared_ptr<TransitionMemo> memo = plannersTransitions(m.request_id, *plan, *sc, options);
    proc::log(kProcess, "request " + std::to_string(m.request_id) + ": interpolating " +
                            std::to_string(plan->stances.size()) + " stances" +
                            (memo ? ", with the " + std::to_string(memo->size()) + " transitions the planner verified"
                                  : std::string()));
    status_.busy(m.request_id);
    const std::int64_t id = m.request_id;
    worker_.start(id, [this, id, sc, plan, options, memo](const std::atomic<bool>& cancel) {
      trajectory_t out{};
      try {
        std::int64_t last = 0;
        auto progress = [&](const InterpolationProgress& p) {
          const std::int64_t now = proc::nowMicros();
          if (now - last < 250000) return;
          last = now;
          progress_t msg{};
          msg.utime = now;
          msg.request_id = id;
          msg.source = kProcess;
          msg.stage = p.stage;
          msg.fraction = p.transitions > 0 ? static_cast<double>(p.transition) / p.transitions : -1;
          msg.posture_calls = p.posture_calls;
          msg.elapsed_s = p.seconds;
          msg.message = "transition " + std::to_string(p.transition) + " of " + std::to_string(p.transitions);
          bus_.publish(channels::kProgress, msg);
        };
        const InterpolationResult r = memo ? interpolate(*plan, *sc, *memo, progress, &cancel)
                                           : interpolate(*plan, *sc, options, progress, &cancel);
        if (memo)
          proc::log(kProcess, "request " + std::to_string(id) + ": " + std::to_string(r.reused) + " of " +
                                  std::to_string(r.transitions.size()) + " transitions taken from the planner's");
        // An outcome that fails its check was solved here instead: the
        // answer stands, but a planner that sends such things is wrong.
        if (r.refused > 0)
          status_.error(id, std::to_string(r.refused) + " of the planner's transitions failed their check and were "
                            "solved here; the first: " + r.refused_reason);
        if (r.success()) out = convert::toMessage(r.trajectory, *sc);
        out.status = trajectoryStatus(r.status);
        out.reason = r.reason;
        proc::log(kProcess, "request " + std::to_string(id) + ": " + toString(r.status) +
                                (r.success() ? ", " + std::to_string(out.num_samples) + " samples" : ": " + r.reason));
        if (!r.success() && r.status != InterpolationResult::Status::Cancelled)
          status_.error(id, std::string(toString(r.status)) + ": " + r.reason);
      } catch (const std::exception& e) {
        out = trajectory_t{};
        out.status = trajectory_t::ERROR;
        out.reason = e.what();
        status_.error(id, e.what());
      }
      out.utime = proc::nowMicros();
      out.request_id = id;
      if (worker_.abandoned()) return;  // stopping: no answer for unfinished work
      bus_.publish(channels::kTrajectory, out);
      status_.served();
      status_.idle();
    });
  }

  void onCancel(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    cancel_t c;
    if (!proc::decode(rb, channel, c, status_)) return;
    if (worker_.cancel(c.request_id))
      proc::log(kProcess, "request " + std::to_string(worker_.current()) + ": cancelled (" + c.reason + ")");
  }

  // chair_paper's (93 transitions) take 0.4 MB.
  static constexpr std::size_t kKeptTransitions = 4;
  static constexpr std::size_t kKeptBytes = 32u << 20;
  struct Kept {
    transitions_t message;
    std::size_t bytes;  // encoded
  };
  InterpolatorOptionsFor options_;
  std::deque<Kept> kept_;  // the planner's transitions, oldest first
};

}  // namespace

int serveInterpolator(const std::string& lcm_url, const InterpolatorOptionsFor& options, bool planner_transitions) {
  return proc::serve<InterpolatorService>(lcm_url, kProcess, channels::kPlan,
                                         InterpolatorService::Setup{options, planner_transitions});
}

}  // namespace acyclic
