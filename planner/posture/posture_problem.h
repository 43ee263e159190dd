#pragma once
// The posture generator's nonlinear program (docs/design.md section 6), evaluated
// without Ipopt so that every derivative can be tested on its own.
//
// Variables x = [ configuration (tangent offset from the initial guess: base
// translation, base rotation vector R = exp(w) R0, joints) | floating contact
// (x, y, theta) if any | friction-pyramid coefficients lambda >= 0, one per
// pyramid edge (planner/scene/friction.h) at each corner of each supporting
// contact, in units of the robot's weight ].
//
// Constraints (rows, in this order):
//   contacts    6 per contact (the fixed ones, the floating one, then the pose
//               target if any): spot origin on its target point (3); spot z
//               along the surface normal (2: z_s . x_t = z_s . y_t = 0); in-plane
//               angle (1: x_s . y_t = 0)
//   floating    (x, y) inside the search polygon; each spot-polygon corner
//               inside the surface polygon
//   statics     h = (g(q) - sum J^T f) / weight over the supporting contacts' corners
//               (moved inward by PostureOptions::support_inset):
//               6 base rows = 0 (forces; moments about the world origin),
//               30 joint rows within the torque limits
//   collision   signed distance >= margin for each active pair
// Contacts that are not supporting (being added or removed) are geometric only.
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "planner/collision/collision_model.h"
#include "planner/posture/posture_cost.h"
#include "planner/scene/friction.h"
#include "planner/scene/scenario.h"

namespace acyclic {

// How far a spot polygon's corner may lie outside its surface polygon (the
// validity contract's 1 mm, docs/design.md section 9): a fixed contact's
// placement is refused beyond it, and a floating contact's footprint solved
// again (PostureGenerator::solve).
constexpr double kContactPolygonTolerance = 1e-3;

// The floating contact's search volume C_i: (x, y) in a convex polygon of the
// surface frame, theta in [theta_min, theta_max].
struct SearchVolume {
  ConvexPolygon polygon;
  double theta_min = -M_PI;
  double theta_max = M_PI;
};

struct FloatingContact {
  int spot = -1;
  int surface = -1;
  SearchVolume volume;
  // The contact rows fix the spot's angle only modulo pi: a solve can end
  // with the spot half a turn from the solver's angle. The footprint rows
  // hold the spot's polygon at the solver's angle, or, with this set, half
  // a turn from it (PostureGenerator::solve sets it to solve again when a
  // solve ends so with the spot's own footprint off the surface).
  bool footprint_turned = false;
};

// A spot's frame held at a world pose, with no surface (the interpolator's
// moving body): 6 rows like a contact's, the origin's offset expressed in the
// pose's frame (so that it can be bounded along and across a surface normal),
// z along its z, x orthogonal to its y. Geometric only.
struct PoseTarget {
  int spot = -1;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // Obstacles the spot's link comes close to on purpose (the surfaces it
  // leaves or reaches): its clearance to them is at least touch_margin
  // instead of the collision margin.
  std::vector<int> touch_obstacles;
  double touch_margin = 0;
  // Bounds on the origin's offset from the pose's origin, in the pose's frame
  // (0: exactly on it).
  Eigen::Vector3d position_tolerance = Eigen::Vector3d::Zero();
  // Bound on each orientation row (about the sine of the tilt about each
  // axis): 0 holds the orientation exactly; a body in the air needs only its
  // position on the path, its orientation roughly.
  double orientation_tolerance = 0;
};

struct PostureRequest {
  std::vector<ContactSpec> contacts;        // fixed contacts (placement given)
  std::optional<FloatingContact> floating;  // at most one, geometric only
  std::optional<PoseTarget> pose_target;    // at most one; rows after the floating contact's
  Configuration initial_guess;
  std::shared_ptr<const PostureCost> cost;  // default: distance to the initial guess
  // Solved again from this guess when the solve from initial_guess fails
  // (PostureGenerator::solve; the cost as it was: the default cost stays the
  // distance to initial_guess). Ipopt is local: the planner retries an added
  // contact with its limb where the guide holds it (guide_limb_guess).
  std::optional<Configuration> retry_guess;
};

struct PostureOptions {
  double collision_margin = 0.005;   // m
  double collision_cutoff = 0.15;    // m: pairs farther than this at the start are left out
  // Generators per corner: edges of the pyramid inscribed in the cone
  // (friction.h), a divisor of the contract's count so that they are edges
  // of the contract's pyramid: the forces are inside the contract's pyramid
  // and the true cone either way.
  // 4 by default (every other edge: 0.707 mu usable in the worst direction
  // instead of 0.924, a smaller pyramid, so more conservative). With all 8
  // the witnesses change, and what is built on them is chaotic in them: the
  // chair's search took 593 nodes instead of 407 and made a plan with a foot
  // step the interpolator cannot make, two of the interpolator's narrow
  // chair transitions failed, sit_down's OMPL guide no longer led to a plan
  // in 300 nodes. 8 is an option (scenario posture_pyramid_edges,
  // acyclic-interpolator --pyramid-edges, acyclic-posture --pyramid-edges).
  int pyramid_sides = 4;
  // Margins that keep a solution strictly inside what the independent check
  // accepts (an optimum sits on its constraints' boundary): each corner's
  // pyramid coefficients at least this in all (body weights), split evenly
  // among its edges (so the least force on a corner does not depend on how
  // many edges span its pyramid), torques within this share of their limits.
  double min_corner_force = 8e-3;
  double torque_share = 0.98;
  // Stability margins (0 and 1: none, the witnesses on the edges of what
  // the check accepts). Executing a plan on compliant soles with servos that
  // do not track its forces needs them: a centre of pressure at a sole's
  // edge rolls the robot over it.
  // support_inset (m): the forces of each supporting contact applied at the
  // corners of its spot polygon shrunk by this much (ConvexPolygon::inset:
  // every edge moved inward, capped at three quarters of the centroid's
  // distance to the nearest edge), so that its centre of pressure stays this far inside the
  // real edges. friction_share: the pyramid's edges at friction_share * mu
  // (in (0, 1]): tangential forces within that share of the friction.
  // Both only shrink the set of forces the generator may use (points inside
  // the spot, edges inside the contract's pyramid): its witnesses still pass
  // the check, which is unchanged.
  double support_inset = 0;
  // support_inset_y >= 0: the inset along the spot's y axis instead (across a
  // sole; along it, x, support_inset): the spot eroded by a box (ConvexPolygon::inset(dx, dy)).
  double support_inset_y = -1;
  double friction_share = 1;
  double force_regularization = 1e-4;  // small cost on lambda^2 (lambda in body weights): unique forces
};

class PostureProblem {
 public:
  // Throws std::invalid_argument on a request that cannot be posed (with the reason).
  PostureProblem(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                 std::shared_ptr<const CollisionModel> collision, const PostureRequest& request,
                 const PostureOptions& options);

  int numVariables() const { return nx_; }
  int numConstraints() const { return ng_; }
  void bounds(Eigen::VectorXd& x_lo, Eigen::VectorXd& x_hi, Eigen::VectorXd& g_lo, Eigen::VectorXd& g_hi) const;
  Eigen::VectorXd initialPoint() const;
  // Sparsity of the constraint Jacobian (row, column), fixed for the problem.
  const std::vector<std::pair<int, int>>& jacobianStructure() const { return structure_; }

  double cost(const Eigen::VectorXd& x);
  Eigen::VectorXd costGradient(const Eigen::VectorXd& x);
  Eigen::VectorXd constraints(const Eigen::VectorXd& x);
  const Eigen::MatrixXd& constraintJacobian(const Eigen::VectorXd& x);  // dense, rows x variables
  void jacobianValues(const Eigen::VectorXd& x, double* values);       // in structure order

  // A constant positive diagonal approximating the Lagrangian's Hessian: the
  // cost's curvature, the constraints' neglected.
  Eigen::VectorXd hessianDiagonal() const;

  // The Hessian of the Lagrangian sigma f + sum y_i g_i, analytic but for:
  // the cost (its diagonal), the collision rows' curvature (left out), and the
  // second-order terms of the base rotation-vector parameterization. Contact,
  // floating-contact and statics rows (gravity and contact forces, through
  // nested products of the joint axes) are exact.
  // Lower triangle, in the order of hessianStructure().
  const std::vector<std::pair<int, int>>& hessianStructure() const { return hstructure_; }
  Eigen::MatrixXd lagrangianHessian(const Eigen::VectorXd& x, double sigma, const Eigen::VectorXd& y);  // dense, symmetric
  void hessianValues(const Eigen::VectorXd& x, double sigma, const Eigen::VectorXd& y, double* values);

  Configuration configurationAt(const Eigen::VectorXd& x) const;
  SurfacePlacement floatingAt(const Eigen::VectorXd& x) const;
  // World corner points and forces of each supporting contact.
  struct ContactForces {
    int contact = -1;  // index into the request's contacts
    std::vector<Eigen::Vector3d> points, forces;
  };
  std::vector<ContactForces> forcesAt(const Eigen::VectorXd& x) const;

  // Row ranges, for reports and tests.
  int contactRows() const { return row_floating_; }
  int statics_row() const { return row_statics_; }
  int collisionRow() const { return row_collision_; }
  const std::vector<int>& collisionPairs() const { return pairs_; }
  // Adds pairs to the collision rows (constraint generation); re-plans the layout.
  void addCollisionPairs(const std::vector<int>& pairs);

 private:
  // Each pyramid coefficient's floor: the corner's least force split among its edges.
  double minCoefficient() const { return opt_.min_corner_force / opt_.pyramid_sides; }
  struct Support {             // a supporting contact's force model
    int contact;
    int link;
    std::vector<Eigen::Vector3d> corners;  // world (target) points
    std::vector<Eigen::Vector3d> generators;  // unit, world
    int lambda0;               // first lambda variable
  };
  // Contact ci (the floating one last) at the current kinematics: its spot's
  // link, the spot's world frame and the target frame it must coincide with.
  struct ContactGeometry {
    bool floating;
    int link;
    Eigen::Isometry3d spot, target;
  };
  int numContacts() const {
    return static_cast<int>(req_.contacts.size()) + (req_.floating ? 1 : 0) + (req_.pose_target ? 1 : 0);
  }
  ContactGeometry contactGeometry(int ci, const Eigen::VectorXd& x) const;
  int spotOf(int ci) const;  // the spot of contact row block ci
  void layout();
  void evaluate(const Eigen::VectorXd& x);
  Eigen::Matrix3d leftJacobian(const Eigen::Vector3d& w) const;

  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  std::shared_ptr<const CollisionModel> collision_;
  PostureRequest req_;
  PostureOptions opt_;
  Kinematics kin_;
  std::vector<Support> supports_;
  std::vector<int> pairs_;
  std::vector<std::pair<int, int>> allowed_touch_;  // (link, obstacle)
  std::vector<std::pair<int, int>> near_touch_;     // (link, obstacle): the pose target's, at touch_margin
  // The floating spot's polygon as its footprint rows hold it in the frame
  // of the solver's angle (FloatingContact::footprint_turned).
  std::vector<Eigen::Vector2d> floating_footprint_;

  int nq_ = 0, nx_ = 0, ng_ = 0;
  int x_float_ = -1, x_lambda_ = -1, n_lambda_ = 0;
  int row_floating_ = 0, n_float_rows_ = 0, row_statics_ = 0, row_collision_ = 0;
  std::vector<std::pair<int, int>> structure_, hstructure_;

  // Evaluation cache.
  bool valid_ = false;
  Eigen::VectorXd x_cached_;
  double f_ = 0;
  Eigen::VectorXd grad_f_, g_;
  Eigen::MatrixXd jac_;
};

}  // namespace acyclic
