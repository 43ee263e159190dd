#include "planner/scene/scene.h"

#include <cmath>
#include <set>

#include "planner/common/yaml_field.h"

namespace acyclic {

namespace {

CollisionShape readObstacleShape(const YamlField& o) {
  CollisionShape s;
  const std::string kind = o["shape"].string();
  if (kind == "box") {
    s.kind = CollisionShape::Kind::Box;
    s.size = o["size"].vec3();
    if ((s.size.array() <= 0).any()) o["size"].fail("three positive sizes [x, y, z] in metres");
  } else if (kind == "cylinder" || kind == "capsule") {
    s.kind = kind == "cylinder" ? CollisionShape::Kind::Cylinder : CollisionShape::Kind::Capsule;
    s.radius = o["radius"].number();
    s.length = o["length"].number();
    if (s.radius <= 0) o["radius"].fail("a positive radius in metres");
    if (s.length <= 0) o["length"].fail("a positive length in metres");
  } else if (kind == "sphere") {
    s.kind = CollisionShape::Kind::Sphere;
    s.radius = o["radius"].number();
    if (s.radius <= 0) o["radius"].fail("a positive radius in metres");
  } else {
    o["shape"].fail("one of box, cylinder, capsule, sphere");
  }
  s.pose = readPose(o);
  return s;
}

}  // namespace

std::shared_ptr<const Scene> Scene::load(const std::string& path) {
  YamlField root = YamlField::loadFile(path);
  root.requireFormat("acyclic.scene/1");
  root.allowOnly({"format", "name", "obstacles", "surfaces"});
  auto scene = std::make_shared<Scene>();
  scene->path_ = path;
  std::set<std::string> names;

  YamlField obs = root["obstacles"];
  for (std::size_t i = 0; i < obs.size(); ++i) {
    YamlField o = obs.at(i);
    o.allowOnly({"name", "shape", "size", "radius", "length", "position", "rpy", "rpy_deg", "quaternion"});
    Obstacle ob;
    ob.name = o["name"].string();
    if (!names.insert(ob.name).second) o["name"].fail("a name not used by another obstacle");
    ob.shape = readObstacleShape(o);
    ob.shape.name = ob.name;
    scene->obstacles_.push_back(ob);
  }

  names.clear();
  YamlField surf = root["surfaces"];
  for (std::size_t i = 0; i < surf.size(); ++i) {
    YamlField s = surf.at(i);
    s.allowOnly({"name", "obstacle", "position", "rpy", "rpy_deg", "quaternion", "polygon", "friction"});
    Surface su;
    su.name = s["name"].string();
    if (!names.insert(su.name).second) s["name"].fail("a name not used by another surface");
    su.obstacle = scene->obstacleIndex(s["obstacle"].string());
    if (su.obstacle < 0) s["obstacle"].fail("the name of an obstacle of this scene");
    su.frame = readPose(s);
    su.polygon = s["polygon"].polygon();
    su.friction = s["friction"].number();
    if (su.friction <= 0 || su.friction > 5) s["friction"].fail("a friction coefficient in (0, 5]");
    scene->surfaces_.push_back(su);
  }
  return scene;
}

int Scene::obstacleIndex(const std::string& name) const {
  for (std::size_t i = 0; i < obstacles_.size(); ++i)
    if (obstacles_[i].name == name) return static_cast<int>(i);
  return -1;
}

int Scene::surfaceIndex(const std::string& name) const {
  for (std::size_t i = 0; i < surfaces_.size(); ++i)
    if (surfaces_[i].name == name) return static_cast<int>(i);
  return -1;
}

Eigen::Isometry3d contactFrame(const Surface& s, const SurfacePlacement& p) {
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
  local.translation() = Eigen::Vector3d(p.x, p.y, 0);
  local.linear() = Eigen::AngleAxisd(p.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return s.frame * local;
}

SurfacePlacement projectOnSurface(const Surface& s, const Eigen::Isometry3d& spot_world) {
  const Eigen::Isometry3d local = s.frame.inverse() * spot_world;
  SurfacePlacement p;
  p.x = local.translation().x();
  p.y = local.translation().y();
  p.theta = std::atan2(local.linear()(1, 0), local.linear()(0, 0));
  return p;
}

bool spotNearSurface(const Surface& s, const Eigen::Isometry3d& spot_world, double distance, double angle) {
  const Eigen::Isometry3d local = s.frame.inverse() * spot_world;
  return std::abs(local.translation().z()) <= distance && local.linear()(2, 2) >= std::cos(angle) &&
         s.polygon.contains(local.translation().head<2>());
}

}  // namespace acyclic
