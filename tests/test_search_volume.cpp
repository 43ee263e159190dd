// Search volumes: C \ V split into at most 6 convex parts that are disjoint
// and whose union is C \ V.
#include <gtest/gtest.h>

#include <random>

#include "planner/search/search_volume.h"

using namespace acyclic;

namespace {

// Monte-Carlo check of one split: every sample of C \ V lies in exactly one
// part, no sample of V or outside C lies in any; the measures add up.
void checkSplit(const SearchVolume& C, const SurfacePlacement& c, const BoxHalfSizes& box, unsigned seed) {
  const std::vector<SearchVolume> parts = subtractBox(C, c, box);
  ASSERT_LE(parts.size(), 6u);
  for (const auto& p : parts) {
    EXPECT_LE(p.theta_min, p.theta_max);
    EXPECT_GT(p.polygon.area(), 0);  // convex: ConvexPolygon refuses anything else
  }
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const auto& v : C.polygon.vertices()) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto inV = [&](double x, double y, double t) {
    const double dt = std::remainder(t - c.theta, 2 * M_PI);
    return std::abs(x - c.x) <= box.x && std::abs(y - c.y) <= box.y && std::abs(dt) <= box.theta;
  };
  auto nearBoundary = [&](double x, double y, double t) {  // samples too close to a face are not judged
    const double m = 1e-6;
    if (std::abs(C.polygon.signedDistance({x, y})) < m) return true;
    for (const auto& p : parts) {
      if (std::abs(p.polygon.signedDistance({x, y})) < m) return true;
      for (double e : {p.theta_min, p.theta_max})
        if (std::abs(std::remainder(t - e, 2 * M_PI)) < m) return true;
    }
    return std::abs(std::abs(x - c.x) - box.x) < m || std::abs(std::abs(y - c.y) - box.y) < m ||
           std::abs(std::abs(std::remainder(t - c.theta, 2 * M_PI)) - box.theta) < m;
  };
  int judged = 0;
  for (int i = 0; i < 20000; ++i) {
    const double x = lo.x() + (hi.x() - lo.x()) * u(rng), y = lo.y() + (hi.y() - lo.y()) * u(rng);
    const double t = -M_PI + 2 * M_PI * u(rng);
    if (nearBoundary(x, y, t)) continue;
    int in = 0;
    for (const auto& p : parts) in += contains(p, x, y, t);
    const bool expected = contains(C, x, y, t) && !inV(x, y, t);
    EXPECT_EQ(in, expected ? 1 : 0) << "sample (" << x << ", " << y << ", " << t << ")";
    ++judged;
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(judged, 19000);
  // Measures: |C \ V| = |C| - |C and V|.
  double sum = 0;
  for (const auto& p : parts) sum += measure(p);
  const std::vector<Eigen::Vector2d> rect = {{c.x - box.x, c.y - box.y}, {c.x + box.x, c.y - box.y},
                                             {c.x + box.x, c.y + box.y}, {c.x - box.x, c.y + box.y}};
  std::vector<Eigen::Vector2d> inter = C.polygon.vertices();
  inter = clip(inter, {1, 0}, c.x + box.x);
  inter = clip(inter, {-1, 0}, -(c.x - box.x));
  inter = clip(inter, {0, 1}, c.y + box.y);
  inter = clip(inter, {0, -1}, -(c.y - box.y));
  double inter_area = 0;
  for (std::size_t k = 0; k < inter.size(); ++k)
    inter_area += 0.5 * (inter[k].x() * inter[(k + 1) % inter.size()].y() - inter[(k + 1) % inter.size()].x() * inter[k].y());
  double theta_overlap = 2 * box.theta;
  if (!isFullCircle(C)) {
    const double t = C.theta_min + std::fmod(std::fmod(c.theta - C.theta_min, 2 * M_PI) + 2 * M_PI, 2 * M_PI);
    theta_overlap = std::min(C.theta_max, t + box.theta) - std::max(C.theta_min, t - box.theta);
  }
  EXPECT_NEAR(sum, measure(C) - inter_area * theta_overlap, 1e-9);
}

}  // namespace

TEST(SearchVolume, FullTableMinusABoxInTheMiddle) {
  const SearchVolume C = fullVolume(ConvexPolygon({{-0.4, -0.6}, {0.4, -0.6}, {0.4, 0.6}, {-0.4, 0.6}}));
  const auto parts = subtractBox(C, {0.1, -0.2, 0.5}, {});
  EXPECT_EQ(parts.size(), 5u);  // a full circle: one theta arc left, four pieces around the box
  checkSplit(C, {0.1, -0.2, 0.5}, {}, 1);
}

TEST(SearchVolume, RepeatedSplitsStayDisjointAndCoverTheRest) {
  // Candidates at random inside random parts, as the planner generates them,
  // including boxes that reach the polygon's edges and angles near +-pi.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<SearchVolume> volumes = {fullVolume(ConvexPolygon({{0, 0}, {0.5, -0.1}, {0.7, 0.3}, {0.2, 0.5}}))};
  for (int round = 0; round < 12 && !volumes.empty(); ++round) {
    const SearchVolume C = volumes[rng() % volumes.size()];
    // a point of C: polygon centroid nudged, theta anywhere in its interval
    const Eigen::Vector2d c = C.polygon.centroid();
    const Eigen::Vector2d v = C.polygon.vertices()[rng() % C.polygon.size()];
    const Eigen::Vector2d p = c + 0.8 * u(rng) * (v - c);
    const double t = C.theta_min + (C.theta_max - C.theta_min) * u(rng);
    const SurfacePlacement center{p.x(), p.y(), t};
    checkSplit(C, center, {}, 100 + round);
    if (::testing::Test::HasFailure()) return;
    const auto parts = subtractBox(C, center, {});
    volumes.insert(volumes.end(), parts.begin(), parts.end());
  }
}

TEST(SearchVolume, AngleIntervalsNeverWrapOntoThemselves) {
  // After the first split no interval is longer than 2 pi - 2 * half-width, so
  // a box around any angle inside it cannot reach its other end.
  const BoxHalfSizes box;
  const SearchVolume C = fullVolume(ConvexPolygon({{0, 0}, {1, 0}, {1, 1}, {0, 1}}));
  const auto parts = subtractBox(C, {0.5, 0.5, 3.0}, box);
  for (const auto& p : parts) EXPECT_LE(p.theta_max - p.theta_min, 2 * M_PI - 2 * box.theta + 1e-12);
  const SearchVolume& arc = parts.front();  // the whole square over the remaining arc
  checkSplit(arc, {0.5, 0.5, arc.theta_min + 0.01}, box, 3);
  checkSplit(arc, {0.5, 0.5, arc.theta_max - 0.01}, box, 4);
}
