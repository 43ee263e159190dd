#pragma once
// One transition of a plan (docs/design.md section 10): designed from the plan's
// structure, then turned into knots (witness postures and posture-generator
// solutions) grouped in pieces of constant contacts.
//
// Kinds, from consecutive kept stances a -> b:
//   Fixed  the same contacts, or one contact's support flipped: every contact
//          held, the supporting ones those supporting in either stance; knots
//          at one step per fixed_step of change (n at most), cost the distance
//          to the linear interpolation of the two witnesses; when that fails,
//          solved again with each knot also near the previous one (a Move's
//          cost: the knots stay on one branch). No motion at all when the
//          witnesses coincide.
//   Move   a contact removed, added, or removed and then added again for the
//          same spot (a -> b -> c merged, the settled stance b giving the
//          contacts held in the air): the moving body follows a BodyPath from
//          its pose in the first witness to its pose in the last; at n steps
//          (and the spline's two ends) the posture generator holds the shared
//          contacts and the body on its path, cost the distance to the
//          witnesses' interpolation plus the distance to the previous step.
//          A body that cannot follow the path exactly near a surface (a thigh
//          whose foot is planted) pivots: height held, straight_slack across.
//          A knot found neither from the previous one nor from the witnesses'
//          interpolation is sought from each witness, which holds the motion's
//          contacts.
//          The body leaves (reaches) a surface in a short piece that keeps the
//          contact: the phase changes when it is `touch_clearance` off the
//          surface, where no check can mistake it for a collision.
// Between knots, the linear interpolation is checked at each segment's middle
// by the independent validity check and refined where it fails; then every
// sample the time law makes of the piece is checked the same way, and the
// segment of a failing sample refined (so every output sample is valid). A
// Move whose path collides (a knot infeasible, or a segment that refinement
// cannot fix) is repaired, farther on each attempt, by raising its spline into
// a bridge or by a detour to either side, whichever carries the moving link
// (rigidly, along the spline) farthest from the obstacles and the links held
// on their contacts; then by a path planned with OMPL for the body alone
// (body_path_planner.h), its orientation followed closely; then all of these
// again with the end of each free limb (a foot or a hand with no contact)
// pulled along a path of its own between its witness positions, where the
// witnesses' interpolation swings it into an obstacle, or, where the limb's
// interpolated joints sweep it through one (an elbow through a table's edge),
// with those joints planned with OMPL (limb_path_planner.h; 10 mm clear,
// else 5 or 3 mm through a narrow gap), the knots' target on each planned
// limb its path itself. Last, a body on a limb that holds no other contact
// (a forearm off a table, its arm free) leaves its path: held only where it
// touches, as a foot hanging from its thigh, its limb's joints planned from
// touching (or interpolated). A Move whose body touches its surface in both
// witnesses is solved as a Fixed one that holds it there.
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "interpolator/body_path.h"
#include "interpolator/body_path_planner.h"
#include "interpolator/limb_path_planner.h"
#include "interpolator/time_law.h"
#include "planner/check/validity.h"
#include "planner/plan/plan.h"
#include "planner/posture/posture_generator.h"

namespace acyclic {

struct TransitionDesign {
  enum class Kind { Fixed, Move };
  Kind kind = Kind::Fixed;
  int from = -1, to = -1;        // plan stance indices
  int motion_stance = -1;        // the stance whose contacts hold during the motion
  std::vector<ContactSpec> motion_contacts;
  int spot = -1;                 // Move: the moving body's spot
  std::optional<ContactSpec> leave, arrive;  // Move: the contacts it leaves and reaches
};

// Designs the transitions between consecutive kept stances. Returns an empty
// string, or why the sequence cannot be interpolated (naming the stances).
std::string designTransitions(const Plan& plan, const std::vector<int>& kept, std::vector<TransitionDesign>& out);
// The same with every stance kept: the plan as the planner verifies it.
std::string designTransitions(const Plan& plan, std::vector<TransitionDesign>& out);

struct MotionPiece {
  std::vector<Configuration> knots;  // travelled from rest to rest
  std::vector<ContactSpec> contacts; // held throughout
  int stance = -1;                   // the plan stance whose contacts these are
};

struct TransitionOptions {
  int steps = 20;                    // n: knots per transition
  // Fixed-contact transitions: one step per this much of the largest
  // coordinate change between the witnesses (rad, m), n at most; 0: always n.
  double fixed_step = 0.02;
  double lift = 0.03;                // m: straight part along each surface normal
  double touch_clearance = 5e-4;     // m: the body is off its surface beyond this (contract: 1 mm)
  // On the spline (in the air) the body's orientation follows the slerp only
  // within this bound on each orientation row (PoseTarget); on the straight
  // parts, near a surface, exactly.
  double air_orientation_tolerance = 0.3;
  // Near a surface, when the body cannot move straight with its orientation
  // held (a thigh whose foot is planted pivots), its spot origin may leave
  // the straight line by this much across the normal (m), its height held.
  double straight_slack = 0.005;
  int repair_attempts = 4;
  double repair_step = 0.05;         // m: via-point height added per attempt
  // After the attempts, the body's path planned with OMPL (body_path_planner.h),
  // its orientation followed within this bound on each row.
  bool plan_body_path = true;
  double planned_orientation_tolerance = 0.05;
  // Then the same attempts with the end of each free limb (no contact on it)
  // pulled along a path of its own, with this weight (ReferencePostureCost::SpotTarget).
  bool free_limb_paths = true;
  // There, a free limb whose joints' interpolation sweeps it through an
  // obstacle has its joints planned with the transition's progress
  // (limb_path_planner.h) and the knots follow them instead of its end's path.
  bool limb_joint_paths = true;
  double free_limb_weight = 100;
  // Where the first attempt's failure says which repair it needs, that
  // repair's first attempt comes next: the free limbs' (on their own paths,
  // then their joints planned) where the collisions its check found are all
  // on links of limbs with no contact, before the repairs that change the
  // moving body's path or the whole body's knots, which do not move those
  // limbs out of the way; else bridges (bridge_jumps) where a segment no
  // halving shortened (a jump between two branches of the inverse
  // kinematics) fails on held contacts alone. Only the order of the attempts
  // changes (each is still made until one succeeds), so a transition is
  // solved or not alike; how it is made can change where an attempt moved
  // forward succeeds and one it passed would have too (on the shipped plans
  // it does not; bench_interpolator says). Off: the order above.
  bool order_by_failure = true;
  // A fixed-contact transition whose knots cannot be made valid at the
  // posture generator's collision margin is solved once more with this much
  // more clearance for its knots (m; 0: no such try). Knots that hug an
  // obstacle at the margin (a trunk under a table top) can sit on different
  // sides of a corner of the distance function, and the straight segment
  // between two of them dips below the margin however densely refined; a
  // little more room takes the dip.
  double wide_clearance = 0.003;
  int refine_depth = 3;              // halvings of a segment whose inside fails the check
  // Last, where every attempt stopped at a jump between two branches of the
  // inverse kinematics (two knots close in path parameter, far apart in
  // joint space, a held contact drifting off its surface between them): the
  // attempt as planned again, each such jump bridged by knots projected from
  // the straight joint-space segment between its two knots, halved while
  // they converge (Refiner in transition.cpp).
  bool bridge_jumps = true;
  int segment_checks = 1;            // points checked inside each segment before timing (its middle)
  // After timing, every sample the piece will give is checked, and refined
  // where one fails (with timing: the time law the interpolator uses).
  bool verify_samples = true;
  TimeLawOptions timing;
  PostureGeneratorOptions posture;
};

struct TransitionOutcome {
  bool ok = false;
  bool cancelled = false;
  std::string reason;                // on failure
  std::vector<MotionPiece> pieces;
  long posture_calls = 0;
  double posture_seconds = 0;        // wall time inside the posture generator
  double seconds = 0;                // wall time of the whole solve
  bool repaired = false;
  bool still = false;                // a Move whose body already touches where it goes: solved as a fixed transition
  std::string how;                   // when solved: "as planned", or the repair that made it
  int attempts = 0;                  // attempts made (each solves its knots anew)
  int refinements = 0;               // knots inserted between the n steps, over every attempt made
};

class TransitionSolver {
 public:
  TransitionSolver(const Scenario& sc, TransitionOptions options);
  TransitionOutcome solve(const Plan& plan, const TransitionDesign& d, const std::atomic<bool>* cancel = nullptr);
  // Why an outcome solved elsewhere (another process's, TransitionMemo's
  // check_on_use) cannot stand for transition `d` of `plan` under these
  // options; empty when it can. It must be a success whose pieces join the
  // first stance's witness to the last one's, each piece starting where the
  // previous ended, hold only contacts of the transition's stances (spot,
  // surface and placement), and every sample the time law makes of each
  // piece must pass the validity check with the piece's contacts, as the
  // samples of a transition solved here do.
  std::string check(const Plan& plan, const TransitionDesign& d, const TransitionOutcome& o);
  const TransitionOptions& options() const { return opt_; }

 private:
  struct Attempt;
  // `follow`: the cost also holds each knot near the previous one; `wide`:
  // the knots solved with the margin plus wide_clearance.
  // `limbs`: free limbs' joints planned around what their interpolation sweeps them through (none: empty).
  bool solveFixed(const Plan& plan, const TransitionDesign& d, bool follow, bool wide,
                  const std::vector<LimbJointPath>& limbs, Attempt& at);
  // `orientation_tolerance`: the body's orientation off its path's in the air (PoseTarget).
  struct FreeEnd;
  // `free_ends`: the end of each limb without contacts pulled along a path
  // of its own between its witness positions (none: nullptr).
  bool solveMove(const Plan& plan, const TransitionDesign& d, const BodyPath& path, double orientation_tolerance,
                 const std::vector<FreeEnd>* free_ends, Attempt& at);
  std::vector<FreeEnd> freeEnds(const Plan& plan, const TransitionDesign& d);
  // `free` (freeEnds') with the joints of each limb that their interpolation
  // sweeps into an obstacle planned, and the joints beyond the moving body
  // in its own limb where they do.
  std::vector<FreeEnd> withPlannedJoints(const Plan& plan, const TransitionDesign& d, std::vector<FreeEnd> free);
  // Per limb with no contact in the transition (and not the moving body's), its most distal spot.
  std::vector<int> freeLimbEnds(const TransitionDesign& d) const;
  // The joints `root` moves (a limb, or what lies beyond the moving body in
  // its limb) planned from q0's to q1's where their interpolation sweeps
  // them into an obstacle; none where it does not, or no path was found.
  // `touching_ends`: LimbPathPlanOptions::touching_ends (the limb's own body on its surface).
  std::optional<LimbJointPath> plannedLimbJoints(const Configuration& q0, const Configuration& q1, int root,
                                                 bool touching_ends = false);
  // The same, planned anew (plannedLimbJoints remembers its answers).
  std::optional<LimbJointPath> planLimbJoints(const Configuration& q0, const Configuration& q1, int root,
                                              bool touching_ends);
  // Whether the Move's body is on a limb that holds no contact during the motion (a forearm, its arm free).
  bool onFreeLimb(const TransitionDesign& d) const;
  // Whether every one of `links` (a failed check's, Attempt::failed_links)
  // is moved by a free limb's joints (freeLimbEnds); false for none.
  bool onFreeLimbsOnly(const TransitionDesign& d, const std::vector<int>& links) const;
  // Whether every one of `links` is a held contact's (d.motion_contacts'),
  // not the moving body's; false for none.
  bool onHeldBodiesOnly(const TransitionDesign& d, const std::vector<int>& links) const;
  // The repair a failed attempt's check names (TransitionOptions::order_by_failure):
  // the free limbs' stages where it failed on free limbs alone, else bridges
  // where it failed on a jump between branches on held contacts alone, else
  // none. (On HRP-2 the first two exclude each other: its spots hang from the
  // hips and shoulders, so a held contact's link is on no free limb.)
  enum class NamedRepair { None, FreeLimbs, Bridges };
  NamedRepair namedRepair(const TransitionDesign& d, const Attempt& failed) const;
  // A Move whose body already touches its surface in both witnesses, as the
  // Fixed transition that holds it touching; none for any other.
  std::optional<TransitionDesign> stillBody(const Plan& plan, const TransitionDesign& d);
  // Whether the Move's body hangs from a contact of its own limb (a foot
  // whose thigh rests on the seat): it swings on an arc (transition.cpp).
  bool hangsFromItsLimb(const TransitionDesign& d) const;
  // The shapes of the links outside `spot`'s limb at q (all but its link, for a spot on the trunk).
  std::vector<PlacedShape> outsideLimb(const Configuration& q, int spot);

  // plannedLimbJoints' answers within one solve(): the later repair stages
  // ask for the same limbs between the same witnesses again, and a limb with
  // no path costs seconds of state checks each time (its five tries).
  struct PlannedLimb {
    Configuration q0, q1;
    int root;
    bool touching_ends;
    std::optional<LimbJointPath> path;
  };
  std::vector<PlannedLimb> planned_limbs_;

  const Scenario& sc_;
  TransitionOptions opt_;
  PostureGenerator generator_;
  std::optional<PostureGenerator> wide_generator_;  // collision margin + wide_clearance, if that is positive
  ValidityChecker checker_;
  Kinematics kin_;
  CollisionModel collisions_;  // the free limbs' joint paths (limb_path_planner.h)
};

}  // namespace acyclic
