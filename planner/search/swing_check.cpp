#include "planner/search/swing_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace acyclic {

namespace {

// The deepest penetration (positive) of the limb below joint `root` at q, and the pair.
double deepest(const RobotModel& m, const CollisionModel& collisions, Kinematics& kin, int root,
               const Configuration& q, int* pair) {
  kin.setConfiguration(q);
  double worst = -std::numeric_limits<double>::infinity();
  for (int pi : collisions.pairsWithin(kin, 0.0)) {
    const CollisionPair& p = collisions.pairs()[pi];
    const bool in_a = m.jointMovesLink(root, p.link_a);
    const bool in_b = p.kind == CollisionPair::Kind::Self && m.jointMovesLink(root, p.link_b);
    if (in_a == in_b) continue;  // not across the limb's boundary
    const double d = -collisions.pairDistance(kin, pi, false).distance;
    if (d > worst) worst = d, *pair = pi;
  }
  return worst;
}

}  // namespace

std::string checkHangingSwings(const Scenario& sc, const CollisionModel& collisions, Kinematics& kin,
                               const std::vector<ContactSpec>& held, const Configuration& a, const Configuration& b,
                               const SwingOptions& o) {
  const RobotModel& m = *sc.robot;
  for (const auto& h : held) {
    const int link = m.spots()[h.spot].link;
    for (const auto& j : m.joints()) {
      if (j.parent_link != link) continue;
      // The limb below: every joint j moves. Another held contact on it closes the chain.
      bool closed = false;
      for (const auto& c : held) closed = closed || m.jointMovesLink(j.index, m.spots()[c.spot].link);
      if (closed) continue;
      const std::vector<int> joints = m.jointsMovedBy(j.index);
      bool moves = false;
      for (int k : joints) moves = moves || a.joints[k] != b.joints[k];
      if (!moves) continue;
      // The end joints: those that move no link with shapes but the limb's
      // last one (an ankle's pitch and roll, which turn the foot alone). The
      // interpolator is free to turn them (the knots are posture-generator
      // solutions): where the interpolation dips, they are tried across
      // their range (kGrid values each) before the swing is refused.
      int last = -1;
      for (int k : joints)
        if (!m.links()[m.joints()[k].child_link].shapes.empty()) last = m.joints()[k].child_link;
      std::vector<int> ends;
      for (int k : joints) {
        bool only_last = true;
        for (const auto& l : m.links())
          if (m.jointMovesLink(k, l.index) && !l.shapes.empty() && l.index != last) only_last = false;
        if (only_last) ends.push_back(k);
      }
      constexpr int kGrid = 7;
      const int combos = ends.size() <= 3 ? static_cast<int>(std::pow(kGrid, ends.size())) : 0;
      for (int i = 1; i <= o.samples; ++i) {
        const double s = static_cast<double>(i) / (o.samples + 1);
        Configuration q = a;  // the held link as in a (where b has it too)
        for (int k : joints) q.joints[k] = (1 - s) * a.joints[k] + s * b.joints[k];
        int pair = -1;
        double depth = deepest(m, collisions, kin, j.index, q, &pair);
        for (int c = 0; c < combos && depth > o.tolerance; ++c) {
          Configuration t = q;
          for (int e = 0, rest = c; e < static_cast<int>(ends.size()); ++e, rest /= kGrid) {
            const JointInfo& ji = m.joints()[ends[e]];
            t.joints[ends[e]] = ji.lower + (ji.upper - ji.lower) * (rest % kGrid) / (kGrid - 1);
          }
          int p = -1;
          const double d = deepest(m, collisions, kin, j.index, t, &p);
          if (d < depth) depth = d, pair = p;
        }
        if (depth > o.tolerance) {
          char buf[96];
          std::snprintf(buf, sizeof buf, " by %.1f mm, swinging below %s's contact", depth * 1e3,
                        m.spots()[h.spot].name.c_str());
          return collisions.describe(pair) + buf;
        }
      }
    }
  }
  return "";
}

}  // namespace acyclic
