#include "hrp2_bridge/prepared_trajectory.h"

#include <algorithm>
#include <cmath>

#include "hrp2_bridge/references.h"

namespace acyclic::hrp2 {

TrajectorySample sampleAt(const Trajectory& tr, double t) {
  const auto& s = tr.samples;
  if (t <= s.front().t) return s.front();
  if (t >= s.back().t) return s.back();
  const auto it = std::upper_bound(s.begin(), s.end(), t, [](double v, const TrajectorySample& x) { return v < x.t; });
  const TrajectorySample& b = *it;
  const TrajectorySample& a = *(it - 1);
  const double u = (t - a.t) / (b.t - a.t);
  TrajectorySample r = a;
  r.t = t;
  r.q.joints = a.q.joints + u * (b.q.joints - a.q.joints);
  r.q.base_position = a.q.base_position + u * (b.q.base_position - a.q.base_position);
  r.q.base_orientation = a.q.base_orientation.slerp(u, b.q.base_orientation);
  r.dq = a.dq + u * (b.dq - a.dq);
  return r;
}

PrepareResult prepareTrajectory(const Trajectory& tr, std::shared_ptr<const RobotModel> robot,
                                std::shared_ptr<const Scene> scene, const BridgeConfig& cfg,
                                const PrepareOptions& opt) {
  PrepareResult res;
  res.check = checkTrajectory(tr, *robot, cfg);
  if (!res.check.ok) return res;

  // Resample on the controller's grid t = k dt; the last row holds the final
  // posture when the duration is not a multiple of dt.
  Trajectory grid;
  grid.dt = cfg.dt;
  grid.phases = tr.phases;
  const double duration = tr.duration();
  const int rows = static_cast<int>(std::ceil(duration / cfg.dt - 1e-9)) + 1;
  grid.samples.reserve(rows);
  for (int k = 0; k < rows; ++k) grid.samples.push_back(sampleAt(tr, k * cfg.dt));
  grid.samples.back().t = (rows - 1) * cfg.dt;

  const StabilizerSchedule sched = scheduleStabilizer(grid, *robot, *scene, cfg);
  PreparedTrajectory& p = res.prepared;
  p.dt = cfg.dt;
  p.switches = sched.switches;
  p.phase_coplanar = sched.phase_coplanar;
  p.samples.resize(rows);

  ReferenceModel refs(robot, scene);
  std::vector<WaistZmp> ref(rows);
  std::vector<bool> computed(rows, false);
  const int stride = std::max(1, opt.zmp_stride);
  for (int k = 0; k < rows; ++k) {
    const TrajectorySample& s = grid.samples[k];
    const bool phase_start = k == 0 || grid.samples[k - 1].phase != s.phase;
    const bool phase_end = k + 1 == rows || grid.samples[k + 1].phase != s.phase;
    const bool coplanar = sched.phase_coplanar[s.phase];
    // The CoM projection is cheap: every sample. The LP: on the stride.
    if (coplanar || phase_start || phase_end || k % stride == 0) {
      ref[k] = refs.compute(s.q, tr.phases[s.phase].contacts, coplanar);
      computed[k] = true;
    }
  }
  for (int k = 0; k < rows; ++k) {
    const TrajectorySample& s = grid.samples[k];
    CommandSample& c = p.samples[k];
    c.t = s.t;
    c.q = s.q.joints;
    c.dq = s.dq;
    c.phase = s.phase;
    c.stabilizer = sched.sample_on[k];
    if (!computed[k]) {
      // Between two computed samples of the same phase (phase ends are computed).
      int a = k - 1, b = k + 1;
      while (!computed[a]) --a;
      while (!computed[b]) ++b;
      const double u = double(k - a) / double(b - a);
      ref[k] = ref[a];
      ref[k].zmp_world = (1 - u) * ref[a].zmp_world + u * ref[b].zmp_world;
      ref[k].from_forces = ref[a].from_forces && ref[b].from_forces;
      ref[k].lp_failed = false;
      const Eigen::Isometry3d waist = s.q.basePose();
      ref[k].zmp_waist = waist.inverse() * ref[k].zmp_world;
    }
    c.waist_position = s.q.base_position;
    c.waist_rpy = quaternionToRpy(s.q.base_orientation);
    c.zmp_world = ref[k].zmp_world;
    c.zmp_waist = ref[k].zmp_waist;
    p.zmp_from_forces += ref[k].from_forces;
    p.zmp_lp_failures += ref[k].lp_failed;
  }
  return res;
}

}  // namespace acyclic::hrp2
