#pragma once
// Contact search volumes (paper, 2.5-2.6): C = polygon(E) x ]-pi, pi] for a
// pair (spot R, surface E). After each candidate (x, y, theta), a small box V
// around it is subtracted and C \ V is split into at most 6 convex parts:
//   theta below V, theta above V (the whole polygon each), and over V's
//   theta range the polygon minus V's rectangle, cut into 4 convex pieces
//   (x below, x above, and between them y below, y above).
// Angles are kept unwrapped: an interval [lo, hi] with hi - lo <= 2 pi means
// the angles lo..hi modulo 2 pi. A full circle is re-centred on the candidate
// (then C \ V has 5 parts), and no later interval is long enough for a box to
// wrap around into it.
#include <vector>

#include "planner/posture/posture_problem.h"  // SearchVolume

namespace acyclic {

struct BoxHalfSizes {
  double x = 0.05;      // m
  double y = 0.05;      // m
  double theta = 0.35;  // rad
};

// The full search volume of a surface: its polygon, all orientations.
SearchVolume fullVolume(const ConvexPolygon& surface_polygon);
bool isFullCircle(const SearchVolume& v);
// The parts of C \ V, V the box of the given half sizes around `center`
// (which must lie in C). Parts thinner than `min_size` (m or rad) are dropped.
std::vector<SearchVolume> subtractBox(const SearchVolume& C, const SurfacePlacement& center, const BoxHalfSizes& box,
                                      double min_size = 1e-4);
// Membership, with theta taken modulo 2 pi.
bool contains(const SearchVolume& v, double x, double y, double theta, double tolerance = 0.0);
double measure(const SearchVolume& v);  // area x angle

// The convex polygon clipped by the half-plane n . p <= b; empty if nothing is left.
std::vector<Eigen::Vector2d> clip(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& n, double b);

}  // namespace acyclic
