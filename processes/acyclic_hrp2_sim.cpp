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
// The runtime is processes/hrp2_sim_service.h; this is its command line.
#include <CLI/CLI.hpp>

#include "processes/command_line.h"
#include "processes/hrp2_sim_service.h"
#include "processes/lcm_process.h"

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
      "kinematic robot above. Its integration overruns some 5 ms periods (logged at exit): drive it with\n"
      "acyclic-hrp2-bridge --config hrp2_bridge/config/simulated_dynamics.yaml.\n"
      "Exit status: 0 on SIGINT/SIGTERM or after --duration, 2 bad input, 3 LCM failure."};
  SimServiceOptions options;
  options.lcm_url = proc::defaultLcmUrl();
  hrp2::SimOptions& o = options.controller;
  bool servo_off = false;
  app.add_option("--scenario", options.scenario_path, "scenario (robot, scene, start configuration)")->required();
  app.add_option("--start-trajectory", options.start_trajectory,
                 "start at this trajectory's first sample instead of the scenario's start");
  app.add_option("--dt", o.dt, "controller period, s (default 0.005)");
  app.add_option("--time-constant", o.time_constant, "joint tracking time constant, s (default 0.02)");
  app.add_option("--latency", o.latency, "fault: apply each command this long after it arrives, s (default 0)");
  app.add_option("--drop-rate", o.drop_rate, "fault: fraction of commands lost, seeded (default 0)");
  app.add_option("--seed", o.seed, "seed of the dropped commands (default 1)");
  app.add_option("--freeze-after", o.freeze_after,
                 "fault: the controller hangs (no motion, no HRP2_STATE) this long after the first command, s");
  app.add_option("--wrench-period", options.wrench_period,
                 "contact wrenches (quasi-static LP, off the control loop) every this many s (default 0.05)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--dynamics", options.dynamics,
               "dynamics simulation: the base is free and falls if the motion does not hold it (default: kinematic)");
  app.add_flag("--servo-off", servo_off, "report the servos off (the bridge must refuse to start)");
  app.add_option("--hold-after-missed", o.hold_after_missed,
                 "hold the last commanded posture (no velocity feed-forward, the base where it stands) after this\n"
                 "many periods without HRP2_COMMAND, once commands have come (the bridge died or hangs); 0: never\n"
                 "(default 20: 0.1 s at 5 ms)");
  app.add_option("--duration", options.duration, "exit after this many seconds (default: run until a signal)");
  app.add_option("--rt-priority", options.rt_priority,
                 "SCHED_FIFO priority of the control loop and LCM receive threads, 0: none (default 20; when not\n"
                 "permitted the simulator says so and runs at normal priority)")
      ->check(CLI::Range(0, 99));
  bool lcm_flag = false;
  app.add_flag("--lcm", lcm_flag, "accepted for symmetry with the other processes (the simulator always serves LCM)");
  app.add_option("--lcm-url", options.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)
  o.servo_on = !servo_off;

  return serveSimulator(options);
}
