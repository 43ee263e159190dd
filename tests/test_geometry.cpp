#include <gtest/gtest.h>

#include <cmath>

#include "planner/common/geometry.h"
#include "planner/common/yaml_field.h"

using namespace acyclic;

TEST(Geometry, RpyMatchesUrdfConvention) {
  // URDF: R = Rz(yaw) Ry(pitch) Rx(roll)
  const Eigen::Vector3d rpy(0.3, -0.7, 1.9);
  const Eigen::Matrix3d R = rpyToQuaternion(rpy).toRotationMatrix();
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(1.9, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_LT((R - expected).norm(), 1e-12);
  EXPECT_LT((quaternionToRpy(rpyToQuaternion(rpy)) - rpy).norm(), 1e-12);
  // y rotation by +90 deg maps z to +x: the convention the spot frames rely on.
  EXPECT_LT((rpyToQuaternion({0, M_PI / 2, 0}) * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 1e-12);
}

TEST(Geometry, ExpLogRoundTrip) {
  const Eigen::Vector3d w(0.2, -1.1, 0.4);
  EXPECT_LT((logSO3(expSO3(w)) - w).norm(), 1e-12);
  EXPECT_LT((expSO3(Eigen::Vector3d::Zero()) - Eigen::Matrix3d::Identity()).norm(), 1e-15);
}

TEST(Geometry, PolygonSignedDistanceAndOrientation) {
  // Given clockwise: stored counter-clockwise, same area.
  ConvexPolygon sq({{0, 0}, {0, 1}, {1, 1}, {1, 0}});
  EXPECT_NEAR(sq.area(), 1.0, 1e-12);
  EXPECT_NEAR(sq.signedDistance({0.5, 0.5}), -0.5, 1e-12);
  EXPECT_NEAR(sq.signedDistance({0.5, 0.9}), -0.1, 1e-12);
  EXPECT_NEAR(sq.signedDistance({2, 0.5}), 1.0, 1e-12);
  EXPECT_NEAR(sq.signedDistance({2, 2}), std::sqrt(2.0), 1e-12);  // corner region: exact distance
  EXPECT_TRUE(sq.contains({1.0005, 0.5}, 1e-3));
  EXPECT_FALSE(sq.contains({1.0005, 0.5}));
  EXPECT_LT((sq.centroid() - Eigen::Vector2d(0.5, 0.5)).norm(), 1e-12);
  EXPECT_LT((sq.nearestBoundaryPoint({2, 0.5}) - Eigen::Vector2d(1, 0.5)).norm(), 1e-12);
  EXPECT_LT((sq.nearestBoundaryPoint({2, 2}) - Eigen::Vector2d(1, 1)).norm(), 1e-12);  // a corner
  EXPECT_LT((sq.nearestBoundaryPoint({0.5, 0.9}) - Eigen::Vector2d(0.5, 1)).norm(), 1e-12);  // from inside
}

TEST(Geometry, PolygonInsetMovesEveryEdgeInward) {
  const ConvexPolygon rect({{-0.077, -0.069}, {0.14, -0.069}, {0.14, 0.069}, {-0.077, 0.069}});
  const ConvexPolygon a = rect.inset(0.02);
  ASSERT_EQ(a.size(), 4u);
  for (const auto& v : a.vertices()) EXPECT_NEAR(rect.signedDistance(v), -0.02, 1e-12);
  EXPECT_NEAR(a.area(), (0.217 - 0.04) * (0.138 - 0.04), 1e-12);
  // Capped at three quarters of the centroid's depth (0.069): a quarter of the width left.
  const ConvexPolygon b = rect.inset(1.0);
  EXPECT_NEAR(b.area(), (0.217 - 0.1035) * (0.138 - 0.1035), 1e-12);
  EXPECT_EQ(rect.inset(0).vertices(), rect.vertices());
  // A short edge between two sharp corners would vanish: scaled instead, every
  // edge at least d inside.
  const ConvexPolygon kite({{0, -1}, {4, -0.01}, {4, 0.01}, {0, 1}});
  const ConvexPolygon k = kite.inset(0.3);
  ASSERT_EQ(k.size(), 4u);
  for (const auto& v : k.vertices()) EXPECT_LE(kite.signedDistance(v), -0.3 + 1e-12);
  EXPECT_THROW(rect.inset(-0.01), std::invalid_argument);
  // Shrunk by a box: 1 cm along x, 4 cm along y.
  const ConvexPolygon c = rect.inset(0.01, 0.04);
  EXPECT_NEAR(c.area(), (0.217 - 0.02) * (0.138 - 0.08), 1e-12);
  EXPECT_EQ(rect.inset(0.02, 0.02).vertices(), a.vertices());
  // Capped: the y edges at three quarters of 0.069, x scaled alike.
  const ConvexPolygon e = rect.inset(0.01, 0.1);
  const double f = 0.75 * 0.069 / 0.1;
  EXPECT_NEAR(e.area(), (0.217 - 0.02 * f) * (0.138 - 0.2 * f), 1e-12);
  // A tilted edge moves by dx |n_x| + dy |n_y|.
  const ConvexPolygon tri({{0, 0}, {2, 0}, {0, 2}});
  const ConvexPolygon t = tri.inset(0.1, 0.2);
  for (const auto& v : t.vertices()) {
    EXPECT_GE(v.x(), 0.1 - 1e-12);
    EXPECT_GE(v.y(), 0.2 - 1e-12);
    EXPECT_LE(v.x() + v.y(), 2 - 0.3 + 1e-12);
  }
}

TEST(Geometry, PolygonRejectsBadInput) {
  EXPECT_THROW(ConvexPolygon({{0, 0}, {1, 0}}), std::invalid_argument);
  EXPECT_THROW(ConvexPolygon({{0, 0}, {1, 0}, {2, 0}}), std::invalid_argument);                   // no area
  EXPECT_THROW(ConvexPolygon({{0, 0}, {2, 0}, {1, 0.2}, {2, 2}, {0, 2}}), std::invalid_argument);  // not convex
}

TEST(YamlField, ErrorsNameFileFieldAndExpectation) {
  YamlField f = YamlField::loadText("a: {b: [1, 2, x]}\nc: 3\n", "mem.yaml");
  try {
    f["a"]["b"].vec3();
    FAIL() << "expected a FormatError";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), "mem.yaml");
    EXPECT_EQ(e.field(), "a.b[2]");
    EXPECT_NE(std::string(e.what()).find("'x'"), std::string::npos) << e.what();
  }
  try {
    f["missing"];
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "missing");
  }
  try {
    f.allowOnly({"a"});
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "c");
  }
  EXPECT_THROW(YamlField::loadText("a: [1, 2\n", "broken.yaml"), FormatError);
  EXPECT_THROW(YamlField::loadFile("/nonexistent/file.yaml"), FormatError);
}
