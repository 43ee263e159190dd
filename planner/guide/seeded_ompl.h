#pragma once
// OMPL's random generators seeded per call: the same problem and seed give
// the same path in any process and on any thread, however many plans were
// made before (OMPL otherwise seeds each generator from a global sequence).
// Used by the guide author and by the interpolator's body-path planner.
#include <memory>
#include <optional>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>

namespace acyclic {

class SeededSampler : public ompl::base::RealVectorStateSampler {
 public:
  SeededSampler(const ompl::base::StateSpace* space, unsigned seed) : ompl::base::RealVectorStateSampler(space) {
    rng_.setLocalSeed(seed);
  }
};

class SeededRRTConnect : public ompl::geometric::RRTConnect {
 public:
  SeededRRTConnect(const ompl::base::SpaceInformationPtr& si, unsigned seed) : ompl::geometric::RRTConnect(si) {
    rng_.setLocalSeed(seed);
  }
};

class SeededSimplifier : public ompl::geometric::PathSimplifier {
 public:
  SeededSimplifier(const ompl::base::SpaceInformationPtr& si, unsigned seed) : ompl::geometric::PathSimplifier(si) {
    rng_.setLocalSeed(seed);
  }
};

// RRTConnect seeded on `ss` (its space, validity checker, start and goal
// set), bounded by state checks, not time (the same path under any load):
// `checks` is the count the validity checker keeps. The path found, its
// vertices reduced and shortcut; none without an exact solution.
inline std::optional<ompl::geometric::PathGeometric> solveSeededRRTConnect(ompl::geometric::SimpleSetup& ss,
                                                                           unsigned seed, const long& checks,
                                                                           long max_checks) {
  auto si = ss.getSpaceInformation();
  ss.setPlanner(std::make_shared<SeededRRTConnect>(si, seed));
  ss.setup();
  const ompl::base::PlannerStatus st =
      ss.solve(ompl::base::PlannerTerminationCondition([&] { return checks >= max_checks; }));
  if (st != ompl::base::PlannerStatus::EXACT_SOLUTION) return std::nullopt;
  ompl::geometric::PathGeometric g = ss.getSolutionPath();
  SeededSimplifier simplifier(si, seed);
  simplifier.reduceVertices(g);
  simplifier.shortcutPath(g);
  simplifier.reduceVertices(g);
  return g;
}

}  // namespace acyclic
