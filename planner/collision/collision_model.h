#pragma once
// Signed distances between the robot and the scene and between listed robot
// links, with witness points and gradients (FCL for the geometry, Simbody
// Jacobians for the derivatives). docs/design.md sections 5 and 6.
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "planner/model/kinematics.h"
#include "planner/scene/scene.h"

namespace acyclic {

struct CollisionPair {
  enum class Kind { RobotEnvironment, Self };
  Kind kind = Kind::RobotEnvironment;
  int link_a = -1, shape_a = -1;   // robot link and its shape index
  int link_b = -1, shape_b = -1;   // Self: second robot link and shape
  int obstacle = -1;               // RobotEnvironment: the obstacle
};

struct PairDistance {
  int pair = -1;
  double distance = 0;             // signed, m: negative when penetrating
  Eigen::Vector3d point_a, point_b;  // world witness points on a and on b
  Eigen::VectorXd gradient;        // d distance / d configuration (tangent); empty unless asked
};

struct DistanceOptions {
  bool gradients = false;
  // Pairs certainly farther apart than this (by bounding volumes) are skipped.
  double cutoff = std::numeric_limits<double>::infinity();
};

// Signed distance between two primitives at world poses, with world witness
// points (FCL; the routine every pair of CollisionModel goes through).
double shapeDistance(const CollisionShape& a, const Eigen::Isometry3d& Ta, const CollisionShape& b,
                     const Eigen::Isometry3d& Tb, Eigen::Vector3d* point_a = nullptr,
                     Eigen::Vector3d* point_b = nullptr);

// How a pair's distance is computed. Fcl: FCL's GJK (libccd) for separated
// shapes, its collide() for the depth of penetrating ones; the independent
// checks use it. Convex: convex::separation (convex_distance.h) for
// separated shapes, several times faster, and FCL when the shapes' cores
// overlap; the posture generator's default (PostureGeneratorOptions), so that
// the check's distances come from other code than the generator's.
enum class DistanceEngine { Fcl, Convex };
// The engine named "fcl" or "convex" (scenario fields, command lines); none for another name.
std::optional<DistanceEngine> distanceEngineNamed(const std::string& name);

class CollisionModel {
 public:
  CollisionModel(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                 DistanceEngine engine = DistanceEngine::Fcl);
  ~CollisionModel();

  const std::vector<CollisionPair>& pairs() const { return pairs_; }
  std::string describe(int pair) const;  // "RLEG_LINK2/capsule_thigh ~ chair_seat"
  int numRobotEnvironmentPairs() const { return n_env_; }
  int numSelfPairs() const { return static_cast<int>(pairs_.size()) - n_env_; }
  DistanceEngine engine() const { return engine_; }

  // Distances of every pair (within the cutoff) at the kinematics' configuration.
  // Thread-safe: the model is read-only; use one Kinematics per thread.
  std::vector<PairDistance> distances(const Kinematics& kin, const DistanceOptions& opt = {}) const;
  // One pair's distance (and gradient if asked).
  PairDistance pairDistance(const Kinematics& kin, int pair, bool gradient) const;
  // The pairs that bounding volumes cannot rule out within `cutoff`.
  std::vector<int> pairsWithin(const Kinematics& kin, double cutoff) const;
  // Whether bounding volumes cannot rule pair `pair` out within `cutoff`
  // (pairsWithin's test for one pair).
  bool mayBeWithin(const Kinematics& kin, int pair, double cutoff) const { return lowerBound(kin, pair) <= cutoff; }

 private:
  struct Geometry;
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  std::vector<CollisionPair> pairs_;
  int n_env_ = 0;
  DistanceEngine engine_;
  double lowerBound(const Kinematics& kin, int pair) const;
  std::unique_ptr<Geometry> geom_;
};

}  // namespace acyclic
