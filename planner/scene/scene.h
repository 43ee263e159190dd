#pragma once
// The environment: obstacles (for collision) and contact surfaces (for
// contacts). Format acyclic.scene/1, documented in docs/design.md section 5.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "planner/common/geometry.h"
#include "planner/model/robot_model.h"  // CollisionShape

namespace acyclic {

struct Obstacle {
  std::string name;
  CollisionShape shape;      // pose in the world
};

struct Surface {
  std::string name;
  int obstacle = -1;         // the obstacle it lies on (a body touching it may touch that obstacle)
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();  // world; z the outward normal
  ConvexPolygon polygon;     // in the frame's xy plane
  double friction = 0.5;     // Coulomb coefficient
};

class Scene {
 public:
  static std::shared_ptr<const Scene> load(const std::string& path);

  const std::string& path() const { return path_; }
  const std::vector<Obstacle>& obstacles() const { return obstacles_; }
  const std::vector<Surface>& surfaces() const { return surfaces_; }
  int obstacleIndex(const std::string& name) const;
  int surfaceIndex(const std::string& name) const;

 private:
  std::string path_;
  std::vector<Obstacle> obstacles_;
  std::vector<Surface> surfaces_;
};

// A contact's placement on a surface: (x, y) in the surface frame and the
// rotation theta about its normal (paper, 2.5).
struct SurfacePlacement {
  double x = 0, y = 0, theta = 0;
};

// World frame of a contact: the surface frame moved by (x, y) and turned by
// theta. In contact, the spot frame coincides with it.
Eigen::Isometry3d contactFrame(const Surface& s, const SurfacePlacement& p);
// The placement of a spot frame projected on a surface (its offset along the
// normal and its tilt are dropped; the contract checks them separately).
SurfacePlacement projectOnSurface(const Surface& s, const Eigen::Isometry3d& spot_world);
// Whether a spot frame rests on a surface, loosely (a key or named posture,
// which holds its contacts only roughly): its origin within `distance` of
// the surface's plane and over its polygon, its z within `angle` of the
// surface's normal (as in contact).
bool spotNearSurface(const Surface& s, const Eigen::Isometry3d& spot_world, double distance = 0.01,
                     double angle = 0.3);

}  // namespace acyclic
