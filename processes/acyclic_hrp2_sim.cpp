// acyclic-hrp2-sim: a simulated HRP-2 controller on LCM. Receives
// HRP2_COMMAND, tracks it with position-controlled joints (first-order law,
// velocity feed-forward, the model's velocity limits; hrp2_bridge/sim/),
// publishes HRP2_STATE at the controller rate (joints, velocities, base pose,
// contact wrenches from the quasi-static model). Fault options for tests:
// latency, dropped commands, a freeze (the controller hangs). With
// --dynamics the tracked joints are the references of a dynamics simulation
// (hrp2_bridge/sim/dynamics_simulation.h): free base, PD servos, compliant
// contact; the state is the simulated robot's.
// Exit: 0 on SIGINT/SIGTERM or at --duration, 2 bad input, 3 LCM failure.
#include <CLI/CLI.hpp>

#include <atomic>
#include <cstdio>
#include <mutex>
#include <thread>

#include "processes/command_line.h"
#include "acyclic/hrp2_command_t.hpp"
#include "acyclic/hrp2_state_t.hpp"
#include "channels.hpp"
#include "hrp2_bridge/periodic_loop.h"
#include "hrp2_bridge/sim/dynamics_simulation.h"
#include "hrp2_bridge/sim/simulated_controller.h"
#include "hrp2_bridge/trajectory_file.h"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"

namespace {

const char* kName = "acyclic-hrp2-sim";

}  // namespace

int main(int argc, char** argv) {
  using namespace acyclic;
  CLI::App app{
      "A simulated HRP-2 controller: subscribes HRP2_COMMAND, tracks it with position-controlled joints\n"
      "(first-order law with velocity feed-forward, within the model's velocity limits; the base follows\n"
      "the streamed waist reference), publishes HRP2_STATE at the controller rate with contact wrenches\n"
      "from the quasi-static model. A command of the wrong size or with a NaN is ignored and counted; like a\n"
      "real controller it refuses (and counts) a command beyond the joint position or velocity limits and\n"
      "never moves a joint past its limits (joints are kinematic: no torques, so no torque limit); when the\n"
      "command stream stops for --hold-after-missed periods it holds the last commanded posture.\n"
      "--dynamics: the robot is a dynamics simulation instead (Simbody: free base, the tracked joints as\n"
      "references of PD servos, compliant contact with the scene; see acyclic-simulate); the default is the\n"
      "kinematic robot above.\n"
      "Exit status: 0 on SIGINT/SIGTERM or after --duration, 2 bad input, 3 LCM failure."};
  std::string scenario_path, start_trajectory, url = proc::defaultLcmUrl();
  hrp2::SimOptions o;
  double wrench_period = 0.05;
  int rt_priority = 20;
  bool servo_off = false, dynamics = false;
  double duration = 0;
  app.add_option("--scenario", scenario_path, "scenario (robot, scene, start configuration)")->required();
  app.add_option("--start-trajectory", start_trajectory,
                 "start at this trajectory's first sample instead of the scenario's start");
  app.add_option("--dt", o.dt, "controller period, s (default 0.005)");
  app.add_option("--time-constant", o.time_constant, "joint tracking time constant, s (default 0.02)");
  app.add_option("--latency", o.latency, "fault: apply each command this long after it arrives, s (default 0)");
  app.add_option("--drop-rate", o.drop_rate, "fault: fraction of commands lost, seeded (default 0)");
  app.add_option("--seed", o.seed, "seed of the dropped commands (default 1)");
  app.add_option("--freeze-after", o.freeze_after,
                 "fault: the controller hangs (no motion, no HRP2_STATE) this long after the first command, s");
  app.add_option("--wrench-period", wrench_period,
                 "contact wrenches (quasi-static LP, off the control loop) every this many s (default 0.05)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--dynamics", dynamics,
               "dynamics simulation: the base is free and falls if the motion does not hold it (default: kinematic)");
  app.add_flag("--servo-off", servo_off, "report the servos off (the bridge must refuse to start)");
  app.add_option("--hold-after-missed", o.hold_after_missed,
                 "hold the last commanded posture (no velocity feed-forward, the base where it stands) after this\n"
                 "many periods without HRP2_COMMAND, once commands have come (the bridge died or hangs); 0: never\n"
                 "(default 20: 0.1 s at 5 ms)");
  app.add_option("--duration", duration, "exit after this many seconds (default: run until a signal)");
  app.add_option("--rt-priority", rt_priority,
                 "SCHED_FIFO priority of the control loop and LCM receive threads, 0: none (default 20; when not\n"
                 "permitted the simulator says so and runs at normal priority)")
      ->check(CLI::Range(0, 99));
  bool lcm_flag = false;
  app.add_flag("--lcm", lcm_flag, "accepted for symmetry with the other processes (the simulator always serves LCM)");
  app.add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)
  o.servo_on = !servo_off;

  std::unique_ptr<hrp2::SimulatedController> sim;
  std::unique_ptr<hrp2::ContactForces> forces;
  std::unique_ptr<hrp2::DynamicsSimulator> dyn;
  try {
    o.validate();
    Scenario sc = Scenario::load(scenario_path);
    Configuration start = sc.start;
    if (!start_trajectory.empty()) start = hrp2::loadTrajectoryFile(start_trajectory, scenario_path).trajectory.samples.at(0).q;
    sim = std::make_unique<hrp2::SimulatedController>(sc.robot, start, o);
    forces = std::make_unique<hrp2::ContactForces>(sc.robot, sc.scene);
    if (dynamics) {
      std::vector<std::pair<int, int>> pairs;  // every allowed spot may touch every allowed surface
      for (int spot : sc.allowed_spots)
        for (int surface : sc.allowed_surfaces) pairs.push_back({spot, surface});
      dyn = std::make_unique<hrp2::DynamicsSimulator>(sc, start, hrp2::DynamicsOptions{}, pairs);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", kName, e.what());
    return 2;
  }
  proc::installSignalHandlers();
  const std::string rt_note = hrp2::enterRealtime(rt_priority);
  std::unique_ptr<proc::Bus> bus;
  try {
    bus = std::make_unique<proc::Bus>(url);
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
    hrp2::setBackgroundPriority(rt_priority > 0);
    hrp2::PeriodicLoop every(wrench_period);
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
  while (!proc::stopRequested() && !lcm_failed) {
    const std::int64_t now = loop.wait();
    if (duration > 0 && now - t0 >= duration * 1e6) break;
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
