// The guide potential f_T: smoothness across the junctions of its corner
// blends, its gradient against finite differences, the growth of s' along T.
#include <gtest/gtest.h>

#include <random>

#include "planner/common/geometry.h"
#include "planner/scene/scenario.h"
#include "planner/search/guide_potential.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& chair() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

Eigen::MatrixXd numericHessian(const GuidePotential& f, const Eigen::VectorXd& P, double h = 1e-5) {
  Eigen::MatrixXd H(P.size(), P.size());
  for (int i = 0; i < P.size(); ++i) {
    Eigen::VectorXd a = P, b = P;
    a[i] += h;
    b[i] -= h;
    H.col(i) = (f.gradient(a) - f.gradient(b)) / (2 * h);
  }
  return H;
}

// Points near T whose closest point is the junction at arc length s: the
// point of T there, moved off T by rho along a unit direction normal to T'.
Eigen::VectorXd nearJunction(const GuidePotential& f, double s, double rho, std::mt19937& rng) {
  const Eigen::VectorXd Q = f.pointAt(s);
  const Eigen::VectorXd t = (f.pointAt(s + 1e-4) - f.pointAt(s - 1e-4)).head(6).normalized();
  std::normal_distribution<double> n(0, 1);
  Eigen::VectorXd d(6);
  for (int i = 0; i < 6; ++i) d[i] = n(rng);
  d -= d.dot(t) * t;
  Eigen::VectorXd P = Q;
  P.head(6) += rho * d.normalized();
  for (int i = 6; i < P.size(); ++i) P[i] += 0.05 * n(rng);  // joints off T as well
  return P;
}

}  // namespace

TEST(GuidePotential, CornersAreBlendedAsLargeAsTheToleranceAllows) {
  // The chair guide turns gently: each blend takes half of its shorter segment.
  const GuidePotential chair_f(chair().key_postures, 1.0, 0.05);
  EXPECT_EQ(chair_f.junctions().size(), 4u);  // two interior corners, each with a blend
  EXPECT_LE(chair_f.maxDeviation(), 0.05 + 1e-9);
  // A sharp corner between long segments: the blend reaches the tolerance.
  Configuration a = chair().start, b = a, c = a;
  a.base_position = {0, 0, 0.6};
  b.base_position = {1, 0, 0.6};
  c.base_position = {1, 1, 0.6};
  for (double tol : {0.02, 0.05}) {
    const GuidePotential f({a, b, c}, 1.0, tol);
    EXPECT_NEAR(f.maxDeviation(), tol, 0.02 * tol);
    EXPECT_LT(f.length(), 2.0);  // shorter than the polyline it smooths
  }
}

TEST(GuidePotential, ValueGradientAndHessianAreContinuousAcrossJunctions) {
  const GuidePotential f(chair().key_postures, 1.0, 0.05);
  std::mt19937 rng(4);
  for (double s : f.junctions()) {
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::VectorXd P = nearJunction(f, s, 0.02, rng);
      // Step across the junction's normal plane along T's tangent there.
      const Eigen::VectorXd t = (f.pointAt(s + 1e-4) - f.pointAt(s - 1e-4)).head(6).normalized();
      for (double eps : {1e-4, 1e-5}) {
        Eigen::VectorXd before = P, after = P;
        before.head(6) -= eps * t;
        after.head(6) += eps * t;
        ASSERT_LT(f.project(before).s, f.project(after).s);
        EXPECT_LT(std::abs(f.value(after) - f.value(before)), 10 * eps) << "s = " << s;
        EXPECT_LT((f.gradient(after) - f.gradient(before)).norm(), 200 * eps) << "s = " << s;
      }
      // Hessians on each side, by differences of the analytic gradient.
      const double eps = 1e-3, h = 1e-6;
      Eigen::VectorXd before = P, after = P;
      before.head(6) -= eps * t;
      after.head(6) += eps * t;
      const Eigen::MatrixXd Hb = numericHessian(f, before, h), Ha = numericHessian(f, after, h);
      EXPECT_LT((Ha - Hb).norm(), 0.5) << "s = " << s << " |H| = " << Ha.norm();
      // and the jump shrinks with the distance to the junction: continuity, not a bounded jump
      Eigen::VectorXd b2 = P, a2 = P;
      b2.head(6) -= 0.1 * eps * t;
      a2.head(6) += 0.1 * eps * t;
      EXPECT_LT((numericHessian(f, a2, h) - numericHessian(f, b2, h)).norm(), 0.3 * (Ha - Hb).norm() + 1e-3);
    }
  }
}

TEST(GuidePotential, GradientMatchesFiniteDifferences) {
  // Joints weighted as the base (the paper) and lighter (guide_joint_weight).
  for (const double w : {1.0, 0.1}) {
  const GuidePotential f(chair().key_postures, 1.0, 0.05, w);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd P = nearJunction(f, u(rng) * f.length(), 0.05 * u(rng), rng);
    Eigen::VectorXd num(P.size());
    for (int i = 0; i < P.size(); ++i) {
      Eigen::VectorXd a = P, b = P;
      const double h = 1e-6;
      a[i] += h;
      b[i] -= h;
      num[i] = (f.value(a) - f.value(b)) / (2 * h);
    }
    EXPECT_LT(test::relativeError(f.gradient(P), num), 1e-6) << "trial " << trial << ", joint weight " << w;
  }
  }
}

TEST(GuidePotential, JointWeightScalesOnlyTheJointsDistance) {
  const auto& keys = chair().key_postures;
  const GuidePotential full(keys, 1.0, 0.05, 1.0), light(keys, 1.0, 0.05, 0.1);
  // On the guide, the potential is -k s' whatever the weight; off it in the
  // joints only, the distance term scales with the weight.
  Eigen::VectorXd P = full.pointAt(0.3);
  EXPECT_NEAR(full.value(P), light.value(P), 1e-12);
  const double on = full.value(P);
  P.tail(P.size() - 6).array() += 0.2;
  EXPECT_NEAR(light.value(P) - on, 0.1 * (full.value(P) - on), 1e-9);
  EXPECT_THROW(GuidePotential(keys, 1.0, 0.05, 0.0), std::invalid_argument);
}

TEST(GuidePotential, TangentGradientAsAPostureCost) {
  const Scenario& sc = chair();
  const GuidePotential f(sc.key_postures, 1.0, 0.05);
  Kinematics k(sc.robot);
  Configuration q = sc.key_postures[1];
  q.base_orientation = Eigen::Quaterniond(expSO3(Eigen::Vector3d(0.3, -0.2, 0.4)));
  k.setConfiguration(q);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(q.tangentSize());
  const double v = f.evaluate(k, g);
  EXPECT_DOUBLE_EQ(v, f.value(GuidePotential::coordinates(q)));
  Eigen::VectorXd num(q.tangentSize());
  for (int i = 0; i < q.tangentSize(); ++i) {
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(q.tangentSize());
    dq[i] = 1e-6;
    num[i] = (f.value(GuidePotential::coordinates(integrate(q, dq))) -
              f.value(GuidePotential::coordinates(integrate(q, -dq)))) / 2e-6;
  }
  EXPECT_LT(test::relativeError(g, num), 1e-6);
}

TEST(GuidePotential, ArcLengthGrowsAlongTheGuideAndThePotentialDescends) {
  const Scenario& sc = chair();
  const GuidePotential f(sc.key_postures, 1.0, 0.05);
  double last_s = -1, last_f = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= 200; ++i) {
    const double s = f.length() * i / 200;
    const Eigen::VectorXd Q = f.pointAt(s);
    const GuidePotential::Projection pr = f.project(Q);
    EXPECT_NEAR(pr.s, s, 1e-6);        // T projects onto itself
    EXPECT_GT(pr.s, last_s - 1e-12);   // s' grows along T
    EXPECT_LT(f.value(Q), last_f + 1e-9);  // and f_T descends along it
    last_s = pr.s;
    last_f = f.value(Q);
  }
  // Key postures in order project to increasing s'; the last at the end.
  double prev = -1;
  for (const auto& q : sc.key_postures) {
    const double s = f.project(GuidePotential::coordinates(q)).s;
    EXPECT_GT(s, prev);
    prev = s;
  }
  EXPECT_NEAR(prev, f.length(), 1e-9);
}

TEST(GuidePotential, RejectsGuidesThatAreNotOneToOne) {
  const Scenario& sc = chair();
  EXPECT_THROW(GuidePotential({sc.start}, 1.0, 0.05), std::invalid_argument);
  EXPECT_THROW(GuidePotential({sc.start, sc.start}, 1.0, 0.05), std::invalid_argument);
}

TEST(GuidePotential, ProjectsOnTheNearestPointOfTheWholeGuide) {
  // chair_paper's hand-written guide: many corners, so many blends, most of
  // them far from any one point and left unsearched by project (their
  // bounding balls are farther than the nearest segment). The projection
  // must still be the nearest point of all of T', sampled densely here.
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_paper.yaml"));
  const GuidePotential f(sc.key_postures, 1.0, 0.05);
  ASSERT_GE(f.junctions().size(), 8u);
  std::vector<Eigen::VectorXd> samples;
  for (int i = 0; i <= 20000; ++i) samples.push_back(f.pointAt(f.length() * i / 20000).head(6));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> along(0, f.length());
  std::normal_distribution<double> n(0, 1);
  int near_a_blend = 0;
  long searched = 0;
  const long blends = static_cast<long>(f.junctions().size() / 2);
  for (int trial = 0; trial < 300; ++trial) {
    Eigen::VectorXd P = f.pointAt(along(rng));
    for (int i = 0; i < 6; ++i) P[i] += 0.04 * n(rng);
    const GuidePotential::Projection pr = f.project(P);
    searched += pr.blends_searched;
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& c : samples) nearest = std::min(nearest, (c - P.head(6)).squaredNorm());
    const double d = (pr.Q.head(6) - P.head(6)).squaredNorm();
    EXPECT_LE(d, nearest + 1e-9) << "trial " << trial;
    const std::vector<double> j = f.junctions();
    for (std::size_t k = 0; k + 1 < j.size(); k += 2)
      if (pr.s > j[k] && pr.s < j[k + 1]) ++near_a_blend;
  }
  EXPECT_GT(near_a_blend, 30);  // the blends were searched where they are nearest
  // and most were left out elsewhere: fewer than a third searched on average
  EXPECT_LT(searched, 300 * blends / 3) << searched << " blend searches for " << blends << " blends";
}
