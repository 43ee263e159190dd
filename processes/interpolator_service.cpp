#include "processes/interpolator_service.h"

#include <memory>

#include "acyclic/cancel_t.hpp"
#include "acyclic/plan_t.hpp"
#include "acyclic/progress_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "lcmtypes/channels.hpp"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"

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
  InterpolatorService(proc::Bus& bus, InterpolatorOptionsFor o) : proc::Service(bus, kProcess), options_(std::move(o)) {
    bus.lcm().subscribe(channels::kPlan, &InterpolatorService::onPlan, this);
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
    proc::log(kProcess, "request " + std::to_string(m.request_id) + ": interpolating " +
                            std::to_string(plan->stances.size()) + " stances");
    status_.busy(m.request_id);
    const std::int64_t id = m.request_id;
    worker_.start(id, [this, id, sc, plan](const std::atomic<bool>& cancel) {
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
        const InterpolationResult r = interpolate(*plan, *sc, options_(*sc), progress, &cancel);
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

  InterpolatorOptionsFor options_;
};

}  // namespace

int serveInterpolator(const std::string& lcm_url, const InterpolatorOptionsFor& options) {
  return proc::serve<InterpolatorService>(lcm_url, kProcess, channels::kPlan, options);
}

}  // namespace acyclic
