#pragma once
// The friction model every part of Acyclic uses (the validity contract): a
// pyramid INSCRIBED in the Coulomb cone ||f_t|| <= mu f_n, with
// kFrictionPyramidEdges edges on the cone at the angles 2 pi m / edges of the
// surface frame's x axis. Every force inside it is inside the true cone.
//
// Its conservatism: a facet lies cos(pi / edges) of the way out to the cone
// (0.924 for 8), so in the worst tangential direction the usable friction
// coefficient is 0.924 mu; it keeps 90% of the cone's cross-section.
//
// The posture generator spans it by its edges (a force is a non-negative sum
// of generators); the independent check bounds it by its facets; both reach
// the same set, from two descriptions.
#include <cmath>

#include <Eigen/Core>

namespace acyclic {

constexpr int kFrictionPyramidEdges = 8;

// The ratio ||f_t|| / (mu f_n) of a force at a contact of normal n and
// friction mu: at most 1 inside the Coulomb cone; infinite for a force that
// pulls (f_n <= 0) with a tangential part. A force no larger than
// `negligible` (N) counts as none (0): an LP's zero is a few 1e-12 N in any
// direction.
inline double coneRatio(const Eigen::Vector3d& f, const Eigen::Vector3d& n, double mu, double negligible = 0) {
  if (f.norm() <= negligible) return 0.0;
  const double fn = f.dot(n);
  const double ft = (f - fn * n).norm();
  if (fn <= 0) return ft > 0 || fn < 0 ? INFINITY : 0.0;
  return ft / (mu * fn);
}

}  // namespace acyclic
