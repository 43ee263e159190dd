#pragma once
// The bridge's parameters (docs/design.md section 11): the controller period and
// every safety threshold, with defaults that fit HRP-2 No.14 (200 Hz).
// Optionally read from a YAML file, format acyclic.hrp2_bridge/1; a wrong
// field is a FormatError naming the file and the field.
#include <string>

namespace acyclic::hrp2 {

struct BridgeConfig {
  double dt = 0.005;                  // s, controller period (hrpsys reads dt from the robot's config)
  double state_timeout = 0.010;       // s without HRP2_STATE before holding (detected at the next
                                      // tick: within 3 periods of the last state)
  double stall_timeout = 0.050;       // s during which the controller acknowledges no new command
  double start_tolerance = 0.02;      // rad, trajectory start vs measured joints (refuse a jump)
  double rest_velocity = 0.05;        // rad/s, start guard: the robot must be at rest
  double velocity_margin = 1.0;       // fraction of the model's velocity limit a trajectory may use
  double position_margin = 0.0;       // rad kept inside the model's position limits
  double jump_factor = 1.5;           // a step between samples may be at most this times vmax*dt
  double max_tracking_error = 0.15;   // rad while streaming; beyond: fault and hold
  double release_blend = 1.0;         // s, e-stop release: playback speed ramps from 0 to 1
  double stabilizer_lead = 0.10;      // s, stabilizer off this long before a non-coplanar contact
  double stabilizer_lag = 0.10;       // s, back on this long after the last one is released
  double coplanar_tolerance = 1e-3;   // m and rad: two surfaces are one plane within this
  double status_period = 0.05;        // s, HRP2_BRIDGE_STATUS rate (20 Hz)
  bool check_contract = true;         // also the validity contract (contract_check.h) before streaming

  // Throws std::invalid_argument naming the first bad value.
  void validate() const;
  // Reads the fields above from a YAML file (any subset); FormatError on bad input.
  static BridgeConfig load(const std::string& path);
};

}  // namespace acyclic::hrp2
