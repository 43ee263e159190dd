#include "planner/collision/convex_distance.h"

#include <cmath>

namespace acyclic::convex {

Eigen::Vector3d Primitive::support(const Eigen::Vector3d& d) const {
  switch (core) {
    case Core::Point: return Eigen::Vector3d::Zero();
    case Core::Segment: return Eigen::Vector3d(0, 0, d.z() >= 0 ? half.z() : -half.z());
    case Core::Box:
      return Eigen::Vector3d(d.x() >= 0 ? half.x() : -half.x(), d.y() >= 0 ? half.y() : -half.y(),
                             d.z() >= 0 ? half.z() : -half.z());
    case Core::Cylinder: {
      const double rho = std::hypot(d.x(), d.y());
      const double z = d.z() >= 0 ? half.z() : -half.z();
      // Along the axis every point of the cap supports: its centre.
      if (rho <= 1e-300) return Eigen::Vector3d(0, 0, z);
      return Eigen::Vector3d(d.x() * half.x() / rho, d.y() * half.x() / rho, z);
    }
  }
  return Eigen::Vector3d::Zero();
}

Primitive primitiveOf(const CollisionShape& s) {
  Primitive p;
  switch (s.kind) {
    case CollisionShape::Kind::Box:
      p.core = Primitive::Core::Box;
      p.half = s.size / 2;
      break;
    case CollisionShape::Kind::Capsule:
      p.core = Primitive::Core::Segment;
      p.half = Eigen::Vector3d(0, 0, s.length / 2);
      p.sweep = s.radius;
      break;
    case CollisionShape::Kind::Sphere:
      p.core = Primitive::Core::Point;
      p.sweep = s.radius;
      break;
    case CollisionShape::Kind::Cylinder:
      p.core = Primitive::Core::Cylinder;
      p.half = Eigen::Vector3d(s.radius, s.radius, s.length / 2);
      break;
  }
  return p;
}

namespace {

// A vertex of the simplex in the Minkowski difference A - B: w = a - b, with
// the points of A and B it comes from (all in A's frame).
struct Vertex {
  Eigen::Vector3d w, a, b;
};

// The simplex, its vertices' barycentric weights of the point nearest the
// origin, and that point.
struct Simplex {
  Vertex v[4];
  double lambda[4];
  int n = 0;
  // Keeps the vertices whose indices are given, with their weights.
  void keep(std::initializer_list<std::pair<int, double>> kept) {
    Vertex nv[4];
    double nl[4];
    int k = 0;
    for (const auto& [i, l] : kept) nv[k] = v[i], nl[k++] = l;
    for (int i = 0; i < k; ++i) v[i] = nv[i], lambda[i] = nl[i];
    n = k;
  }
  Eigen::Vector3d point() const {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) p += lambda[i] * v[i].w;
    return p;
  }
};

// The point of segment (i, j) nearest the origin, as kept vertices.
void nearestOnSegment(Simplex& s, int i, int j) {
  const Eigen::Vector3d& a = s.v[i].w;
  const Eigen::Vector3d ab = s.v[j].w - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? -a.dot(ab) / len2 : 0.0;
  if (t <= 0) s.keep({{i, 1.0}});
  else if (t >= 1) s.keep({{j, 1.0}});
  else s.keep({{i, 1 - t}, {j, t}});
}

// The point of triangle (i, j, k) nearest the origin (Ericson, Real-Time
// Collision Detection 5.1.5, with p the origin), as kept vertices.
void nearestOnTriangle(Simplex& s, int i, int j, int k) {
  const Eigen::Vector3d &a = s.v[i].w, &b = s.v[j].w, &c = s.v[k].w;
  const Eigen::Vector3d ab = b - a, ac = c - a;
  const double d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0 && d2 <= 0) return s.keep({{i, 1.0}});
  const double d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0 && d4 <= d3) return s.keep({{j, 1.0}});
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return s.keep({{i, 1 - t}, {j, t}});
  }
  const double d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0 && d5 <= d6) return s.keep({{k, 1.0}});
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return s.keep({{i, 1 - t}, {k, t}});
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return s.keep({{j, 1 - t}, {k, t}});
  }
  const double sum = va + vb + vc;  // |ab x ac|^2
  if (!(sum > 0)) {                 // degenerate (collinear): the better of two edges
    Simplex e1 = s, e2 = s;
    nearestOnSegment(e1, i, j);
    nearestOnSegment(e2, j, k);
    s = e1.point().squaredNorm() <= e2.point().squaredNorm() ? e1 : e2;
    return;
  }
  const double v = vb / sum, w = vc / sum;
  s.keep({{i, 1 - v - w}, {j, v}, {k, w}});
}

// The point of the tetrahedron nearest the origin; false when the origin is
// inside it.
bool nearestOnTetrahedron(Simplex& s) {
  // Faces with the vertex opposite each.
  static constexpr int faces[4][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
  bool outside_any = false;
  Simplex best;
  double best_d2 = INFINITY;
  for (const auto& f : faces) {
    const Eigen::Vector3d& a = s.v[f[0]].w;
    const Eigen::Vector3d n = (s.v[f[1]].w - a).cross(s.v[f[2]].w - a);
    const double side_origin = -n.dot(a), side_opposite = n.dot(s.v[f[3]].w - a);
    // The origin is beyond this face (or the tetrahedron is flat: every face counts).
    if (side_origin * side_opposite < 0 || side_opposite == 0) {
      outside_any = true;
      Simplex t = s;
      nearestOnTriangle(t, f[0], f[1], f[2]);
      const double d2 = t.point().squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = t;
    }
  }
  if (!outside_any) return false;
  s = best;
  return true;
}

}  // namespace

Separation separation(const Primitive& a, const Eigen::Isometry3d& Ta, const Primitive& b, const Eigen::Isometry3d& Tb,
                      double tolerance) {
  // Everything in A's frame: B's pose relative to it.
  const Eigen::Matrix3d R = Ta.linear().transpose() * Tb.linear();
  const Eigen::Vector3d t = Ta.linear().transpose() * (Tb.translation() - Ta.translation());
  auto support = [&](const Eigen::Vector3d& d) {
    Vertex x;
    x.a = a.support(d);
    x.b = R * b.support(-(R.transpose() * d)) + t;
    x.w = x.a - x.b;
    return x;
  };

  Separation out;
  Simplex s;
  // A point of A - B to start from: the cores' centres.
  Eigen::Vector3d v = -t;
  if (v.squaredNorm() == 0) v = Eigen::Vector3d::UnitX();
  constexpr int kMaxIterations = 128;
  double vv = v.squaredNorm();
  for (out.iterations = 0; out.iterations < kMaxIterations; ++out.iterations) {
    const Vertex x = support(-v);
    // |v| - v.w / |v| bounds the error of |v| as the cores' distance.
    if (s.n > 0 && vv - v.dot(x.w) <= tolerance * std::sqrt(vv)) break;
    bool repeated = false;
    for (int i = 0; i < s.n; ++i) repeated = repeated || (x.w - s.v[i].w).squaredNorm() <= 1e-30;
    if (repeated) break;
    s.v[s.n++] = x;
    switch (s.n) {
      case 1: s.lambda[0] = 1; break;
      case 2: nearestOnSegment(s, 0, 1); break;
      case 3: nearestOnTriangle(s, 0, 1, 2); break;
      case 4:
        if (!nearestOnTetrahedron(s)) {
          out.cores_overlap = true;
          return out;
        }
        break;
    }
    const Eigen::Vector3d nv = s.point();
    const double nvv = nv.squaredNorm();
    if (nvv <= 1e-24) {  // the cores touch or overlap: no normal to tell
      out.cores_overlap = true;
      return out;
    }
    const bool progress = nvv < vv;
    v = nv;
    vv = nvv;
    if (!progress && out.iterations > 0) break;  // rounding: the simplex no longer improves
  }
  Eigen::Vector3d pa = Eigen::Vector3d::Zero(), pb = Eigen::Vector3d::Zero();
  for (int i = 0; i < s.n; ++i) pa += s.lambda[i] * s.v[i].a, pb += s.lambda[i] * s.v[i].b;
  const double core = std::sqrt(vv);
  const Eigen::Vector3d n = (pb - pa) / core;  // from A toward B
  pa += a.sweep * n;
  pb -= b.sweep * n;
  out.distance = core - a.sweep - b.sweep;
  out.point_a = Ta * pa;
  out.point_b = Ta * pb;
  out.normal = Ta.linear() * n;
  return out;
}

}  // namespace acyclic::convex
