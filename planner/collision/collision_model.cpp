#include "planner/collision/collision_model.h"

#include <cmath>

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include "planner/collision/convex_distance.h"

namespace acyclic {

namespace {

std::shared_ptr<fcl::CollisionGeometryd> makeGeometry(const CollisionShape& s) {
  std::shared_ptr<fcl::CollisionGeometryd> g;
  switch (s.kind) {
    case CollisionShape::Kind::Box:
      g = std::make_shared<fcl::Boxd>(s.size.x(), s.size.y(), s.size.z());
      break;
    case CollisionShape::Kind::Capsule:
      g = std::make_shared<fcl::Capsuled>(s.radius, s.length);
      break;
    case CollisionShape::Kind::Cylinder:
      g = std::make_shared<fcl::Cylinderd>(s.radius, s.length);
      break;
    case CollisionShape::Kind::Sphere:
      g = std::make_shared<fcl::Sphered>(s.radius);
      break;
  }
  g->computeLocalAABB();
  return g;
}

// Radius of a sphere about the shape's origin that contains it.
double boundingRadius(const CollisionShape& s) {
  switch (s.kind) {
    case CollisionShape::Kind::Box: return 0.5 * s.size.norm();
    case CollisionShape::Kind::Capsule: return 0.5 * s.length + s.radius;
    case CollisionShape::Kind::Cylinder: return std::hypot(0.5 * s.length, s.radius);
    case CollisionShape::Kind::Sphere: return s.radius;
  }
  return 0;
}

fcl::DistanceRequestd makeDistanceRequest() {
  fcl::DistanceRequestd req(true);  // nearest points; unsigned (see fclDistance)
  req.gjk_solver_type = fcl::GST_LIBCCD;
  req.distance_tolerance = 1e-9;    // GJK stops at 1e-6 by default: too coarse for gradients
  return req;
}

// Signed distance with world witness points. Separated shapes: GJK distance.
// Penetrating shapes: the depth and normal of fcl::collide's contact. FCL's
// own signed distance (its EPA) is not used: Debian's FCL 0.7 is built with
// assertions and aborts inside that EPA on some penetrating pairs.
double fclDistance(const fcl::CollisionGeometryd* ga, const Eigen::Isometry3d& Ta, const fcl::CollisionGeometryd* gb,
                   const Eigen::Isometry3d& Tb, Eigen::Vector3d* pa, Eigen::Vector3d* pb) {
  static const fcl::DistanceRequestd dreq = makeDistanceRequest();
  const fcl::Transform3d Xa(Ta.matrix()), Xb(Tb.matrix());
  fcl::DistanceResultd dres;
  fcl::distance(ga, Xa, gb, Xb, dreq, dres);
  if (dres.min_distance > 0) {
    if (pa) *pa = dres.nearest_points[0];
    if (pb) *pb = dres.nearest_points[1];
    return dres.min_distance;
  }
  fcl::CollisionRequestd creq(1, true);  // one contact, with depth and normal
  creq.gjk_solver_type = fcl::GST_LIBCCD;
  fcl::CollisionResultd cres;
  fcl::collide(ga, Xa, gb, Xb, creq, cres);
  if (!cres.isCollision() || cres.numContacts() == 0) {
    // Touching within GJK's tolerance: distance zero at the shapes' closest point.
    if (pa) *pa = dres.nearest_points[0];
    if (pb) *pb = dres.nearest_points[0];
    return 0.0;
  }
  const fcl::Contactd& c = cres.getContact(0);
  // normal points from a to b; a's deepest point lies depth/2 along it from pos
  const Eigen::Vector3d n = c.normal.normalized();
  if (pa) *pa = c.pos + 0.5 * c.penetration_depth * n;
  if (pb) *pb = c.pos - 0.5 * c.penetration_depth * n;
  return -c.penetration_depth;
}

}  // namespace

double shapeDistance(const CollisionShape& a, const Eigen::Isometry3d& Ta, const CollisionShape& b,
                     const Eigen::Isometry3d& Tb, Eigen::Vector3d* point_a, Eigen::Vector3d* point_b) {
  auto ga = makeGeometry(a);
  auto gb = makeGeometry(b);
  return fclDistance(ga.get(), Ta, gb.get(), Tb, point_a, point_b);
}

struct CollisionModel::Geometry {
  // robot[link][shape], obstacles[i]
  std::vector<std::vector<std::shared_ptr<fcl::CollisionGeometryd>>> robot;
  std::vector<std::vector<double>> robot_radius;
  std::vector<std::vector<convex::Primitive>> robot_primitive;  // the Convex engine's
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> obstacles;
  std::vector<convex::Primitive> obstacle_primitive;
  std::vector<fcl::AABBd> obstacle_aabb;  // world
};

std::optional<DistanceEngine> distanceEngineNamed(const std::string& name) {
  if (name == "fcl") return DistanceEngine::Fcl;
  if (name == "convex") return DistanceEngine::Convex;
  return std::nullopt;
}

CollisionModel::CollisionModel(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                               DistanceEngine engine)
    : robot_(std::move(robot)), scene_(std::move(scene)), engine_(engine), geom_(std::make_unique<Geometry>()) {
  const auto& links = robot_->links();
  geom_->robot.resize(links.size());
  geom_->robot_radius.resize(links.size());
  geom_->robot_primitive.resize(links.size());
  for (const auto& l : links)
    for (const auto& s : l.shapes) {
      geom_->robot[l.index].push_back(makeGeometry(s));
      geom_->robot_radius[l.index].push_back(boundingRadius(s));
      geom_->robot_primitive[l.index].push_back(convex::primitiveOf(s));
    }
  for (const auto& o : scene_->obstacles()) {
    geom_->obstacles.push_back(makeGeometry(o.shape));
    geom_->obstacle_primitive.push_back(convex::primitiveOf(o.shape));
  }
  for (std::size_t i = 0; i < scene_->obstacles().size(); ++i) {
    // World AABB: transform the local AABB's corners.
    const auto& local = geom_->obstacles[i]->aabb_local;
    const Eigen::Isometry3d& T = scene_->obstacles()[i].shape.pose;
    fcl::AABBd world;
    bool first = true;
    for (int c = 0; c < 8; ++c) {
      Eigen::Vector3d p((c & 1) ? local.max_.x() : local.min_.x(), (c & 2) ? local.max_.y() : local.min_.y(),
                        (c & 4) ? local.max_.z() : local.min_.z());
      p = T * p;
      if (first) world = fcl::AABBd(p), first = false;
      else world += p;
    }
    geom_->obstacle_aabb.push_back(world);
  }

  // Robot-environment: every robot shape against every obstacle.
  for (const auto& l : links)
    for (std::size_t s = 0; s < l.shapes.size(); ++s)
      for (std::size_t o = 0; o < scene_->obstacles().size(); ++o) {
        CollisionPair p;
        p.kind = CollisionPair::Kind::RobotEnvironment;
        p.link_a = l.index;
        p.shape_a = static_cast<int>(s);
        p.obstacle = static_cast<int>(o);
        pairs_.push_back(p);
      }
  n_env_ = static_cast<int>(pairs_.size());
  // Self: every shape pair of the listed link pairs.
  for (const auto& [a, b] : robot_->selfCollisionPairs())
    for (std::size_t sa = 0; sa < links[a].shapes.size(); ++sa)
      for (std::size_t sb = 0; sb < links[b].shapes.size(); ++sb) {
        CollisionPair p;
        p.kind = CollisionPair::Kind::Self;
        p.link_a = a;
        p.shape_a = static_cast<int>(sa);
        p.link_b = b;
        p.shape_b = static_cast<int>(sb);
        pairs_.push_back(p);
      }
}

CollisionModel::~CollisionModel() = default;

std::string CollisionModel::describe(int i) const {
  const CollisionPair& p = pairs_.at(i);
  const auto& la = robot_->links()[p.link_a];
  std::string a = la.name + "/" + la.shapes[p.shape_a].name;
  if (p.kind == CollisionPair::Kind::RobotEnvironment) return a + " ~ " + scene_->obstacles()[p.obstacle].name;
  const auto& lb = robot_->links()[p.link_b];
  return a + " ~ " + lb.name + "/" + lb.shapes[p.shape_b].name;
}

double CollisionModel::lowerBound(const Kinematics& kin, int i) const {
  const CollisionPair& p = pairs_[i];
  const auto& links = robot_->links();
  const Eigen::Vector3d ca = kin.linkPose(p.link_a) * links[p.link_a].shapes[p.shape_a].pose.translation();
  const double ra = geom_->robot_radius[p.link_a][p.shape_a];
  if (p.kind == CollisionPair::Kind::RobotEnvironment) {
    const fcl::AABBd& box = geom_->obstacle_aabb[p.obstacle];
    return (ca - ca.cwiseMax(box.min_).cwiseMin(box.max_)).norm() - ra;
  }
  const Eigen::Vector3d cb = kin.linkPose(p.link_b) * links[p.link_b].shapes[p.shape_b].pose.translation();
  return (ca - cb).norm() - ra - geom_->robot_radius[p.link_b][p.shape_b];
}

std::vector<int> CollisionModel::pairsWithin(const Kinematics& kin, double cutoff) const {
  std::vector<int> out;
  for (int i = 0; i < static_cast<int>(pairs_.size()); ++i)
    if (mayBeWithin(kin, i, cutoff)) out.push_back(i);
  return out;
}

PairDistance CollisionModel::pairDistance(const Kinematics& kin, int i, bool gradient) const {
  const CollisionPair& p = pairs_[i];
  const auto& links = robot_->links();
  const Eigen::Isometry3d Ta = kin.linkPose(p.link_a) * links[p.link_a].shapes[p.shape_a].pose;
  Eigen::Isometry3d Tb;
  const fcl::CollisionGeometryd* gb;
  const convex::Primitive* cb;
  if (p.kind == CollisionPair::Kind::RobotEnvironment) {
    gb = geom_->obstacles[p.obstacle].get();
    cb = &geom_->obstacle_primitive[p.obstacle];
    Tb = scene_->obstacles()[p.obstacle].shape.pose;
  } else {
    gb = geom_->robot[p.link_b][p.shape_b].get();
    cb = &geom_->robot_primitive[p.link_b][p.shape_b];
    Tb = kin.linkPose(p.link_b) * links[p.link_b].shapes[p.shape_b].pose;
  }
  PairDistance d;
  d.pair = i;
  bool found = false;
  Eigen::Vector3d core_normal = Eigen::Vector3d::Zero();  // the Convex engine's, from A toward B
  if (engine_ == DistanceEngine::Convex) {
    const convex::Separation s = convex::separation(geom_->robot_primitive[p.link_a][p.shape_a], Ta, *cb, Tb);
    if (!s.cores_overlap) {
      d.distance = s.distance;
      d.point_a = s.point_a;
      d.point_b = s.point_b;
      core_normal = s.normal;
      found = true;
    }
  }
  if (!found) d.distance = fclDistance(geom_->robot[p.link_a][p.shape_a].get(), Ta, gb, Tb, &d.point_a, &d.point_b);
  if (gradient) {
    // d = n . (pb - pa) with n = (pb - pa) / d for either sign of d, so
    // grad d = n^T (J_b(pb) - J_a(pa)). At contact (d ~ 0) the witness
    // points coincide: the cores' normal stands in for n where the Convex
    // engine has one, else the line between the shapes' centres.
    Eigen::Vector3d n;
    if (std::abs(d.distance) > 1e-9 && (d.point_b - d.point_a).norm() > 1e-9)
      n = (d.point_b - d.point_a) / d.distance;
    else if (found)
      n = core_normal;
    else
      n = (Tb.translation() - Ta.translation()).normalized();
    d.gradient = Eigen::VectorXd::Zero(robot_->tangentSize());
    kin.addPointGradient(p.link_a, d.point_a, -n, d.gradient);
    if (p.kind == CollisionPair::Kind::Self) kin.addPointGradient(p.link_b, d.point_b, n, d.gradient);
  }
  return d;
}

std::vector<PairDistance> CollisionModel::distances(const Kinematics& kin, const DistanceOptions& opt) const {
  std::vector<PairDistance> out;
  out.reserve(pairs_.size());
  for (int i = 0; i < static_cast<int>(pairs_.size()); ++i) {
    if (std::isfinite(opt.cutoff) && lowerBound(kin, i) > opt.cutoff) continue;
    out.push_back(pairDistance(kin, i, opt.gradients));
  }
  return out;
}

}  // namespace acyclic
