#pragma once
// The validity contract for a trajectory (DESIGN.md section 9), sample by
// sample: every sample is a valid posture (the independent ValidityChecker)
// with its phase's contacts, so contacts are held within 1 mm; joint velocities
// are within their limits, both as stored and as the samples' finite
// differences; velocity is zero wherever a contact is made or broken; the
// phases tile the samples in time. Shares no code with the interpolator.
#include <functional>
#include <string>
#include <vector>

#include "planner/check/validity.h"
#include "planner/plan/trajectory.h"

namespace acyclic {

struct TrajectoryCheckOptions {
  double velocity_tolerance = 1e-6;  // relative slack on the joint velocity limits
  double rest_velocity = 1e-6;       // rad/s: "zero" joint velocity where a contact is made or broken
  int max_violations = 20;           // kept per part (the count of all is kept too)
};

struct TrajectoryCheckPart {
  std::string name;                  // "samples", "velocity limits", "rest at contact changes", "phases"
  std::string summary;               // what was checked and the worst figure
  long violation_count = 0;
  std::vector<std::string> violations;  // the first max_violations
  bool ok() const { return violation_count == 0; }
};

struct TrajectoryReport {
  std::vector<TrajectoryCheckPart> parts;
  int samples = 0, invalid_samples = 0;
  double worst_velocity_ratio = 0;   // |dq| / limit, stored or finite-difference, worst over all
  bool valid() const;
};

// `progress(done, total)` is called now and then (samples checked).
TrajectoryReport checkTrajectory(const Trajectory& tr, const Scenario& sc, ValidityChecker& checker,
                                 const TrajectoryCheckOptions& options = {},
                                 const std::function<void(int, int)>& progress = {});

}  // namespace acyclic
