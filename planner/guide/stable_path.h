#pragma once
// A rough path carried into the statically stable subspace (Bouyarmane,
// Escande, Lamiraux and Kheddar, ICRA 2009: the guide planned among
// configurations in static equilibrium on contacts with the environment
// near them, each sample projected there by the posture generator). The
// guide author samples its shortcut path along the edges, not only at the
// vertices, and projects each sample in order: the posture generator near
// the sample, on the contacts it makes with the scene, and only a posture
// the independent check accepts. A sample that does not project tells the
// author where the subspace is not reached (it replans around it).
#include <atomic>
#include <string>
#include <vector>

#include "planner/guide/guide_postures.h"

namespace acyclic {

struct StableOptions {
  double reach = 0.05;  // m: a spot this close to an allowed surface (and facing it, 0.5 rad) rests on it
  double angle = 0.5;   // rad
  // m: a projection's base within this of the sample's, horizontally (its
  // height is what the stance makes it: a rough path may float).
  double tolerance = 0.1;
};

struct StableProjection {
  std::vector<Configuration> postures;  // on success: one per sample, the first and last as given
  int failed_sample = -1;               // the first sample with no stable posture near it; -1: none
  int projections = 0;                  // posture generator calls made
  std::string reason;                   // why failed_sample did not project
  bool success() const { return failed_sample < 0; }
};

// Projects `samples` (whole-body configurations along a path; the first and
// the last are valid postures already and are kept as they are) in order.
// Sample i is the posture generator's witness near it (its base's place
// weighs most) accepted by the check, on the first of these contact sets
// that gives one, from the previous projection as the guess, then from
// the sample itself:
//   1. the contacts the sample makes within `reach` (its own stance);
//   2. the previous projection's contacts re-placed under where the sample
//      holds those spots (the stance carried along);
//   3. the previous projection's contacts where they were (the stance kept).
// Every contact supports. A witness whose base lies farther than
// `tolerance` from the sample's horizontally is not near it (a stance kept
// at the edge of a gap while the path crosses it). Stops at the first
// sample with none (or on
// `cancel`, failed_sample at the sample reached and reason "cancelled").
StableProjection projectStable(const Scenario& sc, PostureTools& t, const std::vector<Configuration>& samples,
                               const StableOptions& o, const std::atomic<bool>* cancel = nullptr);

}  // namespace acyclic
