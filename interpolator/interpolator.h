#pragma once
// The trajectory interpolator (docs/design.md section 10, paper 3.3 and 4): turns a
// contact plan into a time-parameterized whole-body trajectory at the
// controller's rate. Stances are filtered (stance_filter.h), each transition
// is turned into knots (transition.h), and the pieces of constant contacts are
// timed rest to rest (time_law.h) and sampled every dt. Knows nothing of LCM.
// Failures return a status with a reason; exceptions are for misuse only.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "interpolator/transition.h"
#include "planner/plan/plan.h"
#include "planner/plan/trajectory.h"

namespace acyclic {

class TransitionMemo;  // transition_memo.h

struct InterpolatorOptions {
  int steps = 20;                // n: posture-generator steps per transition (moving body)
  double fixed_step = 0.02;      // fixed-contact transitions: a step per 0.02 rad (m) of change, n at most; 0: n
  double dt = 0.005;             // s, the controller's period
  double speed_cap = 0.2;        // m/s, any link origin (quasi-static motion)
  double velocity_share = 0.9;   // of each joint's velocity limit
  double link_acceleration_cap = 1.0;  // m/s^2, any link origin (time_law.h); joints: the robot's limits
  double zmp_shift_cap = 0;            // m, the ZMP's shift by the motion's accelerations (time_law.h); 0: none
  bool filter = true;            // drop stances whose direct transition is valid
  double lift = 0.03;            // m: straight along the normal when leaving and reaching a surface
  double touch_clearance = 5e-4; // m: a body this far off its surface has left it
  double air_orientation_tolerance = 0.3;  // the moving body's orientation in the air (transition.h)
  int repair_attempts = 4;       // raised or sideways via-points tried on a colliding path
  double repair_step = 0.05;     // m: via-point height added per attempt
  bool plan_body_path = true;    // after them, the body's path planned with OMPL (body_path_planner.h)
  bool free_limb_paths = true;   // then all again, the free limbs' ends on paths of their own (transition.h)
  bool limb_joint_paths = true;  // there, a free limb swept through an obstacle on joints planned with OMPL
  double wide_clearance = 0.003;  // m: a fixed-contact transition's last try, its knots this much farther from obstacles
  int refine_depth = 3;
  // Last, a jump between two branches of the inverse kinematics bridged by
  // knots from the straight joint-space line across it (transition.h).
  bool bridge_jumps = true;
  // The repair a transition's first failure names tried next
  // (TransitionOptions::order_by_failure); off: the fixed order, for
  // measuring what the order saves (bench_interpolator).
  bool order_by_failure = true;
  // Check every output sample with the validity contract (and refine where
  // one fails). Off, only knots and segment middles are checked: for
  // measuring what the verification costs, not for output.
  bool verify_samples = true;
  // Edges of the knots' friction pyramid: 4 or 8 (PostureOptions::pyramid_sides).
  int pyramid_edges = 4;
  // The knots' stability margins (PostureOptions::support_inset, m, and
  // friction_share): none by default.
  double support_inset = 0;
  double support_inset_y = -1;  // >= 0: across the spot (its y) instead
  double friction_share = 1;
  // Each posture call bounded by iterations, not time: same input, same output.
  int posture_iterations = 100;
  double collision_cutoff = 0.15;  // m: pairs farther than this at the warm start are left out
  std::vector<std::string> posture_ipopt_options;  // "name=value", passed to each posture solve
  // L-BFGS's low-rank part inside the KKT system
  // (PostureGeneratorOptions::lbfgs_in_kkt).
  bool posture_lbfgs_in_kkt = true;
  // Ipopt's barrier oracle for the knots' solves (PostureGeneratorOptions::
  // mu_oracle): "quality-function" (Ipopt's default), "probing" or "loqo".
  // A scenario's planner key transition_mu_oracle sets it (withScenarioMargins);
  // on chair_paper's plans probing makes the same transitions in 0.76 to
  // 0.81 of the time (docs/design.md section 10).
  std::string posture_mu_oracle = "quality-function";
  // Transitions solved at once, one solver each (same result for any count).
  int threads = 2;
};

struct InterpolationProgress {
  int transition = 0, transitions = 0;  // done, total
  long posture_calls = 0;
  double seconds = 0;
  std::string stage;                    // "filtering", "transitions", "timing"
};

// One transition the interpolator solved, or the one it could not: how it
// was made and what it cost (acyclic-interpolator --verbose prints these).
struct TransitionRecord {
  int from = 0, to = 0;                 // stance indices
  bool move = false;                    // a body moves (else a fixed-contact transition)
  bool still = false;                   // a Move whose body already touches: made as a fixed one (`how` from that list)
  bool ok = false;
  std::string how;                      // the attempt that made it (TransitionOutcome::how)
  int attempts = 0;
  long posture_calls = 0;
  double seconds = 0;                   // wall time of its solve (while filtering, for a kept pair it solved then)
};

struct InterpolationResult {
  enum class Status { Success, InvalidInput, Unrepairable, TransitionFailed, Cancelled };
  Status status = Status::InvalidInput;
  std::string reason;                   // on failure; names the stance indices
  std::vector<int> failed_stances;      // the transition that failed: from, to
  Trajectory trajectory;                // on success
  int filtered = 0;                     // stances dropped
  int refinements = 0;                  // knots inserted between steps, over every attempt made
  double posture_seconds = 0;           // of the wall time, inside the posture generator
  // The transitions solved, in the plan's order, up to and with the one that
  // failed (none when the filtering or the design failed first).
  std::vector<TransitionRecord> transitions;
  // Of those, taken from a memo (transition_memo.h) instead of solved: their
  // posture calls are not in the trajectory's stats, which count this run's.
  int reused = 0;
  // Outcomes in a memo from elsewhere (TransitionMemo's check_on_use) that
  // failed their check and were solved instead; why the first one failed.
  int refused = 0;
  std::string refused_reason;
  bool success() const { return status == Status::Success; }
};

const char* toString(InterpolationResult::Status s);

// `options` with the scenario's stability margins (its planner section's
// posture_support_inset, posture_support_inset_y and posture_friction_share,
// and the time law's zmp_shift_cap) where it sets them: the knots between two
// stances keep the margins the stances were planned with, and a scenario
// whose single supports need a slow weight shift to execute says so. Also
// its transition_mu_oracle, the knots' barrier oracle. The interpolator's
// command line and the plan verifier start from these, so that a plan is
// verified as it will be interpolated; a value given on the command line wins.
InterpolatorOptions withScenarioMargins(const Scenario& sc, InterpolatorOptions options);

// The transition solver's options the interpolator uses for these options
// (the plan verifier, plan_verifier.h, solves with the same).
TransitionOptions transitionOptions(const InterpolatorOptions& options);

InterpolationResult interpolate(const Plan& plan, const Scenario& sc, const InterpolatorOptions& options,
                                const std::function<void(const InterpolationProgress&)>& progress = {},
                                const std::atomic<bool>* cancel = nullptr);

// The same with the memo's options, each transition the memo holds taken
// from it instead of solved (InterpolationResult::reused counts them), and
// each one solved kept there: the same result as above, bit for bit
// (transition_memo.h). acyclic-planner --trajectory interpolates its plan
// with the memo its verification of transitions filled.
InterpolationResult interpolate(const Plan& plan, const Scenario& sc, TransitionMemo& memo,
                                const std::function<void(const InterpolationProgress&)>& progress = {},
                                const std::atomic<bool>* cancel = nullptr);

}  // namespace acyclic
