#pragma once
// The contact planner's portfolio (PlannerParameters::portfolio): one search
// per member, each on its own thread, and the plan of the member that solved
// in the fewest posture calls; or (portfolio_mode: sequence) the members one
// after another, each on every thread, until one solves (what follows is
// the race's). Private to the planner (contact_planner.cpp).
//
// Why posture calls and not nodes: calls are most of a search's time, and
// members differ in calls per node. On chair_paper's OMPL guide the
// quality-function member spends 44 s of CPU to pass the winner's 572 nodes
// but about 32 s to pass its 1,255 calls; counted in nodes, the portfolio
// waited for the slower member (docs/design.md section 7). A member's count
// is that of its search made one call at a time (PlanningStats::searchCalls:
// calls a batch solved ahead of their turn are left out until it comes, so
// it does not depend on threads; calls exporting a goal's plan not at all,
// so that it stays the count announced while that goal is verified).
//
// Why the winner does not depend on timing: a member i that solves with c_i
// calls lowers every other member j's cap to c_i (j listed before i, which
// wins a tie) or c_i - 1 (j after). Up to its cap each member makes exactly
// the search it makes alone, and its count only grows: a member stopped
// past its cap would have solved, alone, in more calls than i did, so it
// cannot have been the winner; the winner is never stopped (its count
// never passes a cap set by a worse member).
//
// While member i verifies the transitions of a goal found at count g_i, a
// member j whose count is already past that (tie-adjusted) waits, at the
// top of its loop or within an expansion: if i's plan is accepted j is
// outrun, if refused j goes on as if it had not waited. Its core goes to
// i's verifier meanwhile. If j was itself verifying a goal, it stops that
// verification and verifies again after i's verdict (the transitions it
// solved are remembered by its verifier), so that only the better goal's
// verification runs.
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "planner/search/contact_planner.h"

namespace acyclic {

// The members' shared state: every cap and goal being verified (portfolio.cpp).
struct PortfolioState;

struct ContactPlanner::MemberLink {
  PortfolioState* state = nullptr;
  std::size_t index = 0;  // this member's
  long cap() const;       // the count of posture calls past which this member cannot win
  bool outrun(long calls) const { return calls > cap(); }
  // A goal found at this count is being verified (-1: no longer).
  void verifying(long calls);
  // Another member verifies a goal found at a count this one, at `calls`,
  // cannot beat.
  bool beaten(long calls) const;
  // Waits while another member verifies a goal found at a count this one,
  // at `calls`, cannot beat; `give_up` (polled) ends the wait early.
  void gate(long calls, const std::function<bool()>& give_up);
};

struct ContactPlanner::Portfolio {
  std::vector<std::string> names;
  std::vector<std::unique_ptr<ContactPlanner>> members;
  PlannerParameters::PortfolioMode mode;
  double max_seconds;  // a sequence's, all members together
  Portfolio(const Scenario& scenario, const PlannerParameters& params);
  PlanningResult plan(const std::atomic<bool>* cancel, const Progress& progress);

 private:
  // The members at once (Race) or in turn (Sequence); their results in the
  // portfolio's order (a sequence's: those that ran).
  std::vector<PlanningResult> race(const std::atomic<bool>* cancel, const Progress& progress);
  std::vector<PlanningResult> inTurn(const std::atomic<bool>* cancel, const Progress& progress);
};

}  // namespace acyclic
