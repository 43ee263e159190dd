#pragma once
// Distance between two of the model's primitives (box, capsule, sphere,
// cylinder) by GJK on their cores: a box or a cylinder is its own core, a
// capsule is a segment and a sphere a point, each swept by its radius, so
// that the rounded shapes need no iteration on a curved surface and their
// distance is the cores' less the radii.
//
// Why not FCL's GJK (which CollisionModel uses for the independent check):
// the posture generator evaluates 60-140 pairs at every iterate, and FCL's
// libccd GJK took 1-3 us a pair (its own GJK no less; bench_collision), a
// third of a posture call (perf). This one works in the first
// shape's frame with support functions that are a few sign tests.
//
// It answers separated cores only: when they overlap (penetration deeper
// than the radii) it says so, and the caller asks FCL for the penetration
// depth (CollisionModel). Where a capsule's or a sphere's core first
// touches, the distance (exactly minus its radius up to there) then becomes
// FCL's estimate of the depth: continuous to that estimate's accuracy only.
// An optimizer meets it only from a start deep in an obstacle.
#include <Eigen/Geometry>

#include "planner/model/robot_model.h"

namespace acyclic::convex {

// A primitive as a core swept by a sphere of radius `sweep`.
struct Primitive {
  enum class Core { Point, Segment, Box, Cylinder };
  Core core = Core::Point;
  Eigen::Vector3d half = Eigen::Vector3d::Zero();  // box: half sizes; segment: z half length; cylinder: (r, r, h/2)
  double sweep = 0;
  // The point of the core farthest along d (local frame).
  Eigen::Vector3d support(const Eigen::Vector3d& d) const;
};

Primitive primitiveOf(const CollisionShape& s);

struct Separation {
  bool cores_overlap = false;  // distance, points and normal are meaningless then
  double distance = 0;         // between the swept shapes: negative when a sweep penetrates
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero(), point_b = Eigen::Vector3d::Zero();  // world witness points
  // Unit, world, from the first core's nearest point toward the second's:
  // point_b - point_a = distance * normal for either sign of distance (and
  // the normal is still there when the shapes just touch).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  int iterations = 0;
};

// Distance between a at Ta and b at Tb. The cores' distance is found within
// `tolerance` (m): exactly, up to rounding, when neither core is a
// cylinder (polytopes: GJK ends on the exact simplex).
Separation separation(const Primitive& a, const Eigen::Isometry3d& Ta, const Primitive& b, const Eigen::Isometry3d& Tb,
                      double tolerance = 1e-10);

}  // namespace acyclic::convex
