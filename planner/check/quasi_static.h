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

class QuasiStaticChecker {
 public:
  QuasiStaticChecker(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene);
  // At the kinematics' configuration, with the stance's supporting contacts.
  QuasiStaticReport check(const Kinematics& kin, const std::vector<ContactSpec>& stance) const;

  double residualTolerance() const { return 1e-6; }  // relative, docs/design.md section 9

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

  struct WarmStart {
    int rows = -1, cols = -1;
    std::vector<unsigned char> status;
  };

 private:
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  // Guarded: a checker shared by threads solves cold when another holds it.
  bool warm_start_ = false;
  bool margin_computed_ = true;
  mutable std::mutex warm_mutex_;
  mutable WarmStart warm_[2];
};

}  // namespace acyclic
