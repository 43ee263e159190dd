#pragma once
// The posture generator (docs/design.md section 6): one Ipopt solve per call finds
// a configuration (and the floating contact's placement, and the contact
// forces) that satisfies a stance's constraints at the least cost.
// Failures return a status with a reason; exceptions are for misuse only.
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "planner/posture/posture_problem.h"

namespace acyclic {

struct PostureGeneratorOptions {
  PostureOptions problem;
  int max_iterations = 300;
  double max_seconds = 0.25;          // CPU seconds per solve (Ipopt's max_cpu_time)
  double tolerance = 1e-6;            // Ipopt's tol and constr_viol_tol
  int collision_rounds = 3;           // re-solves when a pair left out of the problem collides
  // Give up, as infeasible, when Ipopt enters its restoration phase: it
  // found no step that lowers the constraint violation enough from where it
  // is. For a search, where a quick "no" is worth more than a rare late
  // "yes": in the chair's planning 1,739 of 2,145 failed calls
  // went through it, 8 of 787 successes did, and the failures spent 47% of
  // their iterations after entering it. Off by default (the generator's
  // callers that need an answer whenever one exists); the planner sets it.
  bool stop_at_restoration = false;
  // Curvature: "lbfgs" (Ipopt's limited-memory quasi-Newton: the default, the
  // best measured by bench_posture), "analytic" (PostureProblem's Hessian of
  // the Lagrangian) or "diagonal" (the cost's, constant).
  std::string hessian = "lbfgs";
  // L-BFGS's low-rank part as extra rows of the KKT system, factorized with
  // it once per iteration (Ipopt's limited_memory_aug_solver=extended: rows
  // for the update's vectors, with -1 and +1 diagonals), instead of
  // Sherman-Morrison's dozen solves per iteration around it. With "ldl" the
  // rows join the dense trailing block (kkt_ldl.h); bench_posture: solves
  // per call a third, an iteration about 15% cheaper. With
  // "mumps" each call has a fixed cost that these small systems do not
  // amortize: 1.2-1.8 times faster. The witnesses differ from
  // Sherman-Morrison's, and searches are chaotic in them: the planner keeps
  // Sherman-Morrison by default (PlannerParameters; docs/design.md,
  // "Posture generator"), the interpolator uses the rows.
  bool lbfgs_in_kkt = true;
  // Ipopt's linear solver: "ldl" (kkt_ldl.h: a sparse LDL^T in an order
  // these KKT systems need no pivoting in, reentrant, so that two generators
  // on two threads run in parallel) or "mumps" (Debian's Ipopt's own,
  // serialized by a process-wide lock). "ldl" needs the Hessian block
  // diagonal but for L-BFGS's rows: hessian "lbfgs" or "diagonal", not
  // "analytic".
  std::string linear_solver = "ldl";
  // How Ipopt's adaptive barrier parameter is chosen at each iteration
  // (Ipopt's mu_oracle): "quality-function" (Ipopt's default) or "probing"
  // (Mehrotra's affine-scaling probe: one more back-solve per iteration,
  // cheap with "ldl"), or "loqo". The default: probing and loqo make
  // fewer successes, and other witnesses for the planner's search.
  std::string mu_oracle = "quality-function";
  // Pair distances: DistanceEngine::Convex (convex_distance.h: GJK on the
  // primitives' cores, several times faster than FCL's) or
  // DistanceEngine::Fcl (FCL's GJK, as the independent checks). The planner
  // keeps Fcl (PlannerParameters): its searches are chaotic in the
  // witnesses, and the chair's plan with Convex has a step the interpolator
  // cannot make (docs/design.md section 7).
  DistanceEngine distance_engine = DistanceEngine::Convex;
  int print_level = 0;                // Ipopt's, for debugging
  // Further Ipopt options "name=value", applied last (for tuning and debugging).
  std::vector<std::string> ipopt_options;
};

struct PostureResult {
  // Stopped: the caller's stop flag ended the solve (its result no longer needed).
  enum class Status { Success, Infeasible, IterationLimit, TimeLimit, BadInput, Stopped };
  Status status = Status::BadInput;
  std::string reason;                 // set on failure
  Configuration configuration;        // the witness posture (the last iterate on failure)
  SurfacePlacement floating;          // the floating contact's placement, if any
  std::vector<PostureProblem::ContactForces> forces;  // per supporting contact
  double cost = 0;
  int iterations = 0;
  int solves = 1;                     // problems solved: more than 1 when retried or turned (below)
  bool retried = false;               // the request's retry_guess was solved too (its first guess failed)
  // Solved again with the floating spot's footprint turned half a turn
  // (FloatingContact::footprint_turned): the first solve ended with the spot
  // half a turn from the solver's angle and its own footprint off the surface.
  bool footprint_turned = false;
  double seconds = 0;                 // wall time
  bool success() const { return status == Status::Success; }
};

const char* toString(PostureResult::Status s);

// The barrier oracles PostureGeneratorOptions::mu_oracle takes, and how an
// error message names them ("quality-function, probing or loqo").
const std::vector<std::string>& muOracles();
bool isMuOracle(const std::string& name);
std::string muOracleChoices();

class PostureGenerator {
 public:
  PostureGenerator(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                   PostureGeneratorOptions options = {});
  ~PostureGenerator();
  PostureGenerator(const PostureGenerator&) = delete;
  PostureGenerator& operator=(const PostureGenerator&) = delete;

  // Solves one request (and again from its retry_guess when that fails).
  // Not re-entrant: use one generator per thread. `stop`, when given and
  // raised (by another thread), ends the solve at Ipopt's next iteration
  // with Status::Stopped: a search that no longer needs the result gets its
  // generator back within one iteration instead of a whole call.
  PostureResult solve(const PostureRequest& request, const std::atomic<bool>* stop = nullptr);

  const PostureGeneratorOptions& options() const { return opt_; }
  std::shared_ptr<const CollisionModel> collisionModel() const { return collision_; }

 private:
  struct Ipopt;
  PostureResult solveOnce(const PostureRequest& request, const std::atomic<bool>* stop);
  // solveOnce, then again with the floating footprint turned if needed.
  PostureResult solveHeld(const PostureRequest& request, const std::atomic<bool>* stop);
  // Whether a success's floating spot has a corner off its surface (beyond
  // the contract's tolerance); `half_turn_only`: and the spot is half a turn
  // from the solver's angle (its x axis against the target frame's).
  bool footprintOffTheSurface(const PostureRequest& request, const PostureResult& res, bool half_turn_only) const;
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  std::shared_ptr<const CollisionModel> collision_;
  PostureGeneratorOptions opt_;
  std::unique_ptr<Ipopt> ipopt_;
};

}  // namespace acyclic
