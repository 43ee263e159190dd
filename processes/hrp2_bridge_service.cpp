#include "processes/hrp2_bridge_service.h"

#include <atomic>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "acyclic/hrp2_estop_t.hpp"
#include "channels.hpp"
#include "hrp2_bridge/bridge.h"
#include "hrp2_bridge/contract_check.h"
#include "hrp2_bridge/periodic_loop.h"
#include "hrp2_bridge/trajectory_file.h"
#include "processes/check_threads.h"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"
#include "processes/message_intake.h"

namespace acyclic {

namespace {

const char* kName = "acyclic-hrp2-bridge";

// One hrp2::Bridge between three kinds of threads: the LCM receive thread
// (robot state, e-stop), the trajectory intake and the checks, and the
// control loop (run) that ticks it every controller period.
class BridgeRuntime {
 public:
  BridgeRuntime(const BridgeServiceOptions& o, const Scenario& sc, const hrp2::BridgeConfig& cfg, proc::Bus& bus)
      : o_(o), sc_(sc), cfg_(cfg), bus_(bus), status_(bus, kName), bridge_(sc.robot, cfg),
        intake_([this](const std::vector<char>& bytes) { takeTrajectory(bytes); },
                [this] { hrp2::setBackgroundPriority(o_.rt_priority > 0); }) {
    popt_.zmp_stride = o.zmp_stride;
    bus.lcm().subscribe(channels::kHrp2State, &BridgeRuntime::onState, this);
    bus.lcm().subscribe(channels::kHrp2Estop, &BridgeRuntime::onEstop, this);
    bus.lcm().subscribe(channels::kTrajectory, &BridgeRuntime::onTrajectory, this);
  }

  // The control loop until a signal, an LCM failure or (file mode) the end
  // of `file_trajectory`. Returns the exit status.
  int run(const Trajectory* file_trajectory, const std::string& rt_note);

 private:
  void onState(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    const std::int64_t now = hrp2::monotonicMicros();
    hrp2_state_t m;
    if (!proc::decode(rb, channel, m, status_)) return;
    // A wrong joint count is passed on as it is: the bridge refuses it (fault while streaming).
    const hrp2::MeasuredState s = convert::fromMessage(m);
    std::lock_guard<std::mutex> lock(mutex_);
    bridge_.onState(s, now);
    got_state_ = true;
  }
  void onEstop(const lcm::ReceiveBuffer* rb, const std::string&) {
    hrp2_estop_t m;
    // An e-stop that does not decode is still an e-stop: freeze.
    static const std::string channel = std::string(channels::kHrp2Estop) + " (engaging)";
    if (!proc::decode(rb, channel, m, status_)) {
      m = hrp2_estop_t{};
      m.engage = true;
      m.source = "undecodable message";
    }
    std::lock_guard<std::mutex> lock(mutex_);
    bridge_.onEstop(m.engage, m.source + (m.reason.empty() ? "" : ": " + m.reason), hrp2::monotonicMicros());
  }
  void onTrajectory(const lcm::ReceiveBuffer* rb, const std::string&) { intake_.push(rb->data, rb->data_size); }
  void takeTrajectory(const std::vector<char>& bytes);
  // Checks on their own threads so that the loop keeps its period; at most
  // one is current (the bridge refuses the others).
  void submit(std::int64_t id, Trajectory tr);

  const BridgeServiceOptions o_;
  const Scenario& sc_;
  const hrp2::BridgeConfig cfg_;
  proc::Bus& bus_;
  proc::StatusReporter status_;
  hrp2::Bridge bridge_;
  std::mutex mutex_;  // the bridge, between the LCM thread, the checks and the control loop
  std::atomic<bool> got_state_{false}, quit_{false}, lcm_failed_{false};
  hrp2::PrepareOptions popt_;
  // Last: their threads stop before the rest goes.
  proc::CheckThreads checks_;
  proc::MessageIntake intake_;
};

void BridgeRuntime::takeTrajectory(const std::vector<char>& bytes) {
  try {
    trajectory_t m;
    if (!proc::decode(bytes.data(), bytes.size(), channels::kTrajectory, m, status_)) return;
    if (m.status != trajectory_t::OK) {
      proc::log(kName, "request " + std::to_string(m.request_id) + ": no trajectory (" + m.reason + "): nothing to do");
      return;
    }
    Trajectory tr;
    try {
      tr = convert::fromMessage(m, sc_);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      bridge_.refuse(m.request_id, e.what(), hrp2::monotonicMicros());  // logged and counted by the loop
      return;
    }
    submit(m.request_id, std::move(tr));
  } catch (const std::exception& e) {
    status_.error(-1, std::string(channels::kTrajectory) + ": a trajectory's intake failed: " + e.what());
  }
}

void BridgeRuntime::submit(std::int64_t id, Trajectory tr) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!bridge_.beginCheck(id, hrp2::monotonicMicros())) return;  // reported by the loop (a refusal event)
  }
  checks_.start([this, id, tr = std::move(tr)] {
    hrp2::setBackgroundPriority(o_.rt_priority > 0);
    const std::int64_t t0 = hrp2::monotonicMicros();
    hrp2::PrepareResult r;
    try {
      r = hrp2::prepareChecked(tr, sc_, cfg_, popt_);
    } catch (const std::exception& e) {
      // A check that fails is a refusal, never the end of the bridge.
      r = hrp2::PrepareResult{};
      r.check = hrp2::CheckResult::failure(std::string("the check failed: ") + e.what());
    }
    char took[120];
    std::snprintf(took, sizeof took, "request %lld checked in %.2f s (%zu samples%s)", static_cast<long long>(id),
                  (hrp2::monotonicMicros() - t0) * 1e-6, tr.samples.size(),
                  cfg_.check_contract ? ", limits and validity contract" : ", limits only");
    proc::log(kName, took);
    std::lock_guard<std::mutex> lock(mutex_);
    bridge_.endCheck(id, std::move(r), hrp2::monotonicMicros());
  });
}

int BridgeRuntime::run(const Trajectory* file_trajectory, const std::string& rt_note) {
  std::thread receiver([&] {
    // A handler's failure is one message lost, never the process.
    lcm_failed_ = proc::spin(bus_, {}, [&] { return quit_.load(); }, 20, [&](const std::string& what) {
                    status_.error(-1, "a message's handler failed: " + what);
                  }) != 0;
  });
  const bool file_mode = file_trajectory != nullptr;
  proc::log(kName, "controller period " + std::to_string(cfg_.dt) + " s; robot " + sc_.robot->name() + ", " +
                       std::to_string(sc_.robot->numJoints()) + " joints; " + rt_note +
                       (o_.cpu >= 0 ? ", CPU " + std::to_string(o_.cpu) : "") +
                       (file_mode ? "; file mode: " + o_.trajectory_path : ""));
  status_.idle();
  hrp2::PeriodicLoop loop(cfg_.dt);
  const std::int64_t t0 = hrp2::monotonicMicros();
  std::int64_t last_status = 0;
  hrp2::BridgeState last_state = hrp2::BridgeState::Idle;
  bool file_submitted = false, file_done = false, file_failed = false;
  int exit_code = 0;
  while (!proc::stopRequested() && !lcm_failed_) {
    const std::int64_t now = loop.wait();
    if (file_mode && !file_submitted) {
      if (got_state_) {
        file_submitted = true;
        submit(o_.file_request_id, *file_trajectory);
      } else if (now - t0 > o_.wait_state * 1e6) {
        status_.error(o_.file_request_id, "no HRP2_STATE within " + std::to_string(o_.wait_state) + " s: nothing streamed");
        exit_code = 1;
        break;
      }
    }
    std::optional<hrp2::Command> cmd;
    std::vector<hrp2::BridgeEvent> events;
    hrp2::BridgeStatus st;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      cmd = bridge_.tick(now);
      events = bridge_.takeEvents();
      st = bridge_.status(now);
    }
    if (cmd) bus_.publish(channels::kHrp2Command, convert::toMessage(*cmd, proc::nowMicros()));
    for (const hrp2::BridgeEvent& e : events) {
      // Safety events and refusals: ACYCLIC_STATUS errors (and a log line); the rest: the log.
      if (e.safety || e.refused) status_.error(e.request_id >= 0 ? e.request_id : st.request_id, e.text);
      else proc::log(kName, e.text);
      if (file_mode && e.request_id == o_.file_request_id) {
        file_done |= e.done;
        file_failed |= e.refused;
      }
    }
    if (st.state != last_state || now - last_status >= cfg_.status_period * 1e6) {
      bus_.publish(channels::kHrp2BridgeStatus, convert::toMessage(st, proc::nowMicros()));
      last_status = now;
      if (st.state != last_state) {
        if (st.state == hrp2::BridgeState::Streaming || st.state == hrp2::BridgeState::Checking) status_.busy(st.request_id);
        else if (st.state == hrp2::BridgeState::Idle) status_.idle();
        last_state = st.state;
      }
    }
    status_.tick();
    checks_.reap();
    if (file_done || file_failed) {
      exit_code = file_done ? 0 : 1;
      break;
    }
  }
  if (file_mode && !file_done && !file_failed && exit_code == 0) exit_code = 1;  // interrupted before the end
  quit_ = true;
  receiver.join();
  intake_.stop();
  checks_.joinAll();
  const hrp2::BridgeStatus st = bridge_.status(hrp2::monotonicMicros());
  bus_.publish(channels::kHrp2BridgeStatus, convert::toMessage(st, proc::nowMicros()));
  status_.stopping();
  char summary[300];
  std::snprintf(summary, sizeof summary,
                "%s; %lld commands sent, worst tracking error %.4f rad, %lld safety events, %ld periods skipped",
                hrp2::toString(st.state), static_cast<long long>(st.commands_sent), st.tracking_error_max,
                static_cast<long long>(st.safety_events), loop.skipped());
  proc::log(kName, summary);
  return lcm_failed_ ? 3 : exit_code;
}

}  // namespace

int serveBridge(const BridgeServiceOptions& o) {
  const bool file_mode = !o.trajectory_path.empty();
  hrp2::BridgeConfig cfg;
  Scenario sc;
  Trajectory file_trajectory;
  try {
    if (!o.config_path.empty()) cfg = hrp2::BridgeConfig::load(o.config_path);
    if (o.dt != 0) cfg.dt = o.dt;
    cfg.validate();
    if (file_mode) {
      hrp2::LoadedTrajectory lt = hrp2::loadTrajectoryFile(o.trajectory_path, o.scenario_path);
      sc = std::move(lt.scenario);
      file_trajectory = std::move(lt.trajectory);
    } else {
      if (o.scenario_path.empty()) throw std::invalid_argument("give --scenario (LCM mode) or --trajectory (file mode)");
      sc = Scenario::load(o.scenario_path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", kName, e.what());
    return 2;
  }

  proc::installSignalHandlers();
  // Real time before LCM starts its threads, so that they inherit it; the
  // heavy threads (checks, trajectory intake) drop it.
  if (o.cpu >= 0) {
    std::string why;
    if (!hrp2::pinToCpu(o.cpu, &why)) {
      std::fprintf(stderr, "%s: --cpu %d: %s\n", kName, o.cpu, why.c_str());
      return 2;
    }
  }
  const std::string rt_note = hrp2::enterRealtime(o.rt_priority);
  std::unique_ptr<proc::Bus> bus;
  try {
    bus = std::make_unique<proc::Bus>(o.lcm_url);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", kName, e.what());
    return 3;
  }
  BridgeRuntime runtime(o, sc, cfg, *bus);
  return runtime.run(file_mode ? &file_trajectory : nullptr, rt_note);
}

}  // namespace acyclic
