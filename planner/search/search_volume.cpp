#include "planner/search/search_volume.h"

#include <cmath>

namespace acyclic {

SearchVolume fullVolume(const ConvexPolygon& p) {
  SearchVolume v;
  v.polygon = p;
  v.theta_min = -M_PI;
  v.theta_max = M_PI;
  return v;
}

bool isFullCircle(const SearchVolume& v) { return v.theta_max - v.theta_min >= 2 * M_PI - 1e-12; }

std::vector<Eigen::Vector2d> clip(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& n, double b) {
  std::vector<Eigen::Vector2d> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d& p = poly[i];
    const Eigen::Vector2d& q = poly[(i + 1) % poly.size()];
    const double dp = n.dot(p) - b, dq = n.dot(q) - b;
    if (dp <= 0) out.push_back(p);
    if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) out.push_back(p + (q - p) * (dp / (dp - dq)));
  }
  return out;
}

namespace {

// A part, unless too thin: a polygon with area and an interval with length.
void addPart(std::vector<SearchVolume>& parts, const std::vector<Eigen::Vector2d>& pts, double lo, double hi,
             double min_size) {
  if (hi - lo < min_size || pts.size() < 3) return;
  // Drop near-duplicate vertices left by clipping through a vertex.
  std::vector<Eigen::Vector2d> clean;
  for (const auto& p : pts)
    if (clean.empty() || (p - clean.back()).norm() > 1e-12) clean.push_back(p);
  while (clean.size() > 1 && (clean.front() - clean.back()).norm() <= 1e-12) clean.pop_back();
  if (clean.size() < 3) return;
  try {
    ConvexPolygon poly(clean);
    // thinner than min_size in its narrowest direction: area / diameter
    double diameter = 0;
    for (const auto& a : poly.vertices())
      for (const auto& c : poly.vertices()) diameter = std::max(diameter, (a - c).norm());
    if (poly.area() / diameter < 0.5 * min_size) return;
    SearchVolume v;
    v.polygon = poly;
    v.theta_min = lo;
    v.theta_max = hi;
    parts.push_back(v);
  } catch (const std::invalid_argument&) {
    // degenerate (collinear) remainder: nothing to search there
  }
}

}  // namespace

std::vector<SearchVolume> subtractBox(const SearchVolume& C, const SurfacePlacement& center, const BoxHalfSizes& box,
                                      double min_size) {
  std::vector<SearchVolume> parts;
  const auto& P = C.polygon.vertices();
  double lo = C.theta_min, hi = C.theta_max;
  double t = center.theta;
  if (isFullCircle(C)) {
    // Re-centre the circle on the candidate: what is left of it in theta is one arc.
    lo = t - M_PI;
    hi = t + M_PI;
    addPart(parts, P, t + box.theta, t + 2 * M_PI - box.theta, min_size);
  } else {
    t = lo + std::remainder(t - lo - M_PI, 2 * M_PI) + M_PI;  // the candidate's angle inside [lo, hi]
    addPart(parts, P, lo, std::min(hi, t - box.theta), min_size);
    addPart(parts, P, std::max(lo, t + box.theta), hi, min_size);
  }
  const double vlo = std::max(lo, t - box.theta), vhi = std::min(hi, t + box.theta);
  const double x0 = center.x - box.x, x1 = center.x + box.x, y0 = center.y - box.y, y1 = center.y + box.y;
  const Eigen::Vector2d ex(1, 0), ey(0, 1);
  addPart(parts, clip(P, ex, x0), vlo, vhi, min_size);                               // x <= x0
  addPart(parts, clip(P, -ex, -x1), vlo, vhi, min_size);                             // x >= x1
  const auto band = clip(clip(P, -ex, -x0), ex, x1);                                 // x0 <= x <= x1
  addPart(parts, clip(band, ey, y0), vlo, vhi, min_size);                            // y <= y0
  addPart(parts, clip(band, -ey, -y1), vlo, vhi, min_size);                          // y >= y1
  return parts;
}

bool contains(const SearchVolume& v, double x, double y, double theta, double tolerance) {
  if (!v.polygon.contains({x, y}, tolerance)) return false;
  if (isFullCircle(v)) return true;
  // theta modulo 2 pi, placed at or above theta_min
  const double t = v.theta_min + std::fmod(std::fmod(theta - v.theta_min, 2 * M_PI) + 2 * M_PI, 2 * M_PI);
  return t <= v.theta_max + tolerance || t - 2 * M_PI >= v.theta_min - tolerance;
}

double measure(const SearchVolume& v) { return v.polygon.area() * (v.theta_max - v.theta_min); }

}  // namespace acyclic
