#pragma once
// The validity contract for a trajectory (docs/design.md section 9), sample by
// sample: every sample is a valid posture (the independent ValidityChecker)
// with its phase's contacts, so contacts are held within 1 mm; joint velocities
// are within their limits, both as stored and as the samples' finite
// differences; the stored velocities are the derivative of the stored
// positions; joint accelerations, from positions, within the robot's limits;
// the robot at rest wherever a contact is made or broken, by the stored
// velocity and by positions; the phases tile the samples in time. Shares no
// code with the interpolator.
#include <functional>
#include <string>
#include <vector>

#include "planner/check/validity.h"
#include "planner/plan/trajectory.h"

namespace acyclic {

struct TrajectoryCheckOptions {
  double velocity_tolerance = 1e-6;  // relative slack on the joint velocity limits
  double rest_velocity = 1e-6;       // rad/s: "zero" stored joint velocity where a contact is made or broken
  // Tolerances in units of each joint's acceleration limit a (RobotModel):
  // - the stored velocities against the positions: over each interval, their
  //   mean differs from (q[i+1] - q[i]) / dt by at most consistency * a * dt
  //   (half a sample's worth of change at the limit by default);
  // - at a contact change, the samples on either side lie within
  //   rest_displacement * a * dt^2 of it (what starting from rest at the
  //   limit moves in one sample).
  double consistency = 0.5;
  double rest_displacement = 0.5;
  double acceleration_tolerance = 1e-6;  // relative slack on the acceleration limits
  int max_violations = 20;           // kept per part (the count of all is kept too)
};

struct TrajectoryCheckPart {
  std::string name;  // "samples", "velocity limits", "velocities from positions", "acceleration limits",
                     // "rest at contact changes", "phases"
  std::string summary;               // what was checked and the worst figure
  long violation_count = 0;
  std::vector<std::string> violations;  // the first max_violations
  bool ok() const { return violation_count == 0; }
};

struct TrajectoryReport {
  std::vector<TrajectoryCheckPart> parts;
  int samples = 0, invalid_samples = 0;
  double worst_velocity_ratio = 0;   // |dq| / limit, stored or finite-difference, worst over all
  double worst_acceleration_ratio = 0;  // |second difference| / dt^2 / limit, worst over all
  double worst_consistency = 0;      // worst |stored - finite-difference velocity| / (a dt)
  double worst_cone_ratio = 0;       // worst ||f_t|| / (mu f_n) of the equilibrium forces, over the samples
  bool valid() const;
};

// `progress(done, total)` is called now and then (samples checked).
TrajectoryReport checkTrajectory(const Trajectory& tr, const Scenario& sc, ValidityChecker& checker,
                                 const TrajectoryCheckOptions& options = {},
                                 const std::function<void(int, int)>& progress = {});

}  // namespace acyclic
