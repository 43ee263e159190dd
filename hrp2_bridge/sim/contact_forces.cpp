#include "hrp2_bridge/sim/contact_forces.h"

#include <cmath>

namespace acyclic::hrp2 {

ContactForces::ContactForces(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene)
    : robot_(robot), scene_(scene), kin_(robot), lp_(robot, scene) {}

std::vector<ContactSpec> ContactForces::detect(const Configuration& q, double distance, double angle) {
  kin_.setConfiguration(q);
  std::vector<ContactSpec> out;
  const auto& surfaces = scene_->surfaces();
  for (int i = 0; i < static_cast<int>(robot_->spots().size()); ++i) {
    const Eigen::Isometry3d spot = kin_.spotPose(i);
    for (int s = 0; s < static_cast<int>(surfaces.size()); ++s) {
      const Surface& sf = surfaces[s];
      const Eigen::Vector3d n = sf.frame.linear().col(2);
      // In contact the spot's z (into the body) equals the surface's outward normal.
      if (spot.linear().col(2).dot(n) < std::cos(angle)) continue;
      const Eigen::Vector3d local = sf.frame.inverse() * spot.translation();
      if (std::abs(local.z()) > distance) continue;
      if (!sf.polygon.contains(local.head<2>(), distance)) continue;
      ContactSpec c;
      c.spot = i;
      c.surface = s;
      c.supporting = true;
      c.placement = projectOnSurface(sf, spot);
      out.push_back(c);
      break;
    }
  }
  return out;
}

std::vector<ContactWrench> ContactForces::compute(const Configuration& q, bool* equilibrium) {
  const std::vector<ContactSpec> contacts = detect(q);
  std::vector<ContactWrench> out;
  const QuasiStaticReport rep = contacts.empty() ? QuasiStaticReport{} : lp_.check(kin_, contacts);
  if (equilibrium) *equilibrium = rep.feasible;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    ContactWrench w;
    w.name = robot_->spots()[contacts[c].spot].name;
    if (rep.feasible) {
      const Eigen::Isometry3d frame = kin_.spotPose(contacts[c].spot);
      Eigen::Vector3d f = Eigen::Vector3d::Zero(), m = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < rep.forces[c].size(); ++k) {
        f += rep.forces[c][k];
        m += (rep.points[c][k] - frame.translation()).cross(rep.forces[c][k]);
      }
      w.wrench.head<3>() = frame.linear().transpose() * f;
      w.wrench.tail<3>() = frame.linear().transpose() * m;
    }
    out.push_back(w);
  }
  return out;
}

}  // namespace acyclic::hrp2
