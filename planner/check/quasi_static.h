#pragma once
// Independent quasi-static feasibility check (docs/design.md sections 6 and 9): an
// LP over contact forces at the corners of each supporting contact, built from
// Simbody's gravity torques and station Jacobians only. It shares no code with
// the posture generator beyond the model. Friction: the contract's pyramid
// inscribed in the Coulomb cone (planner/scene/friction.h), by its facets
// (the generator spans it by its edges).
//
// LP 1: the largest margin s such that every facet row
//       mu cos(pi/E) f_n - t_a . f_t >= s at every corner,
//       subject to force and moment balance and |tau_j| <= limit.
// LP 2: the smallest worst torque ratio max_j |tau_j| / limit_j, forces in
//       their pyramids, balance exact.
// tau = g(q) - sum J^T f (holding torques, kinematics.h).
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"

namespace acyclic {

struct QuasiStaticReport {
  bool feasible = false;
  std::string reason;               // why not, when infeasible
  double margin = 0;                // N: LP 1's s (negative: friction must be exceeded); NaN: not computed
  double worst_torque_ratio = 0;    // LP 2's optimum (<= 1 when feasible)
  std::string worst_joint;
  double residual = 0;              // |force and moment balance| / weight, at LP 2's forces
  double worst_cone_ratio = 0;      // max ||f_t|| / (mu f_n) over LP 2's corner forces (<= 1: in the cone)
  int supporting_contacts = 0;
  // Per stance contact, in stance order: world corner points and forces (LP 2);
  // empty for a contact that does not support.
  std::vector<std::vector<Eigen::Vector3d>> points, forces;
};

// How hard a stance can be pushed (QuasiStaticChecker::pushMargin): the
// largest horizontal force at the centre of mass that its supporting
// contacts still balance, quasi-statically (forces in their pyramids,
// torques within limits), in each of `directions` world directions.
struct PushMargin {
  bool computed = false;             // false: no supporting contact, or the stance is not in equilibrium
  double weakest = 0;                // N: the smallest over the directions (capped at the weight)
  double weakest_direction_deg = 0;  // its direction in the world's x-y plane, from +x toward +y
  std::vector<double> per_direction; // N, direction k at 360 k / directions degrees
};

class QuasiStaticChecker {
 public:
  QuasiStaticChecker(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene);
  // At the kinematics' configuration, with the stance's supporting contacts.
  QuasiStaticReport check(const Kinematics& kin, const std::vector<ContactSpec>& stance) const;

  double residualTolerance() const { return 1e-6; }  // relative, docs/design.md section 9

  // Not part of the contract: a figure of how marginal a valid stance is.
  // For each direction d (k 360 / directions degrees about the vertical),
  // the largest s in [0, W] with forces in their pyramids such that
  // sum J^T f + s J_com^T d balances g(q) at the base and keeps every
  // joint's torque within its limit: a push s d at the centre of mass held
  // still. Rigid contacts: a stance on one sole with its centre of mass
  // millimetres inside an edge is valid, and its margin toward that edge is
  // a few newtons, which the compliant soles and servos of the simulation
  // and of the robot do not hold open-loop. Forces are free to
  // redistribute, so a stance held by a squeeze can show a large margin
  // that position servos do not realize (docs/design.md section 9). One LP
  // without a push (none if it fails: out of equilibrium), then one per
  // direction, from scratch; a direction whose LP fails counts as 0.
  PushMargin pushMargin(const Kinematics& kin, const std::vector<ContactSpec>& stance, int directions = 8) const;

  // Off by default. On, each LP starts from the last optimal basis of the
  // same size: checks along a trajectory follow each other closely, so the
  // dual simplex takes a few pivots instead of a solve from scratch (the
  // trajectory check of the chair: 36 s -> 17 s). The optimum (margin, torque
  // ratio) and so the verdict do not depend on the start; the forces reported
  // may, where they are not unique: from the previous basis they follow it
  // continuously (the bridge's ZMP reference uses it for that, computing its
  // samples in order).
  void setWarmStart(bool on) { warm_start_ = on; }
  // On by default. Off, LP 1 is not solved and the report's margin is NaN:
  // the verdict is the same, because LP 2's forces with s = 0 are feasible
  // for LP 1 whenever LP 2's torque ratio is at most 1 (they are inside the
  // pyramids, balance exactly, and keep every torque within its limit), and
  // the check refuses a ratio above 1 anyway. For callers that need only the
  // verdict, thousands of times (a trajectory's samples): half the LPs.
  void setMarginComputed(bool on) { margin_computed_ = on; }

  // Off by default; only with setWarmStart(true) and setMarginComputed(false)
  // (a caller that wants verdicts, one sample after the other). On, a check
  // first tries the forces of the previous check with the same supporting
  // contacts, moved by the least-norm change that restores the base's
  // balance at this posture: when they stay inside every pyramid facet and
  // keep every torque within (1 - 1e-6) of its limit, forces exist and LP 2
  // is not solved. The verdict is the same (LP 2's optimum is at most that
  // point's torque ratio, below 1); the report's torque ratio is that
  // point's, an upper bound of LP 2's optimum, and its forces are that
  // point's. Otherwise LP 2 is solved as without it and decides; the next
  // check's point is then the midpoint of LP 2's and LP 1's forces, inside
  // both the facets and the limits (each LP's own vertex has corners and
  // facets, or a torque, exactly at their bounds, which the next sample's
  // change leaves). Along an interpolated piece most samples are a small move
  // from the last: the interpolator's checks skip most of their LPs.
  void setForcesReused(bool on) { reuse_forces_ = on; }
  long forcesReused() const { return reused_; }  // checks decided without an LP, since construction

  struct WarmStart {
    int rows = -1, cols = -1;
    std::vector<unsigned char> status;
  };
  // The next check's point (setForcesReused): corner forces (f_n, f_t1,
  // f_t2 per corner) for these supporting contacts (spot, surface), in
  // stance order; none after a check that could not give one.
  struct LastForces {
    std::vector<std::pair<int, int>> contacts;
    Eigen::VectorXd f;
  };

 private:
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  // Guarded: a checker shared by threads solves cold when another holds it.
  bool warm_start_ = false;
  bool margin_computed_ = true;
  bool reuse_forces_ = false;
  mutable std::mutex warm_mutex_;
  mutable WarmStart warm_[2];
  mutable LastForces last_;  // guarded by warm_mutex_, as warm_
  mutable std::atomic<long> reused_{0};
};

}  // namespace acyclic
