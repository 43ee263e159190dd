#include "hrp2_bridge/stabilizer_schedule.h"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <limits>

namespace acyclic::hrp2 {

bool isFootSpot(const RobotModel& m, int spot) {
  const std::string& n = m.spots().at(spot).name;
  return n.size() >= 5 && n.compare(n.size() - 5, 5, "_sole") == 0;
}

bool coplanar(const Surface& a, const Surface& b, double tol) {
  const Eigen::Vector3d na = a.frame.linear().col(2), nb = b.frame.linear().col(2);
  const double angle = std::acos(std::clamp(na.dot(nb), -1.0, 1.0));
  if (angle > tol) return false;
  const Eigen::Vector3d d = b.frame.translation() - a.frame.translation();
  return std::abs(na.dot(d)) <= tol && std::abs(nb.dot(d)) <= tol;
}

bool onlyCoplanarFeet(const std::vector<ContactSpec>& contacts, const RobotModel& m, const Scene& scene,
                      double tol) {
  if (contacts.empty()) return false;
  for (const ContactSpec& c : contacts) {
    if (!isFootSpot(m, c.spot)) return false;
    if (!coplanar(scene.surfaces().at(contacts.front().surface), scene.surfaces().at(c.surface), tol)) return false;
  }
  return true;
}

StabilizerSchedule scheduleStabilizer(const Trajectory& tr, const RobotModel& m, const Scene& scene,
                                      const BridgeConfig& cfg) {
  StabilizerSchedule s;
  for (const TrajectoryPhase& p : tr.phases)
    s.phase_coplanar.push_back(onlyCoplanarFeet(p.contacts, m, scene, cfg.coplanar_tolerance));
  const std::size_t n = tr.samples.size();
  // Intervals [made, released) of non-coplanar contact, from the samples: a
  // run of samples in non-coplanar phases, up to the first sample after it.
  std::vector<std::pair<double, double>> off;
  for (std::size_t i = 0; i < n;) {
    if (s.phase_coplanar.at(tr.samples[i].phase)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < n && !s.phase_coplanar.at(tr.samples[j].phase)) ++j;
    const double end = j < n ? tr.samples[j].t : std::numeric_limits<double>::infinity();
    off.emplace_back(tr.samples[i].t, end);
    i = j;
  }
  s.sample_on.assign(n, true);
  std::vector<int> cause(n, -1);  // the interval that keeps each sample off
  std::size_t k = 0;  // intervals are in time order, so one pass suffices
  for (std::size_t i = 0; i < n; ++i) {
    const double t = tr.samples[i].t;
    while (k < off.size() && off[k].second + cfg.stabilizer_lag <= t) ++k;
    // 1e-9: a sample exactly `lead` before a contact is already off.
    if (k < off.size() && off[k].first - cfg.stabilizer_lead <= t + 1e-9) {
      s.sample_on[i] = false;
      cause[i] = static_cast<int>(k);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const bool before = i == 0 ? true : s.sample_on[i - 1];  // the stabilizer is on before a motion starts
    if (s.sample_on[i] == before) continue;
    char why[160];
    if (s.sample_on[i])
      std::snprintf(why, sizeof why, "only coplanar feet since t = %.3f s", off[cause[i - 1]].second);
    else
      std::snprintf(why, sizeof why, "non-coplanar contact made at t = %.3f s", off[cause[i]].first);
    s.switches.push_back({tr.samples[i].t, s.sample_on[i], why});
  }
  return s;
}

}  // namespace acyclic::hrp2
