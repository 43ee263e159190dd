#include "planner/guide/guide_postures.h"

#include <memory>

#include "planner/posture/posture_cost.h"

namespace acyclic {

PostureGeneratorOptions guidePostureOptions() {
  PostureGeneratorOptions po;
  po.max_iterations = 200;
  po.max_seconds = 2.0;
  return po;
}

std::optional<Configuration> witnessNear(PostureGenerator& pg, const std::vector<ContactSpec>& contacts,
                                         const Configuration& guess, const Configuration& reference) {
  PostureRequest r;
  r.contacts = contacts;
  r.initial_guess = guess;
  r.cost = std::make_shared<ReferencePostureCost>(reference, 0.01, 10.0, 1.0);
  const PostureResult res = pg.solve(r);
  if (!res.success()) return std::nullopt;
  return res.configuration;
}

std::optional<Configuration> checkedWitnessNear(PostureTools& t, const std::vector<ContactSpec>& contacts,
                                                const Configuration& guess, const Configuration& reference) {
  auto w = witnessNear(t.pg, contacts, guess, reference);
  if (w && !t.checker.checkPosture(*w, contacts).valid()) w.reset();
  return w;
}

std::vector<ContactSpec> contactsMadeBy(const Scenario& sc, Kinematics& kin, const Configuration& q, double distance,
                                        double angle) {
  kin.setConfiguration(q);
  std::vector<ContactSpec> out;
  for (int spot : sc.allowed_spots)
    for (int si : sc.allowed_surfaces) {
      if (!sc.allows(spot, si)) continue;
      const Surface& surf = sc.scene->surfaces()[si];
      if (!spotNearSurface(surf, kin.spotPose(spot), distance, angle)) continue;
      ContactSpec c;
      c.spot = spot;
      c.surface = si;
      c.placement = projectOnSurface(surf, kin.spotPose(spot));
      out.push_back(c);
      break;
    }
  return out;
}

}  // namespace acyclic
