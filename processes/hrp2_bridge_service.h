#pragma once
// The HRP-2 bridge's runtime: the control loop at the controller period, the
// LCM receive thread, the trajectory intake and the check threads, around
// one hrp2::Bridge (which holds the safety logic and knows nothing of LCM).
#include <cstdint>
#include <string>

namespace acyclic {

struct BridgeServiceOptions {
  std::string lcm_url;
  std::string scenario_path;     // LCM mode: required; file mode: default the trajectory's own
  std::string trajectory_path;   // file mode when not empty: stream this file once, then exit
  std::string config_path;       // acyclic.hrp2_bridge/1, empty: defaults
  std::int64_t file_request_id = 1;
  double dt = 0;                 // controller period, 0: the configuration's
  double wait_state = 5.0;       // file mode: s to wait for the first HRP2_STATE
  int zmp_stride = 10;
  int rt_priority = 20;          // SCHED_FIFO of the loop and receive threads, 0: none
  int cpu = -1;                  // pinned to this CPU, -1: any
};

// Runs until SIGINT/SIGTERM (LCM mode) or the file's trajectory's end.
// Returns the process's exit status: 0, 1 the file's trajectory refused or
// not played to the end, 2 bad input, 3 LCM failure.
int serveBridge(const BridgeServiceOptions& options);

}  // namespace acyclic
