// acyclic-hrp2-bridge: streams a trajectory to HRP-2's controller safely
// (hrp2_bridge/bridge.h: limits, start guard, watchdogs, e-stop, stabilizer
// schedule). Subscribes ACYCLIC_TRAJECTORY, HRP2_STATE (latest only) and
// HRP2_ESTOP; publishes HRP2_COMMAND every controller period (absolute
// CLOCK_MONOTONIC deadlines) while it commands the robot, and
// HRP2_BRIDGE_STATUS at a steady rate and on every change of state.
// Exit: 0 on SIGINT/SIGTERM (LCM mode) or when the file's trajectory has been
// played (file mode); 1 the file's trajectory refused or not played to the
// end; 2 bad input; 3 LCM failure.
#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <cstdio>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "processes/command_line.h"
#include "acyclic/hrp2_bridge_status_t.hpp"
#include "acyclic/hrp2_command_t.hpp"
#include "acyclic/hrp2_estop_t.hpp"
#include "acyclic/hrp2_state_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "channels.hpp"
#include "hrp2_bridge/bridge.h"
#include "hrp2_bridge/contract_check.h"
#include "hrp2_bridge/periodic_loop.h"
#include "hrp2_bridge/trajectory_file.h"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"

namespace {

using namespace acyclic;
const char* kName = "acyclic-hrp2-bridge";

template <class F>
struct Handler {
  F f;
  void handle(const lcm::ReceiveBuffer* rb, const std::string&) { f(rb); }
};
template <class F>
std::unique_ptr<Handler<F>> subscribe(proc::Bus& bus, const char* channel, F f) {
  auto h = std::make_unique<Handler<F>>(Handler<F>{std::move(f)});
  bus.lcm().subscribe(channel, &Handler<F>::handle, h.get());
  return h;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Streams a whole-body trajectory to HRP-2's controller. Subscribes ACYCLIC_TRAJECTORY, HRP2_STATE (the\n"
      "latest only) and HRP2_ESTOP; publishes HRP2_COMMAND every controller period while it commands the\n"
      "robot, HRP2_BRIDGE_STATUS (idle, checking, streaming, holding, stopped, fault) at a steady rate and\n"
      "ACYCLIC_STATUS at 1 Hz. Before streaming: joint positions, velocities and steps against the model's\n"
      "limits (refused with the reason, never clamped), the validity contract (every sample a valid posture\n"
      "with its contacts; check_contract in the configuration), the start against the measured posture, and the\n"
      "start guard (servo on, robot at rest, no other command source). While streaming: stale state or a\n"
      "stalled controller -> holding; tracking error or a bad measured state -> fault; HRP2_ESTOP engage\n"
      "freezes, release blends back. A trajectory that arrives while one is checked or streamed is refused,\n"
      "not queued (send it again when the bridge reports idle). Holding and fault last until an e-stop\n"
      "engage and release (reset) or, when holding, a new trajectory.\n"
      "File mode: --trajectory FILE streams that file (once a robot state has arrived) and exits.\n"
      "Exit status: 0 on SIGINT/SIGTERM (LCM mode) or when the file's trajectory has been played; 1 the\n"
      "file's trajectory refused or not played to the end; 2 bad input; 3 LCM failure."};
  std::string scenario_path, trajectory_path, config_path, url = proc::defaultLcmUrl();
  double dt = 0, wait_state = 5.0;
  int zmp_stride = 10, rt_priority = 20, cpu = -1;
  std::int64_t file_request_id = 1;
  app.add_option("--scenario", scenario_path,
                 "scenario (robot and scene); required in LCM mode, default in file mode: the trajectory's own");
  app.add_option("--trajectory", trajectory_path, "file mode: stream this trajectory file (acyclic.trajectory/1)");
  app.add_option("--request-id", file_request_id, "file mode: the request id its commands carry (default 1)");
  app.add_option("--config", config_path, "bridge configuration (acyclic.hrp2_bridge/1; README \"HRP-2 bridge\")");
  app.add_option("--dt", dt, "controller period, s (default: the configuration's, else 0.005)");
  app.add_option("--wait-state", wait_state, "file mode: seconds to wait for the first HRP2_STATE (default 5)");
  app.add_option("--zmp-stride", zmp_stride, "quasi-static LP every N samples, interpolated between (default 10)")
      ->check(CLI::PositiveNumber);
  app.add_option("--rt-priority", rt_priority,
                 "SCHED_FIFO priority of the control loop and LCM receive threads, 0: none (default 20; when not\n"
                 "permitted the bridge says so and runs at normal priority)")
      ->check(CLI::Range(0, 99));
  app.add_option("--cpu", cpu, "run on this CPU only (default: any); e.g. the one the planner does not use");
  bool lcm_flag = false;
  app.add_flag("--lcm", lcm_flag, "accepted for symmetry with the other processes (LCM mode is the default without --trajectory)");
  app.add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  const bool file_mode = !trajectory_path.empty();
  if (file_mode && lcm_flag) {
    std::fprintf(stderr, "%s: --lcm and --trajectory exclude each other\n", kName);
    return 2;
  }
  hrp2::BridgeConfig cfg;
  Scenario sc;
  Trajectory file_trajectory;
  try {
    if (!config_path.empty()) cfg = hrp2::BridgeConfig::load(config_path);
    if (dt != 0) cfg.dt = dt;
    cfg.validate();
    if (file_mode) {
      hrp2::LoadedTrajectory lt = hrp2::loadTrajectoryFile(trajectory_path, scenario_path);
      sc = std::move(lt.scenario);
      file_trajectory = std::move(lt.trajectory);
    } else {
      if (scenario_path.empty()) throw std::invalid_argument("give --scenario (LCM mode) or --trajectory (file mode)");
      sc = Scenario::load(scenario_path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", kName, e.what());
    return 2;
  }

  proc::installSignalHandlers();
  // Real time before LCM starts its threads, so that they inherit it; the
  // heavy threads (checks, trajectory intake) drop it.
  if (cpu >= 0) {
    std::string why;
    if (!hrp2::pinToCpu(cpu, &why)) {
      std::fprintf(stderr, "%s: --cpu %d: %s\n", kName, cpu, why.c_str());
      return 2;
    }
  }
  const std::string rt_note = hrp2::enterRealtime(rt_priority);
  std::unique_ptr<proc::Bus> bus;
  try {
    bus = std::make_unique<proc::Bus>(url);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", kName, e.what());
    return 3;
  }
  proc::StatusReporter status(*bus, kName);
  hrp2::Bridge bridge(sc.robot, cfg);
  std::mutex mutex;  // the bridge, between the LCM thread, the checks and the control loop
  std::atomic<bool> got_state{false};
  const int n = sc.robot->numJoints();
  hrp2::PrepareOptions popt;
  popt.zmp_stride = zmp_stride;

  // Checks run on their own threads (a long trajectory's references take a
  // while) so that the loop keeps its period; at most one is current.
  std::list<std::pair<std::thread, std::shared_ptr<std::atomic<bool>>>> checks;
  auto submit = [&](std::int64_t id, Trajectory tr) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (!bridge.beginCheck(id, hrp2::monotonicMicros())) return;  // reported by the loop (a refusal event)
    }
    auto done = std::make_shared<std::atomic<bool>>(false);
    checks.emplace_back(std::thread([&, id, done, tr = std::move(tr)] {
      hrp2::setBackgroundPriority(rt_priority > 0);
      const std::int64_t t0 = hrp2::monotonicMicros();
      hrp2::PrepareResult r;
      try {
        r = hrp2::prepareChecked(tr, sc, cfg, popt);
      } catch (const std::exception& e) {
        // A check that fails is a refusal, never the end of the bridge.
        r = hrp2::PrepareResult{};
        r.check = hrp2::CheckResult::failure(std::string("the check failed: ") + e.what());
      }
      char took[120];
      std::snprintf(took, sizeof took, "request %lld checked in %.2f s (%zu samples%s)", static_cast<long long>(id),
                    (hrp2::monotonicMicros() - t0) * 1e-6, tr.samples.size(),
                    cfg.check_contract ? ", limits and validity contract" : ", limits only");
      proc::log(kName, took);
      {
        std::lock_guard<std::mutex> lock(mutex);
        bridge.endCheck(id, std::move(r), hrp2::monotonicMicros());
      }
      *done = true;
    }), done);
  };
  std::mutex checks_mutex;  // `checks` is touched by the LCM thread and the loop

  auto h_state = subscribe(*bus, channels::kHrp2State, [&](const lcm::ReceiveBuffer* rb) {
    const std::int64_t now = hrp2::monotonicMicros();
    hrp2_state_t m;
    if (!proc::decode(rb, channels::kHrp2State, m, status)) return;
    // A wrong joint count is passed on as it is: the bridge refuses it (fault while streaming).
    const hrp2::MeasuredState s = convert::fromMessage(m);
    std::lock_guard<std::mutex> lock(mutex);
    bridge.onState(s, now);
    got_state = true;
  });
  auto h_estop = subscribe(*bus, channels::kHrp2Estop, [&](const lcm::ReceiveBuffer* rb) {
    hrp2_estop_t m;
    // An e-stop that does not decode is still an e-stop: freeze.
    static const std::string channel = std::string(channels::kHrp2Estop) + " (engaging)";
    if (!proc::decode(rb, channel, m, status)) {
      m = hrp2_estop_t{};
      m.engage = true;
      m.source = "undecodable message";
    }
    std::lock_guard<std::mutex> lock(mutex);
    bridge.onEstop(m.engage, m.source + (m.reason.empty() ? "" : ": " + m.reason), hrp2::monotonicMicros());
  });
  // Trajectories are large (tens to hundreds of kB): the LCM thread only
  // copies the bytes, and an intake thread decodes and converts them, so
  // that HRP2_STATE and HRP2_ESTOP are never queued behind one.
  std::mutex intake_mutex;
  std::condition_variable intake_cv;
  std::deque<std::vector<char>> intake;
  auto h_traj = subscribe(*bus, channels::kTrajectory, [&](const lcm::ReceiveBuffer* rb) {
    const char* data = static_cast<const char*>(rb->data);
    std::lock_guard<std::mutex> lock(intake_mutex);
    intake.emplace_back(data, data + rb->data_size);
    intake_cv.notify_one();
  });
  auto takeTrajectory = [&](const std::vector<char>& bytes) {
    trajectory_t m;
    if (!proc::decode(bytes.data(), bytes.size(), channels::kTrajectory, m, status)) return;
    if (m.status != trajectory_t::OK) {
      proc::log(kName, "request " + std::to_string(m.request_id) + ": no trajectory (" + m.reason + "): nothing to do");
      return;
    }
    Trajectory tr;
    try {
      tr = convert::fromMessage(m, sc);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      bridge.refuse(m.request_id, e.what(), hrp2::monotonicMicros());  // logged and counted by the loop
      return;
    }
    std::lock_guard<std::mutex> lock(checks_mutex);
    submit(m.request_id, std::move(tr));
  };

  std::atomic<bool> lcm_failed{false}, quit{false};
  std::thread receiver([&] {
    // A handler's failure is one message lost, never the process.
    lcm_failed = proc::spin(*bus, {}, [&] { return quit.load(); }, 20, [&](const std::string& what) {
                   status.error(-1, "a message's handler failed: " + what);
                 }) != 0;
  });
  std::thread intake_thread([&] {
    hrp2::setBackgroundPriority(rt_priority > 0);
    std::unique_lock<std::mutex> lock(intake_mutex);
    while (!quit) {
      intake_cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return !intake.empty() || quit; });
      while (!intake.empty() && !quit) {
        std::vector<char> bytes = std::move(intake.front());
        intake.pop_front();
        lock.unlock();
        try {
          takeTrajectory(bytes);
        } catch (const std::exception& e) {
          status.error(-1, std::string(channels::kTrajectory) + ": a trajectory's intake failed: " + e.what());
        }
        lock.lock();
      }
    }
  });

  proc::log(kName, "controller period " + std::to_string(cfg.dt) + " s; robot " + sc.robot->name() + ", " +
                       std::to_string(n) + " joints; " + rt_note + (cpu >= 0 ? ", CPU " + std::to_string(cpu) : "") + (file_mode ? "; file mode: " + trajectory_path : ""));
  status.idle();
  hrp2::PeriodicLoop loop(cfg.dt);
  const std::int64_t t0 = hrp2::monotonicMicros();
  std::int64_t last_status = 0;
  hrp2::BridgeState last_state = hrp2::BridgeState::Idle;
  bool file_submitted = false, file_done = false, file_failed = false;
  int exit_code = 0;
  while (!proc::stopRequested() && !lcm_failed) {
    const std::int64_t now = loop.wait();
    if (file_mode && !file_submitted) {
      if (got_state) {
        file_submitted = true;
        std::lock_guard<std::mutex> lock(checks_mutex);
        submit(file_request_id, file_trajectory);
      } else if (now - t0 > wait_state * 1e6) {
        status.error(file_request_id, "no HRP2_STATE within " + std::to_string(wait_state) + " s: nothing streamed");
        exit_code = 1;
        break;
      }
    }
    std::optional<hrp2::Command> cmd;
    std::vector<hrp2::BridgeEvent> events;
    hrp2::BridgeStatus st;
    {
      std::lock_guard<std::mutex> lock(mutex);
      cmd = bridge.tick(now);
      events = bridge.takeEvents();
      st = bridge.status(now);
    }
    if (cmd) bus->publish(channels::kHrp2Command, convert::toMessage(*cmd, proc::nowMicros()));
    for (const hrp2::BridgeEvent& e : events) {
      // Safety events and refusals: ACYCLIC_STATUS errors (and a log line); the rest: the log.
      if (e.safety || e.refused) status.error(e.request_id >= 0 ? e.request_id : st.request_id, e.text);
      else proc::log(kName, e.text);
      if (file_mode && e.request_id == file_request_id) {
        file_done |= e.done;
        file_failed |= e.refused;
      }
    }
    if (st.state != last_state || now - last_status >= cfg.status_period * 1e6) {
      bus->publish(channels::kHrp2BridgeStatus, convert::toMessage(st, proc::nowMicros()));
      last_status = now;
      if (st.state != last_state) {
        if (st.state == hrp2::BridgeState::Streaming || st.state == hrp2::BridgeState::Checking) status.busy(st.request_id);
        else if (st.state == hrp2::BridgeState::Idle) status.idle();
        last_state = st.state;
      }
    }
    status.tick();
    {
      std::lock_guard<std::mutex> lock(checks_mutex);
      for (auto it = checks.begin(); it != checks.end();)
        if (*it->second) it->first.join(), it = checks.erase(it);
        else ++it;
    }
    if (file_done || file_failed) {
      exit_code = file_done ? 0 : 1;
      break;
    }
  }
  if (file_mode && !file_done && !file_failed && exit_code == 0) exit_code = 1;  // interrupted before the end
  quit = true;
  receiver.join();
  intake_cv.notify_all();
  intake_thread.join();
  for (auto& c : checks) c.first.join();
  const hrp2::BridgeStatus st = bridge.status(hrp2::monotonicMicros());
  bus->publish(channels::kHrp2BridgeStatus, convert::toMessage(st, proc::nowMicros()));
  status.stopping();
  char summary[300];
  std::snprintf(summary, sizeof summary,
                "%s; %lld commands sent, worst tracking error %.4f rad, %lld safety events, %ld periods skipped",
                hrp2::toString(st.state), static_cast<long long>(st.commands_sent), st.tracking_error_max,
                static_cast<long long>(st.safety_events), loop.skipped());
  proc::log(kName, summary);
  if (lcm_failed) return 3;
  return exit_code;
}
