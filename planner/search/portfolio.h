#pragma once
// The contact planner's portfolio (PlannerParameters::portfolio): one search
// per member, each on its own thread, and the plan of the member that solved
// in the fewest nodes. Private to the planner (contact_planner.cpp).
//
// Why the winner does not depend on timing: a member i that solves with n_i
// nodes lowers every other member j's cap to n_i (j listed before i, which
// wins a tie) or n_i - 1 (j after). Up to its cap each member makes exactly
// the search it makes alone, and its count only grows: a member stopped
// past its cap would have solved, alone, in more nodes than i did, so it
// cannot have been the winner; the winner is never stopped (its count
// never passes a cap set by a worse member).
//
// While member i verifies the transitions of a goal found at count g_i, a
// member j whose count is already past that (tie-adjusted) waits at the top
// of its loop: if i's plan is accepted j is outrun, if refused j goes on as
// if it had not waited. Its core goes to i's verifier meanwhile. If j was
// itself verifying a goal, it stops that verification and verifies again
// after i's verdict (the transitions it solved are remembered by its
// verifier), so that only the better goal's verification runs.
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
  long cap() const;       // the count past which this member cannot win
  bool outrun(long nodes) const { return nodes > cap(); }
  // A goal found at this count is being verified (-1: no longer).
  void verifying(long nodes);
  // Another member verifies a goal found at a count this one, at `nodes`,
  // cannot beat.
  bool beaten(long nodes) const;
  // Waits while another member verifies a goal found at a count this one,
  // at `nodes`, cannot beat; `give_up` (polled) ends the wait early.
  void gate(long nodes, const std::function<bool()>& give_up);
};

struct ContactPlanner::Portfolio {
  std::vector<std::string> names;
  std::vector<std::unique_ptr<ContactPlanner>> members;
  Portfolio(const Scenario& scenario, const PlannerParameters& params);
  PlanningResult plan(const std::atomic<bool>* cancel, const Progress& progress);
};

}  // namespace acyclic
