#include "planner/check/plan_check.h"

#include <cmath>
#include <cstdio>

#include "planner/common/fmt.h"
#include "planner/scene/friction.h"

namespace acyclic {

bool PlanReport::valid() const {
  for (const auto& s : stances)
    if (!s.valid()) return false;
  return sequence_violations.empty();
}

CheckPart checkReportedForces(const PlanStance& st, const Scenario& sc, Kinematics& kin, double* worst_out) {
  CheckPart p;
  p.name = "reported forces";
  const RobotModel& robot = *sc.robot;
  bool any = false;
  for (const auto& c : st.contacts) any = any || !c.forces.empty();
  if (!any) {
    p.checked = false;
    p.summary = "the stance reports no contact force";
    return p;
  }
  kin.setConfiguration(st.configuration);
  const double W = robot.totalMass() * 9.81;
  const Eigen::Vector3d com = kin.centerOfMass();
  Eigen::Vector3d force(0, 0, -W), moment = Eigen::Vector3d::Zero();  // gravity acts at the centre of mass
  double worst = 0;
  for (const auto& c : st.contacts) {
    const std::string name = sc.describe(c.spec);
    const auto& corners = robot.spots()[c.spec.spot].polygon.vertices();
    if (!c.spec.supporting) {
      if (!c.forces.empty()) p.violations.push_back(name + ": forces reported on a contact that does not support");
      continue;
    }
    if (c.forces.size() != corners.size() || c.points.size() != corners.size()) {
      p.violations.push_back(name + fmt(": %.0f forces for %.0f corners", c.forces.size(), corners.size()));
      continue;
    }
    const Surface& s = sc.scene->surfaces()[c.spec.surface];
    const Eigen::Vector3d n = s.frame.linear().col(2);
    for (std::size_t k = 0; k < corners.size(); ++k) {
      double nearest = INFINITY;
      for (const auto& v : corners) nearest = std::min(nearest, (c.frame * Eigen::Vector3d(v.x(), v.y(), 0) - c.points[k]).norm());
      if (nearest > 2e-3)
        p.violations.push_back(name + fmt(": point %.0f is %.1f mm from every corner of the spot", k, nearest * 1e3));
      const double r = coneRatio(c.forces[k], n, s.friction, 1e-6 * W);
      worst = std::max(worst, r);
      const double fn = c.forces[k].dot(n), ft = (c.forces[k] - fn * n).norm();
      if (!(ft <= s.friction * fn * (1 + 1e-6) + 1e-6 * W))
        p.violations.push_back(name + fmt(": force %.0f outside the friction cone, ||f_t|| = %.1f mu f_n", k, r) +
                               fmt(" (%.1f N tangential, %.1f N allowed)", ft, s.friction * fn));
      force += c.forces[k];
      moment += (c.points[k] - com).cross(c.forces[k]);
    }
  }
  if (force.norm() > 1e-6 * W) p.violations.push_back(fmt("forces and gravity leave %.3g N unbalanced", force.norm()));
  if (moment.norm() > 1e-6 * W)
    p.violations.push_back(fmt("forces leave a moment of %.3g N m about the centre of mass", moment.norm()));
  p.summary = fmt("worst ||f_t|| / (mu f_n) %.3f; unbalanced %.1e N, %.1e N m", worst, force.norm(), moment.norm());
  if (worst_out) *worst_out = worst;
  return p;
}

PlanReport checkPlan(const Plan& plan, const Scenario& sc, ValidityChecker& checker) {
  PlanReport rep;
  Kinematics kin(sc.robot);
  for (const auto& s : plan.stances) {
    rep.stances.push_back(checker.checkPosture(s.configuration, s.specs()));
    double worst = 0;
    rep.stances.back().parts.push_back(checkReportedForces(s, sc, kin, &worst));
    if (rep.stances.back().parts.back().checked && (rep.worst_cone_stance < 0 || worst > rep.worst_cone_ratio))
      rep.worst_cone_ratio = worst, rep.worst_cone_stance = static_cast<int>(rep.stances.size()) - 1;
  }
  if (plan.stances.empty()) {
    rep.sequence_violations.push_back("the plan has no stance");
    return rep;
  }
  // The first stance is the scenario's start stance: the same contacts, placed and supporting alike.
  const StanceDiff first = diffStances(sc.start_stance, plan.stances.front().specs());
  if (first.changes() != 0)
    rep.sequence_violations.push_back("the first stance is not the scenario's start stance (" +
                                      std::to_string(first.added) + " contacts added, " + std::to_string(first.removed) +
                                      " missing, " + std::to_string(first.flipped) + " with another support)");
  Kinematics& k = kin;
  k.setConfiguration(plan.stances.back().configuration);
  if (!sc.goal.satisfied(k, plan.stances.back().specs()))
    rep.sequence_violations.push_back("the last stance does not meet the goal (" + sc.goal.describe(*sc.robot) + ")");
  for (std::size_t i = 1; i < plan.stances.size(); ++i) {
    const std::string why = checkStep(plan.stances[i - 1], plan.stances[i], sc);
    if (!why.empty())
      rep.sequence_violations.push_back("stances " + std::to_string(i - 1) + " -> " + std::to_string(i) + ": " + why);
  }
  return rep;
}

}  // namespace acyclic
