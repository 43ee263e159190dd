#include "planner/guide/stable_path.h"

#include "planner/common/fmt.h"

namespace acyclic {

namespace {

bool sameSpots(const std::vector<ContactSpec>& a, const std::vector<ContactSpec>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].spot != b[i].spot || a[i].surface != b[i].surface) return false;
  return true;
}

// `contacts` re-placed under where `kin` holds their spots; false when one
// falls off its surface's polygon.
bool replaceUnder(const Scenario& sc, const Kinematics& kin, std::vector<ContactSpec>& contacts) {
  for (auto& c : contacts) {
    const Surface& surf = sc.scene->surfaces()[c.surface];
    c.placement = projectOnSurface(surf, kin.spotPose(c.spot));
    if (!surf.polygon.contains(Eigen::Vector2d(c.placement.x, c.placement.y))) return false;
  }
  return true;
}

std::string names(const Scenario& sc, const std::vector<ContactSpec>& contacts) {
  std::string s;
  for (const auto& c : contacts)
    s += (s.empty() ? "" : ", ") + sc.robot->spots()[c.spot].name + "@" + sc.scene->surfaces()[c.surface].name;
  return s.empty() ? "none" : s;
}

}  // namespace

StableProjection projectStable(const Scenario& sc, PostureTools& t, const std::vector<Configuration>& samples,
                               const StableOptions& o, const std::atomic<bool>* cancel) {
  StableProjection out;
  if (samples.empty()) return out;
  out.postures.push_back(samples.front());
  // The stance under the first posture: the contacts it makes (within 1 cm).
  std::vector<ContactSpec> stance = contactsMadeBy(sc, t.kin, samples.front());
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (i + 1 == samples.size()) {  // the leg's end: a valid posture already
      out.postures.push_back(samples.back());
      break;
    }
    if (cancel && cancel->load()) {
      out.failed_sample = static_cast<int>(i);
      out.reason = "cancelled";
      return out;
    }
    const Configuration& q = samples[i];
    const Configuration& prev = out.postures.back();
    std::vector<std::vector<ContactSpec>> sets;
    std::vector<ContactSpec> own = contactsMadeBy(sc, t.kin, q, o.reach, o.angle);
    if (!own.empty()) sets.push_back(own);
    std::vector<ContactSpec> carried = stance;
    t.kin.setConfiguration(q);
    if (!carried.empty() && replaceUnder(sc, t.kin, carried) && !sameSpots(carried, own)) sets.push_back(carried);
    if (!stance.empty()) sets.push_back(stance);
    bool projected = false;
    for (auto& contacts : sets) {
      for (auto& c : contacts) c.supporting = true;
      for (const Configuration* guess : {&prev, &q}) {
        ++out.projections;
        const auto w = checkedWitnessNear(t, contacts, *guess, q);
        if (w && (w->base_position - q.base_position).head<2>().norm() <= o.tolerance) {
          out.postures.push_back(*w);
          stance = contacts;
          projected = true;
          break;
        }
      }
      if (projected) break;
    }
    if (!projected) {
      out.failed_sample = static_cast<int>(i);
      out.reason = fmt("no statically stable posture near the rough path at base (%.2f, %.2f, %.2f)", q.base_position.x(),
                       q.base_position.y(), q.base_position.z()) +
                   ", sample " + std::to_string(i) + " of " + std::to_string(samples.size() - 1) +
                   fmt(" (none within %.2f m of it horizontally; ", o.tolerance) +
                   fmt("tried its own contacts within %.2f m: ", o.reach) + names(sc, own) +
                   "; the stance before it: " + names(sc, stance) + ")";
      return out;
    }
  }
  return out;
}

}  // namespace acyclic
