#pragma once
// The validity contract of docs/design.md section 9, checked part by part for one
// posture and its stance. Each part reports what it checked, its worst figure
// and every violation with its figure.
//
// Equilibrium is checked by the independent quasi-static LP (quasi_static.h).
#include <limits>
#include <string>
#include <vector>

#include "planner/check/quasi_static.h"
#include "planner/collision/collision_model.h"
#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"

namespace acyclic {

struct ContractTolerances {
  double contact_position = 1e-3;    // m: spot origin to the contact point
  double contact_normal_deg = 1.0;   // deg: between spot and surface normals
  double polygon = 1e-3;             // m: spot polygon corners outside the surface polygon
  double penetration = 1e-3;         // m: allowed for a contacting body on its own surface's obstacle
  double joint_limit = 1e-9;         // rad: numerical slack on joint limits
};

struct CheckPart {
  std::string name;                  // "joint limits", "contacts", "collisions", "equilibrium"
  bool checked = true;               // false: not available (says why in summary)
  std::vector<std::string> violations;
  // The robot links its violations name (collisions: each offending pair's
  // robot link or links; contacts: each violated contact's spot's link), for
  // a caller that acts on which part of the body failed (the interpolator's
  // order of repairs, transition.cpp).
  std::vector<int> links;
  std::string summary;               // what was checked and the worst figure
  bool ok() const { return violations.empty(); }
};

struct ValidityReport {
  std::vector<CheckPart> parts;
  bool valid() const;                // every checked part ok
};

class ValidityChecker {
 public:
  ValidityChecker(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                  ContractTolerances tol = {});

  // `equilibrium`, if given, receives the quasi-static check's report (forces included).
  ValidityReport checkPosture(const Configuration& q, const std::vector<ContactSpec>& stance,
                              QuasiStaticReport* equilibrium = nullptr);

  CheckPart checkJointLimits(const Configuration& q) const;
  CheckPart checkContacts(const std::vector<ContactSpec>& stance);    // at the last set configuration
  CheckPart checkCollisions(const std::vector<ContactSpec>& stance);  // idem
  CheckPart checkEquilibrium(const std::vector<ContactSpec>& stance,
                             QuasiStaticReport* report = nullptr);  // idem

  // Pairs whose bounding spheres are farther apart than `m` cannot collide
  // and are not measured: the verdict is the same, the summary's smallest
  // clearance is then over the pairs measured. Infinite by default (every
  // pair measured, as acyclic-check reports); a caller that checks thousands
  // of postures for their verdict (the interpolator) sets a millimetre.
  void setClearanceCutoff(double m) { clearance_cutoff_ = m; }
  // The equilibrium LPs warm-started (QuasiStaticChecker::setWarmStart): same
  // verdicts, faster along a trajectory.
  void setWarmStart(bool on) { statics_.setWarmStart(on); }
  // The friction margin's LP skipped (QuasiStaticChecker::setMarginComputed):
  // same verdicts, the summary's margin "not computed".
  void setMarginComputed(bool on) { statics_.setMarginComputed(on); }
  // All three, as every caller that checks the samples of a trajectory one
  // after the other for their verdicts uses them: a 1 mm cutoff, warm LPs,
  // no margin LP. The cutoff: a pair's bounding spheres over 1 mm apart put
  // its shapes over 1 mm apart, where FCL's distance (exact to far below a
  // micrometre) cannot report a penetration; 2 cm before, measuring pairs
  // that could not fail (a transition of chair_paper 7% faster at 1 mm).
  void checkVerdictsInSequence() {
    setClearanceCutoff(0.001);
    setWarmStart(true);
    setMarginComputed(false);
  }
  // After checkVerdictsInSequence: the previous check's forces tried
  // first (QuasiStaticChecker::setForcesReused): the same verdicts, most
  // equilibrium LPs skipped, the forces reported no longer LP 2's. For the
  // interpolator and the bridge's contract check, which read verdicts only;
  // acyclic-check reports the LP's forces.
  void setForcesReused(bool on) { statics_.setForcesReused(on); }
  long forcesReused() const { return statics_.forcesReused(); }

 private:
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  ContractTolerances tol_;
  Kinematics kin_;
  CollisionModel collision_;
  QuasiStaticChecker statics_;
  double clearance_cutoff_ = std::numeric_limits<double>::infinity();
};

}  // namespace acyclic
