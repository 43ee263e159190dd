// The planner's portfolio (PlannerParameters::portfolio): the plan of the
// member that solves in the fewest posture calls, the very plan that member makes
// alone, whatever the members' speeds; a member that fails does not fail the
// portfolio; a cancel reaches every member; verifiers are not shared at
// once; the scenario's `planner: portfolio:` with named errors.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "planner/common/format_error.h"
#include "planner/search/planner_parameters.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& step() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  return sc;
}

std::string json(const PlanningResult& r, const Scenario& sc) {
  Plan p = r.plan;
  p.stats.seconds = 0;
  return planToJson(p, sc);
}

// Two settings under which step_forward is solved in different counts of posture calls.
PlannerVariant asConfigured() { return {"as configured", {}}; }
PlannerVariant coarser() {
  return {"coarser", [](PlannerParameters& p) {
            p.duplicate_distance = 0.15;
            p.alternative_step = 0.05;
          }};
}

// A member whose verifier refuses every plan, with budgets it would run to
// the end of: it cannot solve, only be outrun (or run out of stances).
void refuseEveryPlan(PlannerParameters& q) {
  q.verify_transitions = true;
  q.verify_plan = [](const Plan&, const std::atomic<bool>&) {
    PlanVerdict v;
    v.failed_from = 0, v.failed_to = 1, v.reason = "refused by the test";
    return v;
  };
  q.max_nodes = 1000000;
  q.max_posture_calls = 1000000;
  q.max_seconds = 600;
}

// 30 ms more per expansion (its trace is called once per expanded node).
void slowDown(PlannerParameters& q) {
  q.trace = [](const std::string&) { std::this_thread::sleep_for(std::chrono::milliseconds(30)); };
}

}  // namespace

// Each member has two posture generators here, so that calls are solved
// ahead of their turn (lazy sons' batches) and the comparison runs with
// them; that they count only in their turn is what
// TheFirstOfTwoEqualMembersWinsThoughSlower tests (step_forward's goal
// expansions take every call they solve).
TEST(Portfolio, TheMemberWithTheFewestPostureCallsWinsWithThePlanItMakesAlone) {
  const Scenario& sc = step();
  PlannerParameters a, b;
  coarser().apply(b);
  const PlanningResult alone_a = ContactPlanner(sc, a).plan();
  const PlanningResult alone_b = ContactPlanner(sc, b).plan();
  ASSERT_TRUE(alone_a.solved() && alone_b.solved());
  const long na = alone_a.stats.searchCalls(), nb = alone_b.stats.searchCalls();
  ASSERT_NE(na, nb) << "the two settings must differ for this test to mean anything";
  const std::string best = na < nb ? "as configured" : "coarser";
  const std::string best_json = json(na < nb ? alone_a : alone_b, sc);
  // In either order, several times: the same winner and plan.
  for (int order = 0; order < 2; ++order) {
    for (int repeat = 0; repeat < 2; ++repeat) {
      PlannerParameters p;
      p.threads = 4;
      p.portfolio = order == 0 ? std::vector<PlannerVariant>{asConfigured(), coarser()}
                               : std::vector<PlannerVariant>{coarser(), asConfigured()};
      const PlanningResult r = ContactPlanner(sc, p).plan();
      ASSERT_TRUE(r.solved()) << r.reason;
      ASSERT_EQ(r.members.size(), 2u);
      ASSERT_GE(r.winner, 0);
      EXPECT_EQ(r.members[r.winner].name, best);
      EXPECT_EQ(json(r, sc), best_json);
      EXPECT_EQ(r.stats.searchCalls(), std::min(na, nb));
      // The loser either solved too (in its own count, before the winner
      // did) or was stopped past the winner's count.
      const PlanningResult::Member& loser = r.members[1 - r.winner];
      if (loser.status == PlanningResult::Status::Solved) {
        EXPECT_EQ(loser.stats.searchCalls(), std::max(na, nb));
      } else {
        EXPECT_EQ(loser.status, PlanningResult::Status::Cancelled);
        EXPECT_NE(loser.reason.find("outrun"), std::string::npos) << loser.reason;
        EXPECT_GE(loser.stats.searchCalls(), std::min(na, nb));
      }
      EXPECT_EQ(r.portfolioNodes(), r.members[0].stats.nodes_generated + r.members[1].stats.nodes_generated);
    }
  }
}

// A member that cannot win is stopped once another has solved and it is
// past that count of posture calls: here one whose every plan is refused,
// with budgets it would otherwise run to the end of (alone: no solution at
// 37 nodes, the winner solves in 20).
TEST(Portfolio, AMemberPastTheWinnersCountIsStopped) {
  const Scenario& sc = step();
  PlannerParameters p;
  p.portfolio = {asConfigured(), {"refusing", refuseEveryPlan}};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 0);
  EXPECT_EQ(r.members[1].status, PlanningResult::Status::Cancelled) << r.members[1].reason;
  EXPECT_NE(r.members[1].reason.find("outrun"), std::string::npos) << r.members[1].reason;
  EXPECT_GE(r.members[1].stats.searchCalls(), r.stats.searchCalls());
}

// While a member verifies a goal, a member past its count waits instead of
// searching on (its core goes to the verifier); the goal accepted, it is
// outrun. Here the refusing member is slowed (30 ms per expansion) and
// the winner's verifier holds its plan for 5 s: without the wait the
// refusing member ends its search meanwhile (no solution, 37 nodes in 1.8 s).
TEST(Portfolio, AMemberPastAGoalBeingVerifiedWaitsForItsVerdict) {
  const Scenario& sc = step();
  PlannerParameters p;
  p.verify_transitions = true;
  p.verify_plan = [](const Plan& plan, const std::atomic<bool>& stop) {
    for (int i = 0; i < 100 && !stop.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    PlanVerdict v;
    v.transitions = static_cast<int>(plan.stances.size()) - 1;
    return v;
  };
  p.portfolio = {asConfigured(), {"refusing, slowly", [](PlannerParameters& q) {
                                    refuseEveryPlan(q);
                                    slowDown(q);
                                  }}};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 0);
  EXPECT_EQ(r.members[1].status, PlanningResult::Status::Cancelled) << r.members[1].reason;
  EXPECT_NE(r.members[1].reason.find("outrun"), std::string::npos) << r.members[1].reason;
  EXPECT_LT(r.members[1].stats.nodes_generated, 37);
}

// A member verifying a goal stops when another starts verifying a better
// one (here the same count, found by the earlier member, which wins ties):
// only the better goal's verification runs. The earlier member is slowed
// (30 ms per expansion) so that the later one starts verifying first; each
// verifier holds a plan for 5 s unless stopped.
TEST(Portfolio, AVerificationOfABeatenGoalIsDeferred) {
  const Scenario& sc = step();
  std::mutex lock;
  std::vector<double> held;  // seconds each verifier call held, by member
  int made = 0;
  PlannerParameters p;
  p.verify_transitions = true;
  p.make_verifier = [&] {
    std::lock_guard<std::mutex> hold(lock);
    const int member = made++;
    if (held.size() < 2) held.resize(2, 0.0);
    return PlanVerifier([&, member](const Plan& plan, const std::atomic<bool>& stop) {
      const auto t0 = std::chrono::steady_clock::now();
      PlanVerdict v;
      v.transitions = static_cast<int>(plan.stances.size()) - 1;
      for (int i = 0; i < 100 && !stop.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      v.stopped = stop.load();
      std::lock_guard<std::mutex> hold(lock);
      held[member] += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      return v;
    });
  };
  p.portfolio = {{"slowed", slowDown}, asConfigured()};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 0);
  EXPECT_EQ(r.members[1].status, PlanningResult::Status::Cancelled) << r.members[1].reason;
  ASSERT_EQ(held.size(), 2u);
  EXPECT_GT(held[0], 4.5);  // the winner's verification ran whole
  EXPECT_LT(held[1], 3.0);  // the other's was stopped when the winner's began
}

// The first of two equal members wins the tie even when it solves later:
// the second's count caps it at its own, which it reaches only with its
// goal. With two generators a member its batches solve calls ahead of
// their turn; counted before their turn comes, they put it past that cap
// within its last expansion and the second won (sit_down: its goal comes
// before some of that expansion's calls are taken).
TEST(Portfolio, TheFirstOfTwoEqualMembersWinsThoughSlower) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/sit_down.yaml"));
  PlannerParameters p = plannerParameters(sc);
  p.threads = 4;
  p.portfolio = {{"slowed", slowDown}, {"second", {}}};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 0) << r.members[0].reason;
  // The second, not slowed, normally solves first (then with the same count).
  if (r.members[1].status == PlanningResult::Status::Solved) {
    EXPECT_EQ(r.members[0].stats.searchCalls(), r.members[1].stats.searchCalls());
  }
}

TEST(Portfolio, OfTwoEqualMembersTheFirstWins) {
  const Scenario& sc = step();
  PlannerParameters p;
  p.portfolio = {{"first", {}}, {"second", {}}};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 0);
  EXPECT_EQ(json(r, sc), json(ContactPlanner(sc).plan(), sc));
}

TEST(Portfolio, AMemberThatFailsDoesNotFailThePortfolio) {
  const Scenario& sc = step();
  PlannerParameters p;
  // With one contact at most, no stance leaves the start's two feet.
  p.portfolio = {{"one contact", [](PlannerParameters& q) { q.max_contacts = 1; }}, asConfigured()};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 1);
  EXPECT_NE(r.members[0].status, PlanningResult::Status::Solved);
  // None solves: the reasons of both, by name.
  p.portfolio = {{"one contact", [](PlannerParameters& q) { q.max_contacts = 1; }},
                 {"also one contact", [](PlannerParameters& q) { q.max_contacts = 1; }}};
  const PlanningResult none = ContactPlanner(sc, p).plan();
  EXPECT_FALSE(none.solved());
  EXPECT_EQ(none.winner, -1);
  EXPECT_NE(none.reason.find("one contact: "), std::string::npos) << none.reason;
  EXPECT_NE(none.reason.find("also one contact: "), std::string::npos) << none.reason;
  EXPECT_TRUE(none.plan.stances.empty());
}

// Every member's refused plans reach the caller, named by member, with the
// plans themselves when asked (--keep-refused): here no member solves, and
// before, the result carried none of them.
TEST(Portfolio, EveryMembersRefusalsAreKeptNamedByMember) {
  const Scenario& sc = step();
  PlannerParameters p;
  p.keep_refused_plans = true;
  p.portfolio = {{"refusing", refuseEveryPlan}, {"also refusing", refuseEveryPlan}};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_FALSE(r.solved());
  ASSERT_EQ(r.members.size(), 2u);
  long refused = 0;
  for (const auto& m : r.members) {
    EXPECT_GT(m.stats.plans_refused, 0) << m.name;
    refused += m.stats.plans_refused;
  }
  EXPECT_EQ(static_cast<long>(r.refusals.size()), refused);
  ASSERT_EQ(r.refusal_members.size(), r.refusals.size());
  EXPECT_EQ(r.refused_plans.size(), r.refusals.size());
  // In the members' order, each line as its member wrote it.
  EXPECT_EQ(r.refusal_members.front(), "refusing");
  EXPECT_EQ(r.refusal_members.back(), "also refusing");
  for (const std::string& why : r.refusals) EXPECT_EQ(why.rfind("stances 0 -> 1: refused by the test", 0), 0u) << why;
}

TEST(Portfolio, ACancelReachesEveryMember) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  PlannerParameters p = plannerParameters(sc);
  p.portfolio = {asConfigured(), coarser()};
  std::atomic<bool> cancel{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    cancel = true;
  });
  const PlanningResult r = ContactPlanner(sc, p).plan(&cancel);
  stopper.join();
  EXPECT_EQ(r.status, PlanningResult::Status::Cancelled);
  ASSERT_EQ(r.members.size(), 2u);
  for (const auto& m : r.members) EXPECT_EQ(m.status, PlanningResult::Status::Cancelled) << m.name;
  EXPECT_LT(r.stats.seconds, 5.0);  // each stops at its next posture call's end, not at the budget
}

TEST(Portfolio, EachMemberVerifiesWithItsOwnVerifierOrOneAtATime) {
  const Scenario& sc = step();
  // A verifier that accepts every plan, and notes calls that overlap.
  std::atomic<int> inside{0}, overlaps{0}, calls{0}, made{0};
  auto accepting = [&](const Plan& plan, const std::atomic<bool>&) {
    if (inside.fetch_add(1) > 0) ++overlaps;
    ++calls;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    --inside;
    PlanVerdict v;
    v.transitions = static_cast<int>(plan.stances.size()) - 1;
    return v;
  };
  PlannerParameters p;
  p.verify_transitions = true;
  p.verify_plan = accepting;
  p.portfolio = {asConfigured(), coarser()};
  PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_GE(calls.load(), 1);
  EXPECT_EQ(overlaps.load(), 0);  // one shared verifier: one call at a time
  // With a factory: one verifier per member.
  p.make_verifier = [&] {
    ++made;
    return PlanVerifier(accepting);
  };
  r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(made.load(), 2);
}

TEST(Portfolio, TraceLinesNameTheirMember) {
  const Scenario& sc = step();
  std::mutex lock;
  std::vector<std::string> lines;
  PlannerParameters p;
  p.trace = [&](const std::string& line) {
    std::lock_guard<std::mutex> hold(lock);
    lines.push_back(line);
  };
  p.portfolio = {asConfigured(), coarser()};
  ASSERT_TRUE(ContactPlanner(sc, p).plan().solved());
  ASSERT_FALSE(lines.empty());
  for (const auto& l : lines)
    EXPECT_TRUE(l.rfind("[as configured] ", 0) == 0 || l.rfind("[coarser] ", 0) == 0) << l;
}

// In sequence (portfolio_mode: sequence): the first member that solves
// answers, with the very plan it makes alone, and the members after it are
// not run.
TEST(Portfolio, InSequenceTheFirstMemberThatSolvesAnswersAndTheRestDoNotRun) {
  const Scenario& sc = step();
  PlannerParameters p;
  const PlanningResult alone = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(alone.solved()) << alone.reason;
  p.portfolio_mode = PlannerParameters::PortfolioMode::Sequence;
  p.portfolio = {asConfigured(), coarser()};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 0);
  ASSERT_EQ(r.members.size(), 1u);  // "coarser" never ran
  EXPECT_EQ(r.members[0].name, "as configured");
  EXPECT_EQ(json(r, sc), json(alone, sc));
  EXPECT_EQ(r.stats.searchCalls(), alone.stats.searchCalls());
  EXPECT_EQ(r.portfolioNodes(), alone.stats.nodes_generated);
}

// A member that ends without a plan (its own node budget here) hands over
// to the next, whose plan is its own alone; none solving, the last one's
// status and every member's reason.
TEST(Portfolio, InSequenceAMemberOutOfItsBudgetHandsOverToTheNext) {
  const Scenario& sc = step();
  PlannerParameters p;
  const PlanningResult alone = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(alone.solved()) << alone.reason;
  ASSERT_GT(alone.stats.nodes_generated, 3);
  p.portfolio_mode = PlannerParameters::PortfolioMode::Sequence;
  p.portfolio = {{"three nodes", [](PlannerParameters& q) { q.max_nodes = 3; }}, asConfigured()};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 1);
  ASSERT_EQ(r.members.size(), 2u);
  EXPECT_EQ(r.members[0].status, PlanningResult::Status::NodeBudget) << r.members[0].reason;
  EXPECT_EQ(r.members[0].stats.nodes_generated, 3);
  EXPECT_EQ(json(r, sc), json(alone, sc));
  EXPECT_EQ(r.portfolioNodes(), 3 + alone.stats.nodes_generated);

  p.portfolio = {{"one contact", [](PlannerParameters& q) { q.max_contacts = 1; }},
                 {"three nodes", [](PlannerParameters& q) { q.max_nodes = 3; }}};
  const PlanningResult none = ContactPlanner(sc, p).plan();
  EXPECT_FALSE(none.solved());
  EXPECT_EQ(none.winner, -1);
  ASSERT_EQ(none.members.size(), 2u);
  EXPECT_EQ(none.status, PlanningResult::Status::NodeBudget);  // the last member's
  EXPECT_NE(none.reason.find("one contact: "), std::string::npos) << none.reason;
  EXPECT_NE(none.reason.find("three nodes: "), std::string::npos) << none.reason;
  EXPECT_TRUE(none.plan.stances.empty());
}

// max_plateau_nodes: a search whose best guide potential has not fallen for
// that many nodes stops, saying so, and in a sequence hands over to the
// next member, whose plan is then the one it makes alone. A bound the
// search never reaches changes nothing.
TEST(Portfolio, InSequenceAMemberOnAPlateauHandsOverToTheNext) {
  const Scenario& sc = step();
  PlannerParameters p;
  const PlanningResult alone = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(alone.solved()) << alone.reason;
  PlannerParameters wide = p;
  wide.max_plateau_nodes = alone.stats.nodes_generated + 1;
  EXPECT_EQ(json(ContactPlanner(sc, wide).plan(), sc), json(alone, sc));

  PlannerParameters flat = p;
  flat.max_plateau_nodes = 1;  // any son that does not lower the best potential
  const PlanningResult stopped = ContactPlanner(sc, flat).plan();
  ASSERT_FALSE(stopped.solved()) << "step_forward's search must generate a son no better than the best, or this "
                                    "tests nothing";
  EXPECT_EQ(stopped.status, PlanningResult::Status::NodeBudget);
  EXPECT_NE(stopped.reason.find("since the guide potential last fell (max_plateau_nodes"), std::string::npos)
      << stopped.reason;
  EXPECT_LT(stopped.stats.nodes_generated, alone.stats.nodes_generated);

  p.portfolio_mode = PlannerParameters::PortfolioMode::Sequence;
  p.portfolio = {{"flat", [](PlannerParameters& q) { q.max_plateau_nodes = 1; }}, asConfigured()};
  const PlanningResult r = ContactPlanner(sc, p).plan();
  ASSERT_TRUE(r.solved()) << r.reason;
  EXPECT_EQ(r.winner, 1);
  ASSERT_EQ(r.members.size(), 2u);
  EXPECT_EQ(r.members[0].status, PlanningResult::Status::NodeBudget) << r.members[0].reason;
  EXPECT_EQ(r.members[0].stats.nodes_generated, stopped.stats.nodes_generated);
  EXPECT_EQ(json(r, sc), json(alone, sc));
}

// The time budget bounds the sequence, not each member: a member that
// spends it (here one that would run for minutes: every plan refused, 30 ms
// per expansion, its own max_seconds 600) ends on it, and the next is not run.
TEST(Portfolio, InSequenceTheMembersShareTheTimeBudget) {
  const Scenario& sc = step();
  PlannerParameters p;
  p.max_seconds = 1.0;
  p.portfolio_mode = PlannerParameters::PortfolioMode::Sequence;
  p.portfolio = {{"refusing", [](PlannerParameters& q) {
                    refuseEveryPlan(q);
                    slowDown(q);
                  }},
                 asConfigured()};
  const auto t0 = std::chrono::steady_clock::now();
  const PlanningResult r = ContactPlanner(sc, p).plan();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(r.solved());
  EXPECT_EQ(r.status, PlanningResult::Status::TimeLimit) << r.reason;
  ASSERT_EQ(r.members.size(), 1u);
  EXPECT_LT(seconds, 30.0);  // not the member's own 600 s (nor the slowed search's end)
}

TEST(Portfolio, ReadFromTheScenarioWithNamedErrors) {
  test::TempDir dir;
  const std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  const Scenario sc = Scenario::load(dir.write(
      "a.yaml", text + "planner: {duplicate_distance: 0.06, portfolio: [{}, {name: coarse, duplicate_distance: 0.1, "
                       "posture_distance_engine: convex}]}\n"));
  const PlannerParameters p = plannerParameters(sc);
  ASSERT_EQ(p.portfolio.size(), 2u);
  EXPECT_EQ(p.portfolio[0].name, "member 1");
  EXPECT_EQ(p.portfolio[1].name, "coarse");
  PlannerParameters q = p;
  p.portfolio[0].apply(q);
  EXPECT_DOUBLE_EQ(q.duplicate_distance, 0.06);  // an empty member: as configured
  EXPECT_EQ(q.posture.distance_engine, DistanceEngine::Fcl);
  p.portfolio[1].apply(q);
  EXPECT_DOUBLE_EQ(q.duplicate_distance, 0.1);
  EXPECT_EQ(q.posture.distance_engine, DistanceEngine::Convex);
  EXPECT_EQ(p.portfolio_mode, PlannerParameters::PortfolioMode::Race);  // by default
  // A sequence, its first member with its own budgets.
  const Scenario seq = Scenario::load(dir.write(
      "b.yaml", text + "planner: {max_nodes: 900, portfolio_mode: sequence, portfolio: [{max_nodes: 7, "
                       "max_posture_calls: 11, max_plateau_nodes: 5}, {}]}\n"));
  const PlannerParameters ps = plannerParameters(seq);
  EXPECT_EQ(ps.portfolio_mode, PlannerParameters::PortfolioMode::Sequence);
  PlannerParameters first = ps, second = ps;
  ps.portfolio[0].apply(first);
  ps.portfolio[1].apply(second);
  EXPECT_EQ(first.max_nodes, 7);
  EXPECT_EQ(first.max_posture_calls, 11);
  EXPECT_EQ(second.max_nodes, 900);
  EXPECT_EQ(first.max_plateau_nodes, 5);
  EXPECT_EQ(second.max_plateau_nodes, 0);  // by default: no such bound
  for (const auto& [bad, field] : std::vector<std::pair<std::string, std::string>>{
           {"planner: {portfolio: [{}]}\n", "planner.portfolio"},
           {"planner: {portfolio: {a: 1}}\n", "planner.portfolio"},
           {"planner: {portfolio: [{}, 3]}\n", "planner.portfolio[1]"},
           {"planner: {portfolio: [{}, {max_nodes: 0}]}\n", "planner.portfolio[1].max_nodes"},
           {"planner: {portfolio: [{}, {max_plateau_nodes: -1}]}\n", "planner.portfolio[1].max_plateau_nodes"},
           {"planner: {max_plateau_nodes: 1.5}\n", "planner.max_plateau_nodes"},
           {"planner: {portfolio: [{}, {portfolio_mode: race}]}\n", "planner.portfolio[1].portfolio_mode"},
           {"planner: {portfolio: [{}, {}], portfolio_mode: together}\n", "planner.portfolio_mode"},
           {"planner: {portfolio: [{}, {threads: 1}]}\n", "planner.portfolio[1].threads"},
           {"planner: {portfolio: [{}, {duplicate_distance: -1}]}\n", "planner.portfolio[1].duplicate_distance"},
           {"planner: {portfolio: [{name: a}, {name: a}]}\n", "planner.portfolio[1].name"},
           {"planner: {portfolio: [{}, {portfolio: [{}, {}]}]}\n", "planner.portfolio[1].portfolio"}}) {
    const Scenario s = Scenario::load(dir.write("c.yaml", text + bad));
    try {
      plannerParameters(s);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const FormatError& e) {
      EXPECT_EQ(e.field(), field) << e.what();
    }
  }
}
