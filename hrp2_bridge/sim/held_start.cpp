#include "hrp2_bridge/sim/held_start.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace acyclic::hrp2 {

Trajectory heldStart(const Scenario& sc, double seconds, double dt) {
  if (!(std::isfinite(seconds) && seconds > 0)) throw std::invalid_argument("the time to hold the start must be positive");
  if (!(std::isfinite(dt) && dt > 0)) throw std::invalid_argument("the sample period must be positive");
  // A day at the controller's 200 Hz at most: more is a typo, not a test.
  if (seconds / dt > 2e7) throw std::invalid_argument("the time to hold the start is over 2e7 samples");
  const int n = std::max(1, static_cast<int>(std::lround(seconds / dt)));
  Trajectory tr;
  tr.scenario = sc.path;
  tr.dt = dt;
  TrajectoryPhase ph;
  ph.contacts = sc.start_stance;
  ph.t_end = n * dt;
  ph.stance = 0;
  tr.phases.push_back(ph);
  for (int k = 0; k <= n; ++k) {
    TrajectorySample x;
    x.t = k * dt;
    x.q = sc.start;
    x.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
    tr.samples.push_back(x);
  }
  return tr;
}

}  // namespace acyclic::hrp2
