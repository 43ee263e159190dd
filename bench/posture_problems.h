#pragma once
// The posture generator's benchmark problems (bench_posture, bench_kkt): a
// fixed, seeded set drawn from the chair scene: random subsets of the seated
// stance (each foot or thigh kept, supporting or geometric only), perturbed
// start guesses, and two in three with a floating contact in a random part of
// a surface; some infeasible by construction.
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "planner/posture/posture_generator.h"
#include "planner/scene/scenario.h"

namespace acyclic::bench {

struct Problem {
  std::string label;
  PostureRequest request;
  std::vector<ContactSpec> stance;  // for the check: floating contact added as geometric only
};

inline std::vector<Problem> makeProblems(const Scenario& sc, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const std::vector<std::string> floating_spots = {"l_wrist", "r_wrist", "l_palm", "r_palm",
                                                   "l_forearm", "r_forearm", "l_knee", "r_knee"};
  std::vector<Problem> out;
  for (int i = 0; i < n; ++i) {
    Problem p;
    PostureRequest& r = p.request;
    // A random subset of the start stance: each foot or thigh kept (supporting,
    // or geometric only), at least one supporting.
    for (const auto& c : sc.start_stance) {
      const double dice = u(rng);
      if (dice < 0.15) continue;  // dropped
      ContactSpec cs = c;
      cs.supporting = dice > 0.3;
      r.contacts.push_back(cs);
    }
    bool any = false;
    for (const auto& c : r.contacts) any = any || c.supporting;
    if (!any) r.contacts = sc.start_stance;
    // Start guess: the seated posture, perturbed.
    r.initial_guess = sc.start;
    for (int j = 0; j < r.initial_guess.joints.size(); ++j) r.initial_guess.joints[j] += 0.1 * g(rng);
    r.initial_guess.base_position += 0.02 * Eigen::Vector3d(g(rng), g(rng), g(rng));
    r.cost = std::make_shared<ReferencePostureCost>(sc.start);
    p.stance = r.contacts;
    p.label = std::to_string(r.contacts.size()) + " fixed";
    // Two problems in three also search a floating contact in a random part of a surface.
    if (u(rng) < 0.67) {
      FloatingContact f;
      f.spot = sc.robot->spotIndex(floating_spots[rng() % floating_spots.size()]);
      f.surface = sc.allowed_surfaces[rng() % sc.allowed_surfaces.size()];
      const Surface& s = sc.scene->surfaces()[f.surface];
      // a random rectangle inside the surface polygon's bounding box, clipped to 1.2 m around the robot
      Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
      for (const auto& v : s.polygon.vertices()) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      const Eigen::Vector2d robot = (s.frame.inverse() * sc.start.base_position).head<2>();
      lo = lo.cwiseMax(robot - Eigen::Vector2d(1.2, 1.2));
      hi = hi.cwiseMin(robot + Eigen::Vector2d(1.2, 1.2));
      const double w = 0.1 + 0.3 * u(rng);
      const Eigen::Vector2d c(lo.x() + (hi.x() - lo.x()) * u(rng), lo.y() + (hi.y() - lo.y()) * u(rng));
      const Eigen::Vector2d a = (c - Eigen::Vector2d(w, w)).cwiseMax(lo), b = (c + Eigen::Vector2d(w, w)).cwiseMin(hi);
      if ((b - a).minCoeff() > 0.02) {
        f.volume.polygon = ConvexPolygon({{a.x(), a.y()}, {b.x(), a.y()}, {b.x(), b.y()}, {a.x(), b.y()}});
        r.floating = f;
        p.label += " + " + sc.robot->spots()[f.spot].name + "@" + s.name;
      }
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace acyclic::bench
