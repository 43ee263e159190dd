#pragma once
// A time-parameterized whole-body trajectory and its file format,
// acyclic.trajectory/1 (JSON; docs/design.md section 8). Written by the
// interpolator, read by acyclic-check, the HRP-2 bridge and the exporter.
//
// Samples are equally spaced by dt from t = 0. The contacts are constant over
// a phase; each sample names its phase, so every sample knows its active
// contacts and which of them support.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "planner/scene/scenario.h"

namespace acyclic {

struct TrajectoryPhase {
  double t_start = 0, t_end = 0;     // s
  std::vector<ContactSpec> contacts; // active contacts; .supporting as in the plan
  int stance = -1;                   // index of the plan stance it holds (or starts from), -1 if none
};

struct TrajectorySample {
  double t = 0;                      // s
  Configuration q;
  Eigen::VectorXd dq;                // joint velocities, rad/s, controller order
  int phase = 0;                     // index into Trajectory::phases
};

struct TrajectoryStats {
  int stances_in = 0;                // stances of the plan
  int stances_kept = 0;              // after filtering
  int transitions = 0;
  int repairs = 0;                   // transitions whose moving-body path was repaired
  long posture_calls = 0;
  double seconds = 0;                // wall time of the interpolation
};

struct Trajectory {
  std::string scenario;              // the scenario file (as given)
  std::string plan;                  // the plan file it interpolates (as given)
  double dt = 0.005;                 // s
  std::vector<TrajectoryPhase> phases;
  std::vector<TrajectorySample> samples;
  TrajectoryStats stats;
  double duration() const { return samples.empty() ? 0.0 : samples.back().t; }
};

// Writes atomically (beside, then rename). Joint, spot and surface names come
// from the scenario's robot and scene.
void writeTrajectory(const Trajectory& tr, const Scenario& sc, const std::string& path);
std::string trajectoryToJson(const Trajectory& tr, const Scenario& sc);
// Reads against a scenario; FormatError naming the file and field on bad input
// (including samples out of order, a phase index out of range, a NaN).
Trajectory readTrajectory(const std::string& path, const Scenario& sc);
Trajectory trajectoryFromJson(const std::string& text, const std::string& origin, const Scenario& sc);

}  // namespace acyclic
