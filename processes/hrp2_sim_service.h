#pragma once
// The simulated HRP-2 controller's runtime: the control loop at the
// controller period (kinematic tracking, optionally driving the dynamics
// simulation), the LCM receive thread and the contact wrench thread.
#include <string>

#include "hrp2_bridge/sim/simulated_controller.h"

namespace acyclic {

struct SimServiceOptions {
  std::string lcm_url;
  std::string scenario_path;     // robot, scene, start configuration
  std::string start_trajectory;  // start at its first sample instead of the scenario's start
  hrp2::SimOptions controller;   // period, tracking, faults, hold after missed commands
  double wrench_period = 0.05;   // s between two contact wrench LPs
  int rt_priority = 20;          // SCHED_FIFO of the loop and receive threads, 0: none
  bool dynamics = false;         // the robot is the dynamics simulation, not the kinematic one
  double duration = 0;           // s, 0: until a signal
};

// Runs until SIGINT/SIGTERM or `duration`. Returns the process's exit status:
// 0, 2 bad input, 3 LCM failure.
int serveSimulator(const SimServiceOptions& options);

}  // namespace acyclic
