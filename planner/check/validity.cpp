#include "planner/check/validity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "planner/common/fmt.h"

namespace acyclic {

bool ValidityReport::valid() const {
  for (const auto& p : parts)
    if (p.checked && !p.ok()) return false;
  return true;
}

ValidityChecker::ValidityChecker(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                                 ContractTolerances tol)
    : robot_(robot), scene_(scene), tol_(tol), kin_(robot), collision_(robot, scene), statics_(robot, scene) {}

ValidityReport ValidityChecker::checkPosture(const Configuration& q, const std::vector<ContactSpec>& stance,
                                             QuasiStaticReport* equilibrium) {
  ValidityReport r;
  r.parts.push_back(checkJointLimits(q));
  kin_.setConfiguration(q);
  r.parts.push_back(checkContacts(stance));
  r.parts.push_back(checkCollisions(stance));
  r.parts.push_back(checkEquilibrium(stance, equilibrium));
  return r;
}

CheckPart ValidityChecker::checkEquilibrium(const std::vector<ContactSpec>& stance, QuasiStaticReport* out) {
  CheckPart p;
  p.name = "equilibrium";
  const QuasiStaticReport q = statics_.check(kin_, stance);
  if (!q.feasible) p.violations.push_back(q.reason);
  std::ostringstream os;
  os << q.supporting_contacts << " supporting contacts; friction margin "
     << (std::isnan(q.margin) ? std::string("not computed") : fmt("%.1f", q.margin) + " N") << "; worst torque "
     << fmt("%.0f", q.worst_torque_ratio * 100) << "% of its limit ("
     << (q.worst_joint.empty() ? "-" : q.worst_joint) << "); balance residual " << fmt("%.1e", q.residual)
     << " of the weight; worst ||f_t|| / (mu f_n) " << fmt("%.3f", q.worst_cone_ratio);
  p.summary = os.str();
  if (out) *out = q;
  return p;
}

CheckPart ValidityChecker::checkJointLimits(const Configuration& q) const {
  CheckPart p;
  p.name = "joint limits";
  double worst = std::numeric_limits<double>::infinity();
  std::string worst_name;
  if (!q.base_position.allFinite() || !q.base_orientation.coeffs().allFinite() || !q.joints.allFinite())
    p.violations.push_back("configuration has a non-finite value");
  if (std::abs(q.base_orientation.norm() - 1) > 1e-6)
    p.violations.push_back(fmt("base orientation is not a unit quaternion (norm %.9f)", q.base_orientation.norm()));
  for (const auto& j : robot_->joints()) {
    const double v = q.joints[j.index];
    const double margin = std::min(v - j.lower, j.upper - v);
    if (margin < worst) worst = margin, worst_name = j.name;
    if (margin < -tol_.joint_limit) {
      std::ostringstream os;
      os << j.name << " = " << v << " rad outside [" << j.lower << ", " << j.upper << "] by " << -margin
         << " rad";
      p.violations.push_back(os.str());
    }
  }
  std::ostringstream os;
  os << robot_->numJoints() << " joints; smallest margin " << fmt("%.4f", worst) << " rad (" << worst_name << ")";
  p.summary = os.str();
  return p;
}

CheckPart ValidityChecker::checkContacts(const std::vector<ContactSpec>& stance) {
  CheckPart p;
  p.name = "contacts";
  double worst_pos = 0, worst_ang = 0, worst_poly = -std::numeric_limits<double>::infinity();
  for (const auto& c : stance) {
    const ContactSpot& spot = robot_->spots()[c.spot];
    const Surface& surf = scene_->surfaces()[c.surface];
    const std::string name = spot.name + "@" + surf.name;
    const std::size_t before = p.violations.size();
    const Eigen::Isometry3d spot_w = kin_.spotPose(c.spot);
    const Eigen::Isometry3d target = contactFrame(surf, c.placement);
    const double pos = (spot_w.translation() - target.translation()).norm();
    // Spot z is the inward normal, surface z the outward one: in contact they
    // coincide (the body's outward normal opposes the surface's).
    const double cosang = std::clamp(spot_w.linear().col(2).dot(surf.frame.linear().col(2)), -1.0, 1.0);
    const double ang = std::acos(cosang) * 180 / M_PI;
    worst_pos = std::max(worst_pos, pos);
    worst_ang = std::max(worst_ang, ang);
    if (pos > tol_.contact_position)
      p.violations.push_back(name + fmt(": spot origin %.2f mm from the contact point", pos * 1e3));
    if (ang > tol_.contact_normal_deg)
      p.violations.push_back(name + fmt(": normals %.3f deg from opposed", ang));
    // Spot polygon (in the spot frame) mapped into the surface plane.
    const Eigen::Isometry3d spot_in_surf = surf.frame.inverse() * spot_w;
    if (!surf.polygon.contains(Eigen::Vector2d(c.placement.x, c.placement.y), tol_.polygon))
      p.violations.push_back(name + fmt(": contact point %.2f mm outside the surface polygon",
                                        surf.polygon.signedDistance({c.placement.x, c.placement.y}) * 1e3));
    for (const auto& v : spot.polygon.vertices()) {
      const Eigen::Vector3d corner = spot_in_surf * Eigen::Vector3d(v.x(), v.y(), 0);
      const double out = surf.polygon.signedDistance(corner.head<2>());
      worst_poly = std::max(worst_poly, out);
      if (out > tol_.polygon) {
        p.violations.push_back(name + fmt(": spot polygon corner %.2f mm outside the surface polygon", out * 1e3));
        break;
      }
    }
    if (p.violations.size() > before) p.links.push_back(spot.link);
  }
  std::ostringstream os;
  os << stance.size() << " contacts; worst position error " << fmt("%.3f", worst_pos * 1e3)
     << " mm, worst normal error " << fmt("%.3f", worst_ang) << " deg, polygon corners at worst "
     << fmt("%.1f", worst_poly * 1e3) << " mm from the surface edge (negative: inside)";
  p.summary = os.str();
  return p;
}

CheckPart ValidityChecker::checkCollisions(const std::vector<ContactSpec>& stance) {
  CheckPart p;
  p.name = "collisions";
  // A contacting body may touch the obstacle its surface lies on.
  std::set<std::pair<int, int>> touching;
  for (const auto& c : stance)
    touching.insert({robot_->spots()[c.spot].link, scene_->surfaces()[c.surface].obstacle});
  DistanceOptions dopt;
  dopt.cutoff = clearance_cutoff_;
  const auto ds = collision_.distances(kin_, dopt);
  double worst_free = std::numeric_limits<double>::infinity();
  std::string worst_name;
  int n_touch = 0;
  double worst_pen = 0;
  for (const auto& d : ds) {
    const CollisionPair& pr = collision_.pairs()[d.pair];
    const bool allowed = pr.kind == CollisionPair::Kind::RobotEnvironment && touching.count({pr.link_a, pr.obstacle});
    if (allowed) {
      ++n_touch;
      worst_pen = std::max(worst_pen, -d.distance);
      if (d.distance < -tol_.penetration) {
        p.violations.push_back(collision_.describe(d.pair) +
                               fmt(": contacting body penetrates its surface's obstacle by %.2f mm", -d.distance * 1e3));
        p.links.push_back(pr.link_a);
      }
      continue;
    }
    if (d.distance < worst_free) worst_free = d.distance, worst_name = collision_.describe(d.pair);
    if (d.distance < 0) {
      p.violations.push_back(collision_.describe(d.pair) + fmt(": penetration %.2f mm", -d.distance * 1e3));
      p.links.push_back(pr.link_a);
      if (pr.kind == CollisionPair::Kind::Self) p.links.push_back(pr.link_b);
    }
  }
  std::ostringstream os;
  os << collision_.numRobotEnvironmentPairs() << " robot-environment and " << collision_.numSelfPairs()
     << " self pairs; smallest clearance "
     << (std::isfinite(worst_free) ? fmt("%.1f", worst_free * 1e3) + " mm (" + worst_name + ")"
                                   : fmt("over %.0f mm", clearance_cutoff_ * 1e3))
     << "; "
     << n_touch << " contacting pairs, deepest " << fmt("%.3f", std::max(0.0, worst_pen) * 1e3) << " mm";
  p.summary = os.str();
  return p;
}

}  // namespace acyclic
