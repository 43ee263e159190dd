#include "planner/check/trajectory_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "planner/common/fmt.h"

namespace acyclic {

namespace {

void add(TrajectoryCheckPart& p, const std::string& v, int max) {
  if (static_cast<int>(p.violations.size()) < max) p.violations.push_back(v);
  ++p.violation_count;
}

// Two phases' contacts differ by a contact made or broken (a spot, surface or
// placement present in one and not the other); a change of support alone
// makes and breaks nothing.
bool contactMadeOrBroken(const std::vector<ContactSpec>& a, const std::vector<ContactSpec>& b) {
  auto same = [](const ContactSpec& x, const ContactSpec& y) {
    return x.spot == y.spot && x.surface == y.surface && std::abs(x.placement.x - y.placement.x) <= 1e-3 &&
           std::abs(x.placement.y - y.placement.y) <= 1e-3;
  };
  auto covered = [&](const std::vector<ContactSpec>& u, const std::vector<ContactSpec>& v) {
    for (const auto& x : u)
      if (std::none_of(v.begin(), v.end(), [&](const ContactSpec& y) { return same(x, y); })) return false;
    return true;
  };
  return !covered(a, b) || !covered(b, a);
}

}  // namespace

bool TrajectoryReport::valid() const {
  for (const auto& p : parts)
    if (!p.ok()) return false;
  return true;
}

TrajectoryReport checkTrajectory(const Trajectory& tr, const Scenario& sc, ValidityChecker& checker,
                                 const TrajectoryCheckOptions& opt, const std::function<void(int, int)>& progress) {
  const RobotModel& robot = *sc.robot;
  TrajectoryReport rep;
  rep.samples = static_cast<int>(tr.samples.size());
  const int n = rep.samples;

  // Phases: ordered, contiguous, covering the samples; each sample in its phase's interval.
  TrajectoryCheckPart phases{"phases", "", 0, {}};
  const double eps = 1e-9;
  if (tr.phases.empty()) add(phases, "the trajectory has no phase", opt.max_violations);
  if (n == 0) add(phases, "the trajectory has no sample", opt.max_violations);
  if (!(tr.dt > 0)) add(phases, fmt("dt = %g s: expected a positive time step", tr.dt), opt.max_violations);
  for (std::size_t k = 0; k < tr.phases.size(); ++k) {
    const auto& ph = tr.phases[k];
    if (ph.t_end < ph.t_start - eps)
      add(phases, fmt("phase %.0f ends (%.4f s) before it starts (%.4f s)", k, ph.t_end, ph.t_start), opt.max_violations);
    if (k > 0 && std::abs(ph.t_start - tr.phases[k - 1].t_end) > eps)
      add(phases, fmt("phase %.0f starts at %.4f s, the previous one ends at %.4f s", k, ph.t_start, tr.phases[k - 1].t_end),
          opt.max_violations);
  }
  for (int i = 0; i < n && tr.dt > 0; ++i) {
    const auto& s = tr.samples[i];
    if (std::abs(s.t - i * tr.dt) > 1e-6)
      add(phases, fmt("sample %.0f at t = %.6f s, expected %.6f s (dt)", i, s.t, i * tr.dt), opt.max_violations);
    if (s.phase < 0 || s.phase >= static_cast<int>(tr.phases.size())) {
      add(phases, fmt("sample %.0f names phase %.0f, out of range", i, s.phase), opt.max_violations);
      continue;
    }
    const auto& ph = tr.phases[s.phase];
    if (s.t < ph.t_start - eps || s.t > ph.t_end + eps)
      add(phases, fmt("sample %.0f (t = %.4f s) lies outside its phase %.0f", i, s.t, s.phase), opt.max_violations);
    if (i > 0 && s.phase < tr.samples[i - 1].phase)
      add(phases, fmt("sample %.0f goes back from phase %.0f to %.0f", i, tr.samples[i - 1].phase, s.phase),
          opt.max_violations);
  }
  phases.summary = std::to_string(tr.phases.size()) + " phases over " + fmt("%.3f s", tr.duration()) +
                   ", samples every " + fmt("%.4f s", tr.dt);
  const bool phases_ok = phases.ok();

  // Every sample a valid posture with its phase's contacts.
  TrajectoryCheckPart samples{"samples", "", 0, {}};
  int worst_cone_sample = -1;
  for (int i = 0; i < n; ++i) {
    const auto& s = tr.samples[i];
    if (s.phase < 0 || s.phase >= static_cast<int>(tr.phases.size())) continue;
    QuasiStaticReport eq;
    const ValidityReport r = checker.checkPosture(s.q, tr.phases[s.phase].contacts, &eq);
    if (eq.worst_cone_ratio > rep.worst_cone_ratio) rep.worst_cone_ratio = eq.worst_cone_ratio, worst_cone_sample = i;
    if (!r.valid()) {
      ++rep.invalid_samples;
      for (const auto& p : r.parts)
        if (p.checked && !p.ok())
          add(samples, fmt("sample %.0f (t = %.3f s, phase %.0f): ", i, s.t, s.phase) + p.name + ": " + p.violations[0],
              opt.max_violations);
    }
    if (progress && (i % 50 == 0 || i + 1 == n)) progress(i + 1, n);
  }
  samples.summary = std::to_string(n - rep.invalid_samples) + " of " + std::to_string(n) +
                    " samples valid (joint limits, phase contacts within 1 mm, collisions, equilibrium)" +
                    fmt("; worst ||f_t|| / (mu f_n) %.3f (sample %.0f)", rep.worst_cone_ratio, worst_cone_sample);

  // Joint velocity limits: the stored velocities and the finite differences of the positions.
  TrajectoryCheckPart vel{"velocity limits", "", 0, {}};
  std::string worst_joint;
  for (int i = 0; i < n; ++i) {
    const auto& s = tr.samples[i];
    if (s.dq.size() != robot.numJoints()) {
      add(vel, fmt("sample %.0f has %.0f joint velocities, the robot %.0f joints", i, s.dq.size(), robot.numJoints()),
          opt.max_violations);
      continue;
    }
    for (const auto& j : robot.joints()) {
      const double stored = std::abs(s.dq[j.index]) / j.velocity;
      const double fd = (i + 1 < n && tr.dt > 0)
                            ? std::abs(tr.samples[i + 1].q.joints[j.index] - s.q.joints[j.index]) / tr.dt / j.velocity
                            : 0.0;
      const double r = std::max(stored, fd);
      if (r > rep.worst_velocity_ratio) rep.worst_velocity_ratio = r, worst_joint = j.name;
      if (r > 1 + opt.velocity_tolerance)
        add(vel, j.name + fmt(" at sample %.0f: %.3f rad/s over its limit %.3f rad/s", i, r * j.velocity, j.velocity) +
                     (fd > stored ? " (finite difference)" : " (stored)"),
            opt.max_violations);
    }
  }
  vel.summary = fmt("worst joint speed %.0f%% of its limit", rep.worst_velocity_ratio * 100) +
                (worst_joint.empty() ? "" : " (" + worst_joint + ")");

  // The stored velocities are the positions' derivative: over each interval
  // their mean (the trapezoid rule) matches the positions' difference.
  TrajectoryCheckPart consistent{"velocities from positions", "", 0, {}};
  std::string worst_consistent_joint;
  for (int i = 0; i + 1 < n && tr.dt > 0; ++i) {
    const auto& a = tr.samples[i];
    const auto& b = tr.samples[i + 1];
    if (a.dq.size() != robot.numJoints() || b.dq.size() != robot.numJoints()) continue;  // reported above
    for (const auto& j : robot.joints()) {
      const double fd = (b.q.joints[j.index] - a.q.joints[j.index]) / tr.dt;
      const double mean = 0.5 * (a.dq[j.index] + b.dq[j.index]);
      const double r = std::abs(fd - mean) / (j.acceleration * tr.dt);
      if (r > rep.worst_consistency) rep.worst_consistency = r, worst_consistent_joint = j.name;
      if (!(r <= opt.consistency))
        add(consistent, j.name + fmt(" between samples %.0f and %.0f: stored velocities %.4f rad/s on average, ", i, i + 1, mean) +
                            fmt("positions %.4f rad/s", fd),
            opt.max_violations);
    }
  }
  consistent.summary = fmt("stored velocities against positions: worst gap %.2f of a * dt (tolerance %.2f)",
                           rep.worst_consistency, opt.consistency) +
                       (worst_consistent_joint.empty() ? "" : " (" + worst_consistent_joint + ")");

  // Accelerations from positions: the second difference over dt^2.
  TrajectoryCheckPart accel{"acceleration limits", "", 0, {}};
  std::string worst_accel_joint;
  for (int i = 1; i + 1 < n && tr.dt > 0; ++i) {
    for (const auto& j : robot.joints()) {
      const double a = (tr.samples[i + 1].q.joints[j.index] - 2 * tr.samples[i].q.joints[j.index] +
                        tr.samples[i - 1].q.joints[j.index]) /
                       (tr.dt * tr.dt);
      const double r = std::abs(a) / j.acceleration;
      if (r > rep.worst_acceleration_ratio) rep.worst_acceleration_ratio = r, worst_accel_joint = j.name;
      if (!(r <= 1 + opt.acceleration_tolerance))
        add(accel, j.name + fmt(" at sample %.0f: %.2f rad/s^2 over its limit %.2f rad/s^2", i, std::abs(a), j.acceleration),
            opt.max_violations);
    }
  }
  accel.summary = fmt("from positions: worst joint acceleration %.0f%% of its limit", rep.worst_acceleration_ratio * 100) +
                  (worst_accel_joint.empty() ? "" : " (" + worst_accel_joint + ")");

  // Zero velocity where a contact is made or broken: at the sample on each such phase boundary.
  TrajectoryCheckPart rest{"rest at contact changes", "", 0, {}};
  int boundaries = 0;
  for (std::size_t k = 1; k < tr.phases.size() && phases_ok && n > 0; ++k) {
    if (!contactMadeOrBroken(tr.phases[k - 1].contacts, tr.phases[k].contacts)) continue;
    ++boundaries;
    const double tb = tr.phases[k].t_start;
    const int i = static_cast<int>(std::lround(tb / tr.dt));
    if (i < 0 || i >= n || std::abs(tr.samples[i].t - tb) > 1e-6) {
      add(rest, fmt("no sample at the contact change of t = %.4f s (phase %.0f)", tb, k), opt.max_violations);
      continue;
    }
    const double v = tr.samples[i].dq.size() ? tr.samples[i].dq.cwiseAbs().maxCoeff() : 0.0;
    if (v > opt.rest_velocity)
      add(rest, fmt("sample %.0f (t = %.4f s, contact change into phase %.0f): ", i, tb, k) +
                    fmt("joint speed %.3g rad/s, not zero", v),
          opt.max_violations);
    // At rest as the positions show it: the samples on either side barely move.
    for (int other : {i - 1, i + 1}) {
      if (other < 0 || other >= n) continue;
      for (const auto& j : robot.joints()) {
        const double d = std::abs(tr.samples[other].q.joints[j.index] - tr.samples[i].q.joints[j.index]);
        const double allowed = opt.rest_displacement * j.acceleration * tr.dt * tr.dt;
        if (d > allowed * (1 + 1e-9) + 1e-12) {
          add(rest, fmt("sample %.0f (t = %.4f s, contact change into phase %.0f): ", i, tb, k) + j.name +
                        fmt(" moves %.3g mrad to sample %.0f, at rest it could move %.3g mrad", d * 1e3, other, allowed * 1e3),
              opt.max_violations);
          break;
        }
      }
    }
  }
  rest.summary = std::to_string(boundaries) +
                 " contacts made or broken, at rest at each (stored velocity zero, neighbouring samples still)";

  rep.parts = {samples, vel, consistent, accel, rest, phases};
  return rep;
}

}  // namespace acyclic
