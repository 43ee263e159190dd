// acyclic-hrp2-bridge: streams a trajectory to HRP-2's controller safely
// (hrp2_bridge/bridge.h: limits, start guard, watchdogs, e-stop, stabilizer
// schedule). Subscribes ACYCLIC_TRAJECTORY, HRP2_STATE (latest only) and
// HRP2_ESTOP; publishes HRP2_COMMAND every controller period (absolute
// CLOCK_MONOTONIC deadlines) while it commands the robot, and
// HRP2_BRIDGE_STATUS at a steady rate and on every change of state.
// Exit: 0 on SIGINT/SIGTERM (LCM mode) or when the file's trajectory has been
// played (file mode); 1 the file's trajectory refused or not played to the
// end; 2 bad input; 3 LCM failure.
// The runtime is processes/hrp2_bridge_service.h; this is its command line.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "processes/command_line.h"
#include "processes/hrp2_bridge_service.h"
#include "processes/lcm_process.h"

using namespace acyclic;

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
  BridgeServiceOptions o;
  o.lcm_url = proc::defaultLcmUrl();
  app.add_option("--scenario", o.scenario_path,
                 "scenario (robot and scene); required in LCM mode, default in file mode: the trajectory's own");
  app.add_option("--trajectory", o.trajectory_path, "file mode: stream this trajectory file (acyclic.trajectory/1)");
  app.add_option("--request-id", o.file_request_id, "file mode: the request id its commands carry (default 1)");
  app.add_option("--config", o.config_path, "bridge configuration (acyclic.hrp2_bridge/1; docs/design.md section 11)");
  app.add_option("--dt", o.dt, "controller period, s (default: the configuration's, else 0.005)");
  app.add_option("--wait-state", o.wait_state, "file mode: seconds to wait for the first HRP2_STATE (default 5)");
  app.add_option("--zmp-stride", o.zmp_stride, "quasi-static LP every N samples, interpolated between (default 10)")
      ->check(CLI::PositiveNumber);
  app.add_option("--rt-priority", o.rt_priority,
                 "SCHED_FIFO priority of the control loop and LCM receive threads, 0: none (default 20; when not\n"
                 "permitted the bridge says so and runs at normal priority)")
      ->check(CLI::Range(0, 99));
  app.add_option("--cpu", o.cpu, "run on this CPU only (default: any); e.g. the one the planner does not use");
  bool lcm_flag = false;
  app.add_flag("--lcm", lcm_flag, "accepted for symmetry with the other processes (LCM mode is the default without --trajectory)");
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  if (!o.trajectory_path.empty() && lcm_flag) {
    std::fprintf(stderr, "acyclic-hrp2-bridge: --lcm and --trajectory exclude each other\n");
    return 2;
  }
  return serveBridge(o);
}
