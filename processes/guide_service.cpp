#include "processes/guide_service.h"

#include <memory>

#include "acyclic/cancel_t.hpp"
#include "acyclic/guide_t.hpp"
#include "acyclic/request_t.hpp"
#include "lcmtypes/channels.hpp"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"

namespace acyclic {

namespace {

const char* kProcess = "acyclic-guide";

int8_t guideStatus(GuideResult::Status s) {
  switch (s) {
    case GuideResult::Status::Success: return guide_t::OK;
    case GuideResult::Status::InvalidStart: return guide_t::INVALID_INPUT;
    case GuideResult::Status::NoGoalPosture:
    case GuideResult::Status::NoPath: return guide_t::NO_SOLUTION;
    case GuideResult::Status::Cancelled: return guide_t::CANCELLED;
  }
  return guide_t::ERROR;
}

class GuideService : public proc::Service {
 public:
  GuideService(proc::Bus& bus, GuideOptions o) : proc::Service(bus, kProcess), options_(o) {
    bus.lcm().subscribe(channels::kRequest, &GuideService::onRequest, this);
    bus.lcm().subscribe(channels::kCancel, &GuideService::onCancel, this);
    status_.ready();
  }

 private:
  void answer(guide_t m) {
    m.utime = proc::nowMicros();
    m.source = "ompl";
    bus_.publish(channels::kGuide, m);
  }
  void onRequest(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    request_t req;
    if (!proc::decode(rb, channel, req, status_)) return;
    auto sc = std::make_shared<Scenario>();
    try {
      *sc = Scenario::loadText(req.scenario_yaml,
                               "request " + std::to_string(req.request_id) + " (" + req.scenario_name + ")",
                               req.base_path);
    } catch (const std::exception& e) {
      // The planner answers this request with the same reason; the guide says it too.
      status_.error(req.request_id, std::string("the scenario does not load: ") + e.what());
      guide_t m{};
      m.request_id = req.request_id;
      m.status = guide_t::INVALID_INPUT;
      m.reason = e.what();
      answer(m);
      return;
    }
    if (sc->key_postures.size() >= 2) return;  // hand-written: the planner uses those
    if (worker_.busy()) {
      guide_t m{};
      m.request_id = req.request_id;
      m.status = guide_t::ERROR;
      m.reason = proc::busyRefusal(worker_.current(), "request");
      status_.error(req.request_id, m.reason);
      answer(m);
      return;
    }
    GuideOptions o = options_;
    o.seed = static_cast<unsigned>(req.seed >= 0 ? req.seed : static_cast<std::int64_t>(sc->seed));
    proc::log(kProcess, "request " + std::to_string(req.request_id) + ": authoring the guide of " + sc->name);
    status_.busy(req.request_id);
    const std::int64_t id = req.request_id;
    worker_.start(id, [this, id, sc, o](const std::atomic<bool>& cancel) {
      guide_t m{};
      m.request_id = id;
      try {
        const GuideResult r = authorGuide(*sc, o, &cancel);
        m.status = guideStatus(r.status);
        m.reason = r.reason;
        m.seconds = r.success() ? r.guide.seconds : r.goal_seconds + r.path_seconds;
        for (const auto& q : r.guide.key_postures) m.postures.push_back(convert::toMessage(q));
        m.num_postures = static_cast<int32_t>(m.postures.size());
        proc::log(kProcess, "request " + std::to_string(id) + ": " + toString(r.status) +
                                (r.success() ? ", " + std::to_string(m.num_postures) + " key postures"
                                             : ": " + r.reason));
        if (!r.success() && r.status != GuideResult::Status::Cancelled)
          status_.error(id, std::string(toString(r.status)) + ": " + r.reason);
      } catch (const std::exception& e) {
        m.status = guide_t::ERROR;
        m.reason = e.what();
        status_.error(id, e.what());
      }
      if (worker_.abandoned()) return;  // stopping: no answer for unfinished work
      answer(m);
      status_.served();
      status_.idle();
    });
  }
  void onCancel(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    cancel_t c;
    if (!proc::decode(rb, channel, c, status_)) return;
    worker_.cancel(c.request_id);
  }

  GuideOptions options_;
};

}  // namespace

int serveGuide(const std::string& lcm_url, const GuideOptions& options) {
  return proc::serve<GuideService>(lcm_url, kProcess, channels::kRequest, options);
}

}  // namespace acyclic
