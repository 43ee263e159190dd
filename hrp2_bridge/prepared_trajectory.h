#pragma once
// A trajectory made ready for the controller: checked against the model
// (trajectory_check.h), resampled at the controller period, with the
// stabilizer flag and the waist and ZMP references of every command. Both the
// bridge (streaming) and the SequencePlayer export use it, so what is
// streamed and what is exported are the same numbers.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hrp2_bridge/bridge_config.h"
#include "hrp2_bridge/stabilizer_schedule.h"
#include "hrp2_bridge/trajectory_check.h"
#include "planner/plan/trajectory.h"

namespace acyclic::hrp2 {

struct CommandSample {
  double t = 0;                // s from the start, a multiple of the controller period
  Eigen::VectorXd q, dq;       // controller order
  Eigen::Vector3d waist_position = Eigen::Vector3d::Zero(), waist_rpy = Eigen::Vector3d::Zero();
  Eigen::Vector3d zmp_world = Eigen::Vector3d::Zero(), zmp_waist = Eigen::Vector3d::Zero();
  bool stabilizer = true;
  int phase = 0;
};

struct PreparedTrajectory {
  double dt = 0.005;
  std::vector<CommandSample> samples;
  std::vector<StabilizerSwitch> switches;
  std::vector<bool> phase_coplanar;
  int zmp_from_forces = 0;     // samples whose ZMP is the feet's centre of pressure
  int zmp_lp_failures = 0;     // samples where the LP failed (CoM projection used)
  double duration() const { return samples.empty() ? 0.0 : samples.back().t; }
};

struct PrepareResult {
  CheckResult check;           // !ok: refused, `prepared` is empty
  PreparedTrajectory prepared;
};

struct PrepareOptions {
  // The quasi-static LP runs every `zmp_stride` samples of a phase (and at its
  // ends); the ZMP is interpolated linearly between (quasi-static motion is slow).
  int zmp_stride = 10;
};

PrepareResult prepareTrajectory(const Trajectory& tr, std::shared_ptr<const RobotModel> robot,
                                std::shared_ptr<const Scene> scene, const BridgeConfig& config,
                                const PrepareOptions& options = {});

// The trajectory at time t (clamped to [0, duration]): joints and velocities
// linear between samples, base position linear, orientation slerped; the
// phase of the sample at or before t.
TrajectorySample sampleAt(const Trajectory& tr, double t);

}  // namespace acyclic::hrp2
