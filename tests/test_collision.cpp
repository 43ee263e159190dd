// Collision distances: FCL and the posture generator's GJK (convex_distance.h)
// against a brute-force reference on primitives and against each other,
// gradients against finite differences with either, and the chair
// scenario's start.
#include <gtest/gtest.h>

#include <random>

#include "planner/collision/collision_model.h"
#include "planner/collision/convex_distance.h"
#include "planner/common/geometry.h"
#include "planner/scene/scenario.h"
#include "test_support.h"

using namespace acyclic;
using Kind = CollisionShape::Kind;

namespace {

// Exact unsigned distance from a world point to a solid primitive (0 inside).
double pointDistance(const CollisionShape& s, const Eigen::Isometry3d& T, const Eigen::Vector3d& pw) {
  const Eigen::Vector3d p = T.inverse() * pw;
  switch (s.kind) {
    case Kind::Box: {
      const Eigen::Vector3d q = p.cwiseAbs() - s.size / 2;
      return q.cwiseMax(0.0).norm();
    }
    case Kind::Sphere: return std::max(0.0, p.norm() - s.radius);
    case Kind::Capsule: {
      const double z = std::clamp(p.z(), -s.length / 2, s.length / 2);
      return std::max(0.0, (p - Eigen::Vector3d(0, 0, z)).norm() - s.radius);
    }
    case Kind::Cylinder: {
      const double radial = std::hypot(p.x(), p.y()) - s.radius;
      const double axial = std::abs(p.z()) - s.length / 2;
      return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
    }
  }
  return 0;
}

// Points covering the surface of a primitive, in world coordinates.
std::vector<Eigen::Vector3d> surfaceSamples(const CollisionShape& s, const Eigen::Isometry3d& T, int n) {
  std::vector<Eigen::Vector3d> out;
  auto lin = [n](int i, double lo, double hi) { return lo + (hi - lo) * i / (n - 1); };
  switch (s.kind) {
    case Kind::Box: {
      const Eigen::Vector3d h = s.size / 2;
      for (int axis = 0; axis < 3; ++axis)
        for (double side : {-1.0, 1.0})
          for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
              Eigen::Vector3d p;
              const int a = (axis + 1) % 3, b = (axis + 2) % 3;
              p[axis] = side * h[axis];
              p[a] = lin(i, -h[a], h[a]);
              p[b] = lin(j, -h[b], h[b]);
              out.push_back(T * p);
            }
      break;
    }
    case Kind::Sphere:
    case Kind::Capsule: {
      const double half = s.kind == Kind::Capsule ? s.length / 2 : 0;
      for (int i = 0; i < 2 * n; ++i)
        for (int j = 0; j < 2 * n; ++j) {
          const double phi = lin(i, 0, 2 * M_PI), th = lin(j, 0, M_PI);
          Eigen::Vector3d d(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
          out.push_back(T * (s.radius * d + Eigen::Vector3d(0, 0, d.z() >= 0 ? half : -half)));
        }
      if (s.kind == Kind::Capsule)
        for (int i = 0; i < 2 * n; ++i)
          for (int j = 0; j < n; ++j) {
            const double phi = lin(i, 0, 2 * M_PI);
            out.push_back(T * Eigen::Vector3d(s.radius * std::cos(phi), s.radius * std::sin(phi), lin(j, -half, half)));
          }
      break;
    }
    case Kind::Cylinder:
      for (int i = 0; i < 2 * n; ++i) {
        const double phi = lin(i, 0, 2 * M_PI);
        for (int j = 0; j < n; ++j) {
          out.push_back(T * Eigen::Vector3d(s.radius * std::cos(phi), s.radius * std::sin(phi),
                                            lin(j, -s.length / 2, s.length / 2)));
          const double r = lin(j, 0, s.radius);
          for (double z : {-s.length / 2, s.length / 2})
            out.push_back(T * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z));
        }
      }
      break;
  }
  return out;
}

CollisionShape randomShape(std::mt19937& rng, Kind kind) {
  std::uniform_real_distribution<double> u(0.03, 0.25);
  CollisionShape s;
  s.kind = kind;
  s.size = Eigen::Vector3d(u(rng), u(rng), u(rng));
  s.radius = 0.5 * u(rng);
  s.length = u(rng);
  return s;
}

Eigen::Isometry3d randomPose(std::mt19937& rng, double spread) {
  std::uniform_real_distribution<double> s(-1, 1);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSO3(Eigen::Vector3d(s(rng), s(rng), s(rng)) * 2.0);
  T.translation() = Eigen::Vector3d(s(rng), s(rng), s(rng)) * spread;
  return T;
}

}  // namespace

TEST(ShapeDistance, MatchesBruteForceOnSeparatedPrimitives) {
  std::mt19937 rng(21);
  const Kind kinds[] = {Kind::Box, Kind::Capsule, Kind::Cylinder, Kind::Sphere};
  int compared = 0;
  for (Kind ka : kinds)
    for (Kind kb : kinds)
      for (int trial = 0; trial < 6; ++trial) {
        const CollisionShape a = randomShape(rng, ka), b = randomShape(rng, kb);
        const Eigen::Isometry3d Ta = randomPose(rng, 0.3), Tb = randomPose(rng, 0.3);
        Eigen::Vector3d pa, pb;
        const double d = shapeDistance(a, Ta, b, Tb, &pa, &pb);
        if (d < 0.01) continue;  // separated cases only: the brute force is unsigned
        // Brute force: the closest of many points on a's surface to the solid b.
        double brute = std::numeric_limits<double>::infinity();
        for (const auto& p : surfaceSamples(a, Ta, 60)) brute = std::min(brute, pointDistance(b, Tb, p));
        EXPECT_LE(d, brute + 1e-6) << "FCL reports more than a sampled pair of points";
        EXPECT_NEAR(d, brute, 2e-3) << int(ka) << " vs " << int(kb);
        // Witness points lie on the shapes and are d apart.
        EXPECT_NEAR((pb - pa).norm(), d, 1e-6);
        EXPECT_LT(pointDistance(a, Ta, pa), 1e-6);
        EXPECT_LT(pointDistance(b, Tb, pb), 1e-6);
        EXPECT_NEAR(pointDistance(b, Tb, pa), d, 1e-5);
        ++compared;
      }
  EXPECT_GT(compared, 40);
}

namespace {
// A capsule (radius 5 cm) lying flat on a slab 10 cm thick whose top is at
// z = 0.05, its axis along x, `depth` into the slab's top.
struct CapsuleOnSlab {
  CollisionShape box, cap;
  Eigen::Isometry3d Tb = Eigen::Isometry3d::Identity(), Tc = Eigen::Isometry3d::Identity();
  explicit CapsuleOnSlab(double depth) {
    box.kind = Kind::Box;
    box.size = Eigen::Vector3d(1, 1, 0.1);
    cap.kind = Kind::Capsule;
    cap.radius = 0.05;
    cap.length = 0.3;
    Tc.linear() = expSO3(Eigen::Vector3d(0, M_PI / 2, 0));
    Tc.translation() = Eigen::Vector3d(0.1, 0, 0.05 + 0.05 - depth);
  }
};
}  // namespace

TEST(ShapeDistance, PenetrationIsNegativeWithItsDepth) {
  CapsuleOnSlab c(0.004);  // 4 mm into the box's top
  const CollisionShape &box = c.box, &cap = c.cap;
  const Eigen::Isometry3d& Tb = c.Tb;
  Eigen::Isometry3d& Tc = c.Tc;
  EXPECT_NEAR(shapeDistance(cap, Tc, box, Tb), -0.004, 1e-5);
  Tc.translation().z() += 0.01;
  EXPECT_NEAR(shapeDistance(cap, Tc, box, Tb), 0.006, 1e-6);
}

TEST(ShapeDistance, PenetrationNormalPointsOut) {
  // In penetration the depth is MPR's estimate (fcl::collide), not the exact
  // minimal depth, so n = (pb - pa) / d is not its exact gradient; what the
  // optimizer needs is checked instead: moving b along n separates the shapes
  // and moving it against n deepens the penetration, at the rate of about 1.
  std::mt19937 rng(5);
  int compared = 0;
  for (int trial = 0; trial < 400 && compared < 40; ++trial) {
    const CollisionShape a = randomShape(rng, trial % 2 ? Kind::Capsule : Kind::Box);
    const CollisionShape b = randomShape(rng, trial % 3 ? Kind::Box : Kind::Cylinder);
    const Eigen::Isometry3d Ta = randomPose(rng, 0.1), Tb = randomPose(rng, 0.1);
    Eigen::Vector3d pa, pb;
    const double d = shapeDistance(a, Ta, b, Tb, &pa, &pb);
    if (d > -0.001 || d < -0.02) continue;  // shallow penetrations, as an optimizer meets them
    const Eigen::Vector3d n = (pb - pa) / d;
    EXPECT_NEAR(n.norm(), 1.0, 1e-9);
    const double h = 1e-4;
    Eigen::Isometry3d Tp = Tb, Tm = Tb;
    Tp.translation() += h * n;
    Tm.translation() -= h * n;
    const double rate = (shapeDistance(a, Ta, b, Tp) - shapeDistance(a, Ta, b, Tm)) / (2 * h);
    EXPECT_GT(rate, 0.5) << "trial " << trial << " d " << d;
    EXPECT_LT(rate, 1.5) << "trial " << trial << " d " << d;
    ++compared;
  }
  EXPECT_GE(compared, 20);
}

class ChairCollision : public ::testing::Test {
 protected:
  Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  CollisionModel cm{sc.robot, sc.scene};
};

// The same tests with the posture generator's engine.
class ChairCollisionConvex : public ChairCollision {
 protected:
  ChairCollisionConvex() : ChairCollision() { cm_convex = std::make_unique<CollisionModel>(sc.robot, sc.scene, DistanceEngine::Convex); }
  std::unique_ptr<CollisionModel> cm_convex;
};

TEST_F(ChairCollision, StartIsCollisionFreeExceptContactingPairs) {
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  std::set<std::pair<int, int>> contacting;
  for (const auto& c : sc.start_stance)
    contacting.insert({sc.robot->spots()[c.spot].link, sc.scene->surfaces()[c.surface].obstacle});
  const auto ds = cm.distances(k);
  EXPECT_EQ(ds.size(), cm.pairs().size());
  int touching = 0;
  for (const auto& d : ds) {
    const auto& p = cm.pairs()[d.pair];
    const bool is_contact = p.kind == CollisionPair::Kind::RobotEnvironment && contacting.count({p.link_a, p.obstacle});
    if (is_contact) {
      EXPECT_NEAR(d.distance, 0.0, 1e-3) << cm.describe(d.pair);  // touching, not floating
      ++touching;
    } else {
      EXPECT_GT(d.distance, 0.0) << cm.describe(d.pair);
    }
  }
  EXPECT_EQ(touching, 4);
}

namespace {
// Each pair's gradient (near the chair's start, the base lifted and tilted,
// the joints perturbed) against central differences of its distance.
void expectGradientsMatchFiniteDifferences(const Scenario& sc, const CollisionModel& cm) {
  Kinematics k(sc.robot), probe(sc.robot);
  std::mt19937 rng(17);
  std::normal_distribution<double> n(0, 0.05);
  int compared = 0;
  for (int trial = 0; trial < 3; ++trial) {
    Configuration q = sc.start;
    q.base_position.z() += 0.03;  // lift off the seat so contacting pairs are separated too
    // Tilt the base: with faces exactly parallel (box on box) the distance has
    // a kink and no gradient; a generic posture has none.
    q.base_orientation = Eigen::Quaterniond(expSO3(Eigen::Vector3d(n(rng), n(rng), n(rng))));
    for (int j = 0; j < q.joints.size(); ++j) q.joints[j] += n(rng);
    k.setConfiguration(q);
    DistanceOptions opt;
    opt.gradients = true;
    opt.cutoff = 0.25;  // the pairs an optimizer would constrain
    const auto ds = cm.distances(k, opt);
    for (const auto& d : ds) {
      if (d.distance < 0.002) continue;
      const int tn = q.tangentSize();
      Eigen::VectorXd num(tn);
      const double h = 1e-5;
      for (int i = 0; i < tn; ++i) {
        Eigen::VectorXd dq = Eigen::VectorXd::Zero(tn);
        dq[i] = h;
        DistanceOptions all;  // no cutoff: the pair must be evaluated
        probe.setConfiguration(integrate(q, dq));
        const double plus = cm.distances(probe, all)[d.pair].distance;
        probe.setConfiguration(integrate(q, -dq));
        const double minus = cm.distances(probe, all)[d.pair].distance;
        num[i] = (plus - minus) / (2 * h);
      }
      EXPECT_LT(test::relativeError(d.gradient, num, 1e-2), 1e-3) << cm.describe(d.pair) << " d=" << d.distance;
      if (++compared >= 40) return;
    }
  }
  EXPECT_GE(compared, 20);
}
}  // namespace

TEST_F(ChairCollision, GradientsMatchFiniteDifferences) { expectGradientsMatchFiniteDifferences(sc, cm); }

TEST_F(ChairCollisionConvex, GradientsMatchFiniteDifferences) { expectGradientsMatchFiniteDifferences(sc, *cm_convex); }

TEST_F(ChairCollisionConvex, EnginesAgreeOnEveryPairNearTheChair) {
  // Postures around the start, some penetrating the seat or the table: every
  // one of the 316 pairs by both engines. Separated pairs agree to FCL's own
  // accuracy (its GJK on curved shapes stops within a few micrometres);
  // penetrating ones are penetrating by both (the depth is FCL's estimate,
  // by MPR, where the cores overlap, and exact by the Convex engine where
  // only a capsule's or a sphere's sweep penetrates).
  Kinematics k(sc.robot);
  std::mt19937 rng(29);
  std::normal_distribution<double> n(0, 0.15);
  int separated = 0, penetrating = 0;
  for (int trial = 0; trial < 12; ++trial) {
    Configuration q = sc.start;
    q.base_position += Eigen::Vector3d(0.1 * n(rng), 0.1 * n(rng), 0.1 * n(rng));
    q.base_orientation = Eigen::Quaterniond(expSO3(Eigen::Vector3d(n(rng), n(rng), n(rng)) * 0.3));
    for (int j = 0; j < q.joints.size(); ++j) q.joints[j] += n(rng);
    k.setConfiguration(q);
    const auto a = cm.distances(k), b = cm_convex->distances(k);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].pair, b[i].pair);
      if (a[i].distance > 1e-4) {
        EXPECT_NEAR(a[i].distance, b[i].distance, 1e-5) << cm.describe(a[i].pair);
        ++separated;
      } else if (a[i].distance < -1e-4) {
        EXPECT_LT(b[i].distance, 0) << cm.describe(a[i].pair);
        ++penetrating;
      }
    }
  }
  EXPECT_GT(separated, 2000);
  EXPECT_GT(penetrating, 10);
}

TEST_F(ChairCollision, CutoffKeepsEveryCloserPair) {
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  const auto all = cm.distances(k);
  DistanceOptions opt;
  opt.cutoff = 0.1;
  const auto near = cm.distances(k, opt);
  EXPECT_LT(near.size(), all.size());
  std::set<int> kept;
  for (const auto& d : near) kept.insert(d.pair);
  for (const auto& d : all)
    if (d.distance <= 0.1) {
      EXPECT_TRUE(kept.count(d.pair)) << cm.describe(d.pair);
    }
}

TEST(ConvexSeparation, MatchesBruteForceAndFclOnSeparatedPrimitives) {
  std::mt19937 rng(23);
  const Kind kinds[] = {Kind::Box, Kind::Capsule, Kind::Cylinder, Kind::Sphere};
  int compared = 0;
  for (Kind ka : kinds)
    for (Kind kb : kinds)
      for (int trial = 0; trial < 12; ++trial) {
        const CollisionShape a = randomShape(rng, ka), b = randomShape(rng, kb);
        const Eigen::Isometry3d Ta = randomPose(rng, 0.3), Tb = randomPose(rng, 0.3);
        const convex::Separation s = convex::separation(convex::primitiveOf(a), Ta, convex::primitiveOf(b), Tb);
        const double fcl = shapeDistance(a, Ta, b, Tb);
        if (fcl < 0.01) continue;  // separated cases only: the brute force is unsigned
        ASSERT_FALSE(s.cores_overlap) << int(ka) << " vs " << int(kb) << " trial " << trial;
        const double d = s.distance;
        EXPECT_NEAR(d, fcl, 1e-5) << int(ka) << " vs " << int(kb);
        double brute = std::numeric_limits<double>::infinity();
        for (const auto& p : surfaceSamples(a, Ta, 60)) brute = std::min(brute, pointDistance(b, Tb, p));
        EXPECT_LE(d, brute + 1e-9);
        EXPECT_NEAR(d, brute, 2e-3);
        // The witness points certify d: each lies on its shape, they are d
        // apart, and a's lies at d from the whole solid b (exact reference).
        EXPECT_NEAR((s.point_b - s.point_a).norm(), d, 1e-9);
        EXPECT_LT(pointDistance(a, Ta, s.point_a), 1e-7);
        EXPECT_LT(pointDistance(b, Tb, s.point_b), 1e-7);
        // Exact where neither shape is a cylinder (GJK ends on the exact
        // simplex of polytope cores); within its tolerance on a cylinder's rim.
        const bool curved = ka == Kind::Cylinder || kb == Kind::Cylinder;
        EXPECT_NEAR(pointDistance(b, Tb, s.point_a), d, curved ? 1e-6 : 1e-9) << int(ka) << " vs " << int(kb);
        ++compared;
      }
  EXPECT_GT(compared, 90);
}

TEST(ConvexSeparation, ASweepsPenetrationIsExactAndOverlappingCoresAreSaid) {
  CapsuleOnSlab c(0.004);  // 4 mm into the box's top
  const CollisionShape& box = c.box;
  const convex::Primitive pbox = convex::primitiveOf(c.box), pcap = convex::primitiveOf(c.cap);
  const Eigen::Isometry3d& Tb = c.Tb;
  Eigen::Isometry3d& Tc = c.Tc;
  convex::Separation s = convex::separation(pcap, Tc, pbox, Tb);
  ASSERT_FALSE(s.cores_overlap);
  EXPECT_NEAR(s.distance, -0.004, 1e-12);
  // n = (pb - pa) / d points from the capsule toward the box, as when separated.
  EXPECT_NEAR(((s.point_b - s.point_a) / s.distance - Eigen::Vector3d(0, 0, -1)).norm(), 0, 1e-9);
  EXPECT_NEAR(s.point_b.z(), 0.05, 1e-12);  // on the box's top
  // The segment itself inside the box: no normal from GJK.
  Tc.translation().z() = 0.0;
  s = convex::separation(pcap, Tc, pbox, Tb);
  EXPECT_TRUE(s.cores_overlap);
  // A box inside a box.
  CollisionShape small = box;
  small.size = Eigen::Vector3d(0.1, 0.1, 0.1);
  EXPECT_TRUE(convex::separation(convex::primitiveOf(small), Eigen::Isometry3d::Identity(), pbox, Tb).cores_overlap);
}

TEST(ConvexSeparation, ASweepsPenetrationMovesAlongItsNormalAndParallelFacesAreExact) {
  // A capsule or a sphere whose sweep (not its core) is inside the other
  // shape: the distance, negative, changes along the normal at rate 1 when
  // the other shape moves (what the posture generator's gradients use).
  std::mt19937 rng(41);
  int compared = 0;
  for (int trial = 0; trial < 2000 && compared < 40; ++trial) {
    const CollisionShape a = randomShape(rng, trial % 2 ? Kind::Capsule : Kind::Sphere);
    const CollisionShape b = randomShape(rng, trial % 3 ? Kind::Box : Kind::Capsule);
    const convex::Primitive pa = convex::primitiveOf(a), pb = convex::primitiveOf(b);
    const Eigen::Isometry3d Ta = randomPose(rng, 0.15), Tb = randomPose(rng, 0.15);
    const convex::Separation s = convex::separation(pa, Ta, pb, Tb);
    if (s.cores_overlap || s.distance > -1e-3 || s.distance < -0.02) continue;
    EXPECT_NEAR((s.point_b - s.point_a - s.distance * s.normal).norm(), 0, 1e-12);
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Isometry3d Tp = Tb, Tm = Tb;
      Tp.translation()[k] += h;
      Tm.translation()[k] -= h;
      const double rate =
          (convex::separation(pa, Ta, pb, Tp).distance - convex::separation(pa, Ta, pb, Tm).distance) / (2 * h);
      EXPECT_NEAR(rate, s.normal[k], 1e-6) << "trial " << trial;
    }
    ++compared;
  }
  EXPECT_GE(compared, 20);
  // Faces and axes exactly parallel (a foot flat over the floor, two limbs
  // side by side): GJK's simplex turns flat or collinear there.
  CollisionShape slab, foot, cap;
  slab.kind = foot.kind = Kind::Box;
  slab.size = Eigen::Vector3d(1, 1, 0.1);
  foot.size = Eigen::Vector3d(0.22, 0.14, 0.09);
  cap.kind = Kind::Capsule;
  cap.radius = 0.05;
  cap.length = 0.16;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (double gap : {0.02, 1e-3, 1e-6}) {
    T.translation() = Eigen::Vector3d(0.1, -0.2, 0.05 + 0.045 + gap);
    const convex::Separation s =
        convex::separation(convex::primitiveOf(foot), T, convex::primitiveOf(slab), Eigen::Isometry3d::Identity());
    ASSERT_FALSE(s.cores_overlap) << gap;
    EXPECT_NEAR(s.distance, gap, 1e-12);
    EXPECT_NEAR((s.normal - Eigen::Vector3d(0, 0, -1)).norm(), 0, 1e-9);
  }
  // Two capsules side by side, their axes parallel, 1.4 cm between their sweeps.
  T.translation() = Eigen::Vector3d(0.11, 0.03, -0.02);
  const convex::Separation c =
      convex::separation(convex::primitiveOf(cap), T, convex::primitiveOf(cap), Eigen::Isometry3d::Identity());
  ASSERT_FALSE(c.cores_overlap);
  EXPECT_NEAR(c.distance, std::hypot(0.11, 0.03) - 0.1, 1e-12);
}
