#include "processes/hrp2_sim_service.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "acyclic/hrp2_command_t.hpp"
#include "acyclic/hrp2_state_t.hpp"
#include "channels.hpp"
#include "hrp2_bridge/periodic_loop.h"
#include "hrp2_bridge/sim/dynamics_simulation.h"
#include "hrp2_bridge/trajectory_file.h"
#include "planner/common/fmt.h"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"

namespace acyclic {

namespace {
const char* kName = "acyclic-hrp2-sim";
}  // namespace

int serveSimulator(const SimServiceOptions& options) {
  hrp2::SimOptions o = options.controller;
  std::unique_ptr<hrp2::SimulatedController> sim;
  std::unique_ptr<hrp2::ContactForces> forces;
  std::unique_ptr<hrp2::DynamicsSimulator> dyn;
  try {
    o.validate();
    Scenario sc = Scenario::load(options.scenario_path);
    Configuration start = sc.start;
    if (!options.start_trajectory.empty())
      start = hrp2::loadTrajectoryFile(options.start_trajectory, options.scenario_path).trajectory.samples.at(0).q;
    sim = std::make_unique<hrp2::SimulatedController>(sc.robot, start, o);
    forces = std::make_unique<hrp2::ContactForces>(sc.robot, sc.scene);
    if (options.dynamics) {
      std::vector<std::pair<int, int>> pairs;  // every allowed spot may touch every allowed surface
      for (int spot : sc.allowed_spots)
        for (int surface : sc.allowed_surfaces) pairs.push_back({spot, surface});
      // Real time first: the explicit integrator and Simbody's default
      // stiction regularization. acyclic-simulate's cpodes at 0.001 m/s is
      // closer to Coulomb friction, but streamed at 5 ms it fell behind the
      // clock here (the bridge saw HRP2_STATE 88 ms stale).
      hrp2::DynamicsOptions d;
      d.integrator = "semi-explicit-euler2";
      d.transition_velocity = 0.01;
      dyn = std::make_unique<hrp2::DynamicsSimulator>(sc, start, d, pairs);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", kName, e.what());
    return 2;
  }
  proc::installSignalHandlers();
  const std::string rt_note = hrp2::enterRealtime(options.rt_priority);
  std::unique_ptr<proc::Bus> bus;
  try {
    bus = std::make_unique<proc::Bus>(options.lcm_url);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", kName, e.what());
    return 3;
  }
  proc::StatusReporter status(*bus, kName);
  std::mutex mutex;
  long bad_messages = 0, bad_modes = 0;
  const int n = static_cast<int>(sim->state().q.size());
  // The robot's state: the kinematic controller's, or the dynamics' driven by it.
  auto robotState = [&] {
    hrp2::SimState st = sim->state();
    if (dyn) {
      st.configuration = dyn->configuration();
      st.q = st.configuration.joints;
      st.dq = dyn->jointVelocities();
    }
    return st;
  };

  struct Handler {
    std::function<void(const lcm::ReceiveBuffer*)> f;
    void handle(const lcm::ReceiveBuffer* rb, const std::string&) { f(rb); }
  } on_command{[&](const lcm::ReceiveBuffer* rb) {
    const std::int64_t now = hrp2::monotonicMicros();
    hrp2_command_t m;
    if (!proc::decode(rb, channels::kHrp2Command, m, status)) return;
    if (m.num_joints != n) {
      if (bad_messages++ == 0)
        status.error(-1, std::string(channels::kHrp2Command) + ": a command for " + std::to_string(m.num_joints) +
                             " joints (the robot has " + std::to_string(n) + "): ignored (counted from now on)");
      return;
    }
    hrp2::SimCommand c;
    try {
      c = convert::fromMessage(m);
    } catch (const std::exception& e) {
      // An unknown mode: refused and counted, as a real controller would.
      if (bad_modes++ == 0)
        status.error(-1, std::string(channels::kHrp2Command) + ": " + e.what() + ": ignored (counted from now on)");
      return;
    }
    std::lock_guard<std::mutex> lock(mutex);
    sim->receive(c, now);
  }};
  bus->lcm().subscribe(channels::kHrp2Command, &Handler::handle, &on_command);

  std::atomic<bool> lcm_failed{false}, quit{false};
  std::thread receiver([&] {
    // A handler's failure is one message lost, never the process.
    lcm_failed = proc::spin(*bus, {}, [&] { return quit.load(); }, 20, [&](const std::string& what) {
                   status.error(-1, "a message's handler failed: " + what);
                 }) != 0;
  });
  // Contact wrenches: the LP takes milliseconds, so it runs on its own thread
  // at its own rate and the control loop attaches the latest result.
  std::mutex wrench_mutex;
  std::vector<hrp2::ContactWrench> wrenches;
  bool equilibrium = false;
  std::thread wrench_thread([&] {
    hrp2::setBackgroundPriority(options.rt_priority > 0);
    hrp2::PeriodicLoop every(options.wrench_period);
    while (!proc::stopRequested() && !quit) {
      Configuration q;
      {
        std::lock_guard<std::mutex> lock(mutex);
        q = robotState().configuration;
      }
      bool eq = false;
      auto w = forces->compute(q, &eq);
      {
        std::lock_guard<std::mutex> lock(wrench_mutex);
        wrenches = std::move(w);
        equilibrium = eq;
      }
      every.wait();
    }
  });
  proc::log(kName, "running at " + std::to_string(o.dt) + " s, " + (dyn ? "dynamics, " : "") + rt_note +
                       (o.latency > 0 ? ", latency " + std::to_string(o.latency) + " s" : "") +
                       (o.drop_rate > 0 ? ", dropping " + std::to_string(o.drop_rate) : "") +
                       (o.freeze_after >= 0 ? ", freezing " + std::to_string(o.freeze_after) + " s after the first command" : ""));
  status.idle();
  hrp2::PeriodicLoop loop(o.dt);
  const std::int64_t t0 = hrp2::monotonicMicros();
  bool announced_freeze = false, holding_missed = false;
  long refused_reported = 0;
  std::int64_t refused_reported_at = 0;
  // The work of a period against the period (the dynamics' integration mostly):
  // a simulator that does not keep up shows as stale state at the bridge.
  std::int64_t worst_work_us = 0, worst_late_us = 0;  // and the wake-ups' lateness (a stall while asleep)
  long over_period = 0, periods = 0;
  while (!proc::stopRequested() && !lcm_failed) {
    const std::int64_t now = loop.wait();
    worst_late_us = std::max(worst_late_us, now - loop.deadline());
    if (options.duration > 0 && now - t0 >= options.duration * 1e6) break;
    std::optional<hrp2_state_t> msg;
    {
      std::lock_guard<std::mutex> lock(mutex);
      sim->step(now);
      if (dyn && !sim->frozen(now)) {
        // Reached linearly over a period: the servo's reference stays continuous.
        const hrp2::SimState ref = sim->state();
        dyn->setReference(ref.q, ref.dq, o.dt);
        dyn->advanceTo((now - t0) * 1e-6);
      }
      if (!sim->frozen(now)) {
        hrp2::SimState st = robotState();
        std::lock_guard<std::mutex> wlock(wrench_mutex);
        st.wrenches = wrenches;
        st.equilibrium = equilibrium;
        msg = convert::toMessage(st, proc::nowMicros());
      }
      else if (!announced_freeze) {
        announced_freeze = true;
        proc::log(kName, "frozen (fault option): no motion, no state from now on");
      }
    }
    if (msg) bus->publish(channels::kHrp2State, *msg);
    const std::int64_t work_us = hrp2::monotonicMicros() - now;
    worst_work_us = std::max(worst_work_us, work_us);
    over_period += work_us > o.dt * 1e6;
    ++periods;
    bool holding_now;
    long refused;
    {
      std::lock_guard<std::mutex> lock(mutex);
      holding_now = sim->holdingForMissedCommands();
      refused = sim->refusedPosition() + sim->refusedVelocity();
    }
    if (holding_now && !holding_missed)
      proc::log(kName, "no HRP2_COMMAND for " + std::to_string(o.hold_after_missed) +
                           " periods: holding the last commanded posture");
    holding_missed = holding_now;
    if (refused > refused_reported && now - refused_reported_at >= 1000000) {  // once a second at most
      refused_reported_at = now;
      std::lock_guard<std::mutex> lock(mutex);
      status.error(-1, std::string(channels::kHrp2Command) + ": refused " + std::to_string(refused - refused_reported) +
                           " command(s) beyond the joint limits (" + std::to_string(sim->refusedPosition()) +
                           " position, " + std::to_string(sim->refusedVelocity()) + " velocity so far)");
      refused_reported = refused;
    }
    status.tick();
  }
  quit = true;
  receiver.join();
  wrench_thread.join();
  status.stopping();
  proc::log(kName, fmt("%.0f periods, %.0f skipped; the worst period's work took %.1f ms, ", periods, loop.skipped(),
                       worst_work_us * 1e-3) +
                       std::to_string(over_period) + fmt(" periods' work took longer than the period; the latest wake-up "
                                                         "came %.1f ms after its deadline", worst_late_us * 1e-3));
  proc::log(kName, "commands: " + std::to_string(sim->received()) + " received, " + std::to_string(sim->applied()) +
                       " applied, " + std::to_string(sim->dropped()) + " dropped, " + std::to_string(sim->rejected()) +
                       " rejected, " + std::to_string(bad_messages) + " of the wrong size, " +
                       std::to_string(bad_modes) + " with an unknown mode, " +
                       std::to_string(status.undecodableCount()) + " not decoded, " +
                       std::to_string(sim->refusedPosition()) + " beyond position limits, " +
                       std::to_string(sim->refusedVelocity()) + " beyond velocity limits, " +
                       std::to_string(sim->missedHolds()) + " holds for missed commands");
  return lcm_failed ? 3 : 0;
}

}  // namespace acyclic
