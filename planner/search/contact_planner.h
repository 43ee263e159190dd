#pragma once
// The contact planner (paper, 2.2-2.8): best-first search over sets of
// contacts, keyed on the guide potential f_T of each node's witness posture.
//
// A node is a set of contacts and the witness posture found when it was
// created: the transition posture, in which the contact just added or just
// removed touches but does not support (paper, 2.3). Its sons:
//   - removal of each of its contacts (generated eagerly): the posture
//     generator with that contact geometric only;
//   - addition, for each pair (spot R, surface E): candidates from the
//     posture generator with the new contact floating in a search volume
//     (2.5-2.6). With lazy sons (2.8) a pair keeps one pending son at a time,
//     and its next son is generated only when that one is selected.
// Every witness is re-checked by the independent validity check before its
// node joins the tree. Ablation switches reproduce the paper's baseline:
// random (x, y, theta) samples instead of optimized candidates, eager
// instead of lazy sons, distance to the goal instead of f_T.
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "planner/plan/plan.h"
#include "planner/posture/posture_generator.h"
#include "planner/search/search_volume.h"

namespace acyclic {

// What a plan verifier says of a plan the search found (PlannerParameters::
// verify_plan): the first transition between consecutive stances that
// cannot be made, or none.
struct PlanVerdict {
  int failed_from = -1, failed_to = -1;  // plan stance indices of the first failing transition; -1: none
  std::string reason;                    // why it fails
  bool stopped = false;                  // the stop flag was raised before every transition was checked
  int transitions = 0;                   // transitions in the plan
  int solved = 0;                        // of them, solved by this call (the others were known)
  bool ok() const { return failed_from < 0 && !stopped; }
};
// Checks a plan; `stop` (raised by the search on its budget or a cancel)
// asks it to return early with `stopped`.
using PlanVerifier = std::function<PlanVerdict(const Plan&, const std::atomic<bool>& stop)>;

struct PlannerParameters;
// A member of a portfolio (PlannerParameters::portfolio): the planner's
// parameters with some changed, applied to a copy of them.
struct PlannerVariant {
  std::string name;  // in traces and results
  std::function<void(PlannerParameters&)> apply;
};

struct PlannerParameters {
  double potential_k = 1.0;            // slope of f_T along the guide
  double smoothing_tolerance = 0.05;   // corner blends of the guide
  double guide_joint_weight = 1.0;     // weight of the joints in |P - Q|^2 (the base's is 1)
  double depth_weight = 0.0;           // added to a node's key per contact change from the start (0: the paper)
  // m along the guide: a pair's n-th son waits in the open list as if its
  // f_T were k * alternative_step * (n - 1) higher (0: the paper). Where
  // the search must cross a rise of f_T (a side step raises it while the
  // weight goes onto the trailing foot), a foot's pair otherwise supplies
  // placements without end, each a little worse than the last, and best
  // first expands all of them below the rise (docs/design.md section 7).
  double alternative_step = 0.02;
  // Subtracted around each candidate: a contact this close to one already
  // tried is not a new one (20 cm by 20 cm, 40 degrees; see docs/design.md section 7).
  BoxHalfSizes box{0.10, 0.10, 0.35};
  double duplicate_distance = 0.05;    // m: sons this close to a node (same contacts) are dropped
  double duplicate_angle = 0.35;       // rad
  int max_contacts = 6;                // no stance with more contacts
  double reach_slack = 0.3;            // m: trunk and base motion allowed for in the reachability test
  long max_nodes = 1000;               // nodes generated
  // Nodes generated since the best guide potential of the tree last fell,
  // at most (0: no such bound): a search on a plateau hands over (a
  // portfolio in sequence gives the next member the rest of the time).
  // Counted in nodes, as max_nodes is, so that where a search stops does
  // not depend on the machine.
  long max_plateau_nodes = 0;
  long max_posture_calls = 20000;
  double max_seconds = 60;
  bool lazy_sons = true;               // paper 2.8 (false: every son of a node at once)
  bool optimized_candidates = true;    // paper 2.6 (false: random samples per pair)
  int random_samples_per_pair = 4;     // with optimized_candidates = false
  int eager_candidates_per_pair = 6;   // with lazy_sons = false: candidates per pair at expansion
  bool guide_potential = true;         // paper 2.7 (false: distance to the goal)
  // Failure memory (beyond the paper): a pair (spot, surface) whose first
  // candidate, over the whole surface, failed at a node is not tried at a son
  // of that node whose witness holds the spot within failure_memory_distance
  // and failure_memory_angle of where it was: the same local problem from the
  // same place fails again. Pairs that cannot be made from a posture (a knee
  // on the table from a seat) otherwise cost a failed call at every node.
  // A son that adds or removes a contact on the spot's own limb (the foot of
  // the leg whose thigh failed) poses a new problem: the memory stops there.
  bool failure_memory = true;
  // A son whose limb hanging from a contact it shares with its parent (a
  // foot below a thigh on the seat) cannot swing from the parent's witness
  // to its own clear of the obstacles is refused (swing_check.h).
  bool swing_check = true;
  // An added contact that fails from the parent's witness is tried once
  // more (beyond the paper) with the joints of the limb that carries it (hip
  // to foot, shoulder to hand) as the key posture nearest the witness that
  // has the spot on that surface holds them. Ipopt is local: a knee put
  // down needs the shank swung back, a palm the wrist turned 75 degrees,
  // and from the limb where the parent holds it the solve can end locally
  // infeasible. Off by default (a retry changes the tree wherever a call
  // failed); crawl_under_table sets it.
  bool guide_limb_guess = false;
  // Lazy verification of the transitions (beyond the paper): a plan the
  // search finds is handed to verify_plan (in processes: the interpolator's
  // transition solver, interpolator/plan_verifier.h); when one of its
  // transitions cannot be made, the stance it leads to is dropped with its
  // subtree and the search goes on. Its time counts in max_seconds. Set
  // verify_transitions without a verifier: the planner refuses to start.
  bool verify_transitions = false;
  // With verify_transitions: the transitions into a node are verified when
  // it is first selected for expansion (its path from the start exported and
  // handed to verify_plan), not only when a plan reaches the goal. A stance
  // that cannot be reached is dropped before the search builds a subtree on
  // it (on the paper's chair, a foot stepped onto the seat from under the
  // table's edge: every goal below it was refused, hundreds of nodes each).
  // Costs one verification per expanded node; transitions are remembered.
  bool verify_on_expansion = false;
  PlanVerifier verify_plan;
  // A fresh verifier for each member of a portfolio, so that members verify
  // at once (attachPlanVerifier sets it). Empty: members share verify_plan,
  // one call at a time.
  std::function<PlanVerifier()> make_verifier;
  // Each plan the verifier refuses is kept whole in the result
  // (PlanningResult::refused_plans), to reproduce its failing transition
  // with the interpolator (acyclic-planner --keep-refused).
  bool keep_refused_plans = false;
  double failure_memory_distance = 0.05;  // m
  double failure_memory_angle = 0.35;     // rad
  PostureGeneratorOptions posture;     // max_iterations bounds each call deterministically
  // Posture generators run at once on independent sons (removal sons, each
  // pair's first son). Results do not depend on it: request i of a batch
  // always goes to generator i % threads.
  int threads = 2;
  // Called with one line per expanded node (for -v); empty: silent.
  std::function<void(const std::string&)> trace;
  // A portfolio (beyond the paper; docs/design.md section 7): when not
  // empty, plan() runs one search per variant at once, each on these
  // parameters with the variant applied and threads / members posture
  // generators, and returns the plan of the member that solved in the
  // fewest posture calls (PlanningStats::searchCalls; ties: the earlier
  // member). A member stops as soon as it has made more calls than a
  // member that solved, so the winner does not depend on the members'
  // speeds: the same plan as that member run alone, whatever the timing.
  // The counts of a search hinge on the last bits of its witnesses
  // (bench_sensitivity); members that differ in them fail on different
  // perturbations.
  std::vector<PlannerVariant> portfolio;
  // How the members run. Race: as above, all at once. Sequence (restarts):
  // one after another in the portfolio's order, each on all `threads` and
  // with its own budget (a member's max_nodes, max_posture_calls), until one
  // solves; that member's plan is the answer, the same as it alone would
  // give, and the members after it are not run. max_seconds bounds them
  // all together. Where a fast member usually solves, its speed on every
  // core; where it does not, the next member after its budget.
  enum class PortfolioMode { Race, Sequence };
  PortfolioMode portfolio_mode = PortfolioMode::Race;
  PlannerParameters();
};

struct PlanningStats {
  long nodes_generated = 0, nodes_expanded = 0, posture_calls = 0, posture_failures = 0, check_refusals = 0;
  long pairs_remembered = 0;  // pairs not tried thanks to the failure memory
  // Of nodes_generated, sons dropped as too close to a node with the same
  // contacts (duplicate_distance, duplicate_angle), each after its posture call.
  long duplicates = 0;
  long calls_ahead_unused = 0;  // solved ahead on an idle generator, their turn never came (not in posture_calls)
  // Started ahead like those, and stopped within an iteration when the pair's
  // candidate before them made its son (not in posture_calls either).
  long calls_stopped = 0;
  // Of posture_calls, those made exporting plans found (witnesses of the
  // settled stances between a removal and an addition).
  long export_calls = 0;
  // The calls of the search itself: what a portfolio compares its members by.
  long searchCalls() const { return posture_calls - export_calls; }
  // guide_limb_guess: added contacts solved again from the guide's limb, and
  // how many of those the retry made (both within posture_calls).
  long limb_retries = 0, limb_retry_successes = 0;
  double seconds = 0, best_potential = 0;
  // Lazy verification (verify_transitions): plans handed to the verifier,
  // refused by it, transitions solved, and the wall time spent in it.
  long plans_verified = 0, plans_refused = 0, transitions_solved = 0;
  // verify_on_expansion: nodes whose path was verified before their
  // expansion, and of them dropped (a transition into them cannot be made).
  long nodes_verified = 0, nodes_refused = 0;
  double verify_seconds = 0;
  bool verifying = false;  // reported while the verifier runs
};

// A plan the verifier refused, as the search found it, and its first
// transition that cannot be made (stance indices in it).
struct RefusedPlan {
  Plan plan;
  int failed_from = -1, failed_to = -1;
  std::string reason;  // the verifier's, whole
};

struct PlanningResult {
  enum class Status { Solved, NoSolution, NodeBudget, PostureBudget, TimeLimit, Cancelled, InvalidInput };
  // How one member of a portfolio ended (a member that stopped because
  // another solved in fewer posture calls: Cancelled, "outrun ...").
  struct Member {
    std::string name;
    Status status = Status::InvalidInput;
    std::string reason;
    PlanningStats stats;
  };
  Status status = Status::InvalidInput;
  std::string reason;
  Plan plan;            // the path to the goal (Solved), else empty
  PlanningStats stats;
  // Each plan the verifier refused (verify_transitions), in order: its first
  // failing transition, "stances A -> B: " and the reason's first 300 characters.
  // With a portfolio, every member's, the winner's first.
  std::vector<std::string> refusals;
  // With a portfolio, the member that refused each (parallel to refusals);
  // without, empty.
  std::vector<std::string> refusal_members;
  // The refused plans themselves, in the same order, with keep_refused_plans.
  std::vector<RefusedPlan> refused_plans;
  // With a portfolio: every member's outcome, in the portfolio's order, and
  // the index of the one whose plan and stats this is; -1: none solved.
  // In a sequence only the members that ran. Without: empty and -1.
  std::vector<Member> members;
  int winner = -1;
  long portfolioNodes() const;  // nodes generated by all the members (without a portfolio: stats')
  bool solved() const { return status == Status::Solved; }
};

const char* toString(PlanningResult::Status s);

class ContactPlanner {
 public:
  using Progress = std::function<void(const PlanningStats&)>;
  ContactPlanner(const Scenario& scenario, PlannerParameters params = {});
  ~ContactPlanner();
  // Plans; `cancel` (set from another thread) stops the search with Cancelled.
  PlanningResult plan(const std::atomic<bool>* cancel = nullptr, const Progress& progress = {});

 private:
  struct Impl;        // one search
  struct Portfolio;   // one ContactPlanner per member (portfolio.h)
  struct MemberLink;  // a member's view of its portfolio (portfolio.h)
  // One search; as a member of a portfolio (link), it stops (Cancelled)
  // once it has made more posture calls than another member solved in, and
  // waits while another verifies a goal it cannot beat.
  PlanningResult search(const std::atomic<bool>* cancel, const Progress& progress, MemberLink* link);
  // A member run in a sequence: the time the portfolio has left.
  void setTimeBudget(double seconds);
  std::unique_ptr<Impl> impl_;            // without a portfolio
  std::unique_ptr<Portfolio> portfolio_;  // with one
};

}  // namespace acyclic
