#pragma once
// The validity contract of a trajectory (docs/design.md section 9) before the
// bridge streams or exports it: every sample a valid posture with its phase's
// contacts (the independent check, planner/check/trajectory_check.h), joint
// velocities within limits, rest where a contact is made or broken. The
// bridge's own checks (trajectory_check.h) guard the robot's limits; this one
// guards physics: a motion that would collide, lose a contact or fall is
// refused too. It costs about a millisecond per sample, so it runs in the
// bridge's checking state, off the control loop.
#include <functional>

#include "hrp2_bridge/prepared_trajectory.h"
#include "hrp2_bridge/trajectory_check.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

// ok, or refused with the number of invalid samples and the first violation.
// `progress(done, total)` is called now and then (samples checked).
CheckResult checkContract(const Trajectory& tr, const Scenario& sc,
                          const std::function<void(int, int)>& progress = {});

// What the bridge and the exporter run: prepareTrajectory (the robot's limits
// first: cheap), then, when config.check_contract, the contract.
PrepareResult prepareChecked(const Trajectory& tr, const Scenario& sc, const BridgeConfig& config,
                             const PrepareOptions& options = {},
                             const std::function<void(int, int)>& progress = {});

}  // namespace acyclic::hrp2
