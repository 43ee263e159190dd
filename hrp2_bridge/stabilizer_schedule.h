#pragma once
// When HRP-2's stabilizer may run (paper, section 4): it handles coplanar foot
// contacts only, so it is switched off just before a non-coplanar contact is
// made (a hand on the table, a thigh on the chair, a foot on another plane)
// and back on just after the last one is released, when only coplanar foot
// contacts remain. Computed from the trajectory's phases and the scene's
// surfaces; a contact counts from the phase where it appears, supporting or
// not (touching is already a contact the stabilizer cannot handle).
#include <string>
#include <vector>

#include "hrp2_bridge/bridge_config.h"
#include "planner/plan/trajectory.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

// A foot contact: a spot whose name ends in "_sole" (the robot description's
// naming, models/hrp2/hrp2.yaml).
bool isFootSpot(const RobotModel& m, int spot);
// Two surfaces lie in one plane: normals within `tolerance` rad and each
// origin within `tolerance` m of the other's plane.
bool coplanar(const Surface& a, const Surface& b, double tolerance);
// Only foot contacts, all on one plane, and at least one.
bool onlyCoplanarFeet(const std::vector<ContactSpec>& contacts, const RobotModel& m, const Scene& scene,
                      double tolerance);

struct StabilizerSwitch {
  double t = 0;      // s, trajectory time
  bool on = false;
  std::string why;
};

struct StabilizerSchedule {
  std::vector<bool> phase_coplanar;   // per phase: only coplanar feet
  std::vector<bool> sample_on;        // per sample: the stabilizer flag
  std::vector<StabilizerSwitch> switches;
};

// Per sample: on when its phase holds only coplanar feet, no non-coplanar
// contact is made within config.stabilizer_lead after it, and none was
// released within config.stabilizer_lag before it.
StabilizerSchedule scheduleStabilizer(const Trajectory& tr, const RobotModel& m, const Scene& scene,
                                      const BridgeConfig& config);

}  // namespace acyclic::hrp2
