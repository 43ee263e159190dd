#include "hrp2_bridge/references.h"

#include <cmath>

#include "hrp2_bridge/stabilizer_schedule.h"
#include "planner/common/geometry.h"

namespace acyclic::hrp2 {

namespace {

// The ground plane under the robot: the plane of the first foot contact, or
// the horizontal plane z = 0 when no foot touches anything.
void groundPlane(const std::vector<ContactSpec>& contacts, const RobotModel& m, const Scene& scene,
                 Eigen::Vector3d& point, Eigen::Vector3d& normal) {
  point = Eigen::Vector3d::Zero();
  normal = Eigen::Vector3d::UnitZ();
  for (const ContactSpec& c : contacts)
    if (isFootSpot(m, c.spot)) {
      const Surface& s = scene.surfaces().at(c.surface);
      point = s.frame.translation();
      normal = s.frame.linear().col(2);
      return;
    }
}

// The vertical line through p meets the plane (point, normal); a plane
// parallel to gravity has no such point, so p is projected orthogonally.
Eigen::Vector3d alongGravity(const Eigen::Vector3d& p, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  const double nz = normal.z();
  if (std::abs(nz) < 1e-6) return p - normal * normal.dot(p - point);
  return p - Eigen::Vector3d::UnitZ() * (normal.dot(p - point) / nz);
}

}  // namespace

ReferenceModel::ReferenceModel(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene)
    : robot_(robot), scene_(scene), kin_(robot), lp_(robot, scene) {
  lp_.setWarmStart(true);
}

WaistZmp ReferenceModel::compute(const Configuration& q, const std::vector<ContactSpec>& contacts,
                                 bool coplanar_feet) {
  WaistZmp r;
  r.waist_position = q.base_position;
  r.waist_rpy = quaternionToRpy(q.base_orientation);
  kin_.setConfiguration(q);
  Eigen::Vector3d point, normal;
  groundPlane(contacts, *robot_, *scene_, point, normal);
  r.zmp_world = alongGravity(kin_.centerOfMass(), point, normal);
  if (!coplanar_feet) {
    std::vector<ContactSpec> supporting;
    for (const ContactSpec& c : contacts)
      if (c.supporting) supporting.push_back(c);
    const QuasiStaticReport rep = lp_.check(kin_, supporting);
    if (!rep.feasible) {
      r.lp_failed = true;
    } else {
      // Centre of pressure of the feet's corner forces on the ground plane.
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      double fn = 0;
      for (std::size_t c = 0; c < supporting.size(); ++c) {
        if (!isFootSpot(*robot_, supporting[c].spot)) continue;
        for (std::size_t k = 0; k < rep.points[c].size(); ++k) {
          const double f = rep.forces[c][k].dot(normal);
          sum += f * rep.points[c][k];
          fn += f;
        }
      }
      if (fn > 0.01 * robot_->totalMass() * 9.81) {
        const Eigen::Vector3d cop = sum / fn;
        r.zmp_world = cop - normal * normal.dot(cop - point);  // corners lie on the plane up to 1 mm
        r.from_forces = true;
      }
    }
  }
  const Eigen::Isometry3d waist = q.basePose();
  r.zmp_waist = waist.inverse() * r.zmp_world;
  return r;
}

}  // namespace acyclic::hrp2
