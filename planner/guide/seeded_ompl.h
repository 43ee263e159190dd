#pragma once
// OMPL's random generators seeded per call: the same problem and seed give
// the same path in any process and on any thread, however many plans were
// made before (OMPL otherwise seeds each generator from a global sequence).
// Used by the guide author and by the interpolator's body-path planner.
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
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

}  // namespace acyclic
