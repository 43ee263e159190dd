// HRP-2 model: public figures, named postures, and every Jacobian against
// finite differences (relative error under 1e-6).
#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "planner/common/geometry.h"
#include "planner/model/kinematics.h"
#include "planner/model/robot_model.h"
#include "test_support.h"

using namespace acyclic;

namespace {

std::shared_ptr<const RobotModel> hrp2() {
  static auto m = RobotModel::load(test::sourcePath("models/hrp2/hrp2.yaml"));
  return m;
}

// A random configuration within the joint limits, base anywhere near the origin.
Configuration randomConfiguration(const RobotModel& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1), s(-1, 1);
  Configuration q = m.zeroConfiguration();
  q.base_position = Eigen::Vector3d(s(rng), s(rng), 0.5 + u(rng));
  q.base_orientation = Eigen::Quaterniond(expSO3(Eigen::Vector3d(s(rng), s(rng), s(rng))));
  for (const auto& j : m.joints()) q.joints[j.index] = j.lower + (j.upper - j.lower) * u(rng);
  return q;
}

// Central differences of a vector function of the configuration, on the tangent space.
template <class F>
Eigen::MatrixXd numericJacobian(const Configuration& q, int rows, F f, double h = 1e-6) {
  Eigen::MatrixXd J(rows, q.tangentSize());
  for (int i = 0; i < q.tangentSize(); ++i) {
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(q.tangentSize());
    dq[i] = h;
    J.col(i) = (f(integrate(q, dq)) - f(integrate(q, -dq))) / (2 * h);
  }
  return J;
}

}  // namespace

TEST(Hrp2Model, PublicFigures) {
  auto m = hrp2();
  ASSERT_EQ(m->numJoints(), 30);
  EXPECT_EQ(m->numLinks(), 31);
  EXPECT_NEAR(m->totalMass(), 58.0, 0.5);
  const std::vector<std::string> order = {
      "RLEG_JOINT0", "RLEG_JOINT1", "RLEG_JOINT2", "RLEG_JOINT3", "RLEG_JOINT4", "RLEG_JOINT5",
      "LLEG_JOINT0", "LLEG_JOINT1", "LLEG_JOINT2", "LLEG_JOINT3", "LLEG_JOINT4", "LLEG_JOINT5",
      "CHEST_JOINT0", "CHEST_JOINT1", "HEAD_JOINT0", "HEAD_JOINT1",
      "RARM_JOINT0", "RARM_JOINT1", "RARM_JOINT2", "RARM_JOINT3", "RARM_JOINT4", "RARM_JOINT5", "RARM_JOINT6",
      "LARM_JOINT0", "LARM_JOINT1", "LARM_JOINT2", "LARM_JOINT3", "LARM_JOINT4", "LARM_JOINT5", "LARM_JOINT6"};
  EXPECT_EQ(m->jointNames(), order);
  const double d = M_PI / 180;
  auto limits = [&](const char* n) { return m->joints()[m->jointIndex(n)]; };
  EXPECT_NEAR(limits("RLEG_JOINT3").lower, -2 * d, 1e-6);
  EXPECT_NEAR(limits("RLEG_JOINT3").upper, 150 * d, 1e-6);
  EXPECT_NEAR(limits("RLEG_JOINT0").lower, -45 * d, 1e-6);
  EXPECT_NEAR(limits("LLEG_JOINT0").upper, 45 * d, 1e-6);
  EXPECT_NEAR(limits("LARM_JOINT1").upper, 95 * d, 1e-6);
  EXPECT_NEAR(limits("RARM_JOINT0").lower, -180 * d, 1e-6);
  EXPECT_NEAR(limits("RLEG_JOINT0").velocity, 3.54, 1e-9);
  EXPECT_EQ(m->spots().size(), 12u);
  EXPECT_GT(m->selfCollisionPairs().size(), 50u);
  for (const auto& [a, b] : m->selfCollisionPairs()) {
    // non-adjacent: neither link is the other's parent
    const auto& la = m->links()[a];
    const auto& lb = m->links()[b];
    if (la.parent_joint >= 0) {
      EXPECT_NE(m->joints()[la.parent_joint].parent_link, b) << la.name << "-" << lb.name;
    }
    if (lb.parent_joint >= 0) {
      EXPECT_NE(m->joints()[lb.parent_joint].parent_link, a) << la.name << "-" << lb.name;
    }
  }
}

TEST(Hrp2Model, HalfSittingWaistHeightAndCenterOfMass) {
  auto m = hrp2();
  Kinematics k(m);
  Configuration q = m->posture("half_sitting");
  q.base_position.setZero();
  k.setConfiguration(q);
  const Eigen::Isometry3d r = k.spotPose(m->spotIndex("r_sole"));
  const Eigen::Isometry3d l = k.spotPose(m->spotIndex("l_sole"));
  // Feet flat and level: the waist height is the soles' depth below it.
  EXPECT_NEAR(-r.translation().z(), 0.6487, 1e-3);
  EXPECT_NEAR(r.translation().z(), l.translation().z(), 1e-9);
  EXPECT_NEAR(r.linear().col(2).z(), 1.0, 1e-9);
  EXPECT_NEAR(r.translation().y(), -0.095, 1e-9);
  EXPECT_NEAR(l.translation().y(), 0.095, 1e-9);
  // The named posture stands on z = 0: CoM height as published (about 0.814).
  k.setConfiguration(m->posture("half_sitting"));
  EXPECT_NEAR(k.spotPose(m->spotIndex("r_sole")).translation().z(), 0.0, 1e-6);
  const double com_z = k.centerOfMass().z();
  EXPECT_GE(com_z, 0.79);
  EXPECT_LE(com_z, 0.83);
  // left-right symmetric but for the grippers, whose public axis is unknown and not mirrored
  EXPECT_NEAR(k.centerOfMass().y(), 0.0, 1e-4);
}

TEST(Hrp2Model, SittingPutsThighsLevelAndSolesFlat) {
  auto m = hrp2();
  Kinematics k(m);
  k.setConfiguration(m->posture("sitting"));
  for (const char* s : {"r_sole", "l_sole"}) {
    EXPECT_NEAR(k.spotPose(m->spotIndex(s)).translation().z(), 0.0, 1e-9) << s;
    EXPECT_NEAR(k.spotPose(m->spotIndex(s)).linear().col(2).z(), 1.0, 1e-9) << s;
  }
  for (const char* s : {"r_thigh", "l_thigh"}) {
    // the thigh underside faces down: its inward normal points up, 0.06 below the hip
    EXPECT_NEAR(k.spotPose(m->spotIndex(s)).translation().z(), 0.345, 1e-9) << s;
    EXPECT_NEAR(k.spotPose(m->spotIndex(s)).linear().col(2).z(), 1.0, 1e-9) << s;
  }
}

TEST(Hrp2Model, PointAndFrameJacobiansMatchFiniteDifferences) {
  auto m = hrp2();
  Kinematics k(m), probe(m);
  std::mt19937 rng(7);
  const Eigen::Vector3d p(0.03, -0.02, -0.1);
  for (int trial = 0; trial < 5; ++trial) {
    const Configuration q = randomConfiguration(*m, rng);
    k.setConfiguration(q);
    for (const char* name : {"WAIST", "RLEG_LINK5", "LARM_LINK6", "HEAD_LINK1", "CHEST_LINK1"}) {
      const int link = m->linkIndex(name);
      const Eigen::MatrixXd J = k.pointJacobian(link, p);
      const Eigen::MatrixXd Jn = numericJacobian(q, 3, [&](const Configuration& c) {
        probe.setConfiguration(c);
        return Eigen::VectorXd(probe.linkPose(link) * p);
      });
      EXPECT_LT(test::relativeError(J, Jn), 1e-6) << name << " trial " << trial;

      const Eigen::MatrixXd F = k.frameJacobian(link, p);
      EXPECT_LT(test::relativeError(F.topRows(3), Jn), 1e-6) << name;
      // Angular part: finite difference of the rotation, as a world rotation vector.
      Eigen::MatrixXd Wn(3, q.tangentSize());
      for (int i = 0; i < q.tangentSize(); ++i) {
        Eigen::VectorXd dq = Eigen::VectorXd::Zero(q.tangentSize());
        const double h = 1e-6;
        dq[i] = h;
        probe.setConfiguration(integrate(q, dq));
        const Eigen::Matrix3d Rp = probe.linkPose(link).linear();
        probe.setConfiguration(integrate(q, -dq));
        const Eigen::Matrix3d Rm = probe.linkPose(link).linear();
        Wn.col(i) = logSO3(Rp * Rm.transpose()) / (2 * h);
      }
      EXPECT_LT(test::relativeError(F.bottomRows(3), Wn), 1e-6) << name;
    }
  }
}

TEST(Hrp2Model, CenterOfMassJacobianMatchesFiniteDifferences) {
  auto m = hrp2();
  Kinematics k(m), probe(m);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const Configuration q = randomConfiguration(*m, rng);
    k.setConfiguration(q);
    const Eigen::MatrixXd Jn = numericJacobian(q, 3, [&](const Configuration& c) {
      probe.setConfiguration(c);
      return Eigen::VectorXd(probe.centerOfMass());
    });
    EXPECT_LT(test::relativeError(k.centerOfMassJacobian(), Jn), 1e-6) << "trial " << trial;
  }
}

TEST(Hrp2Model, GravityTorquesAreTheGradientOfPotentialEnergy) {
  // g(q) = dV/dq with V = M g z_com: the torques that hold the robot still.
  auto m = hrp2();
  Kinematics k(m), probe(m);
  std::mt19937 rng(13);
  for (int trial = 0; trial < 5; ++trial) {
    const Configuration q = randomConfiguration(*m, rng);
    k.setConfiguration(q);
    const Eigen::MatrixXd dV = numericJacobian(q, 1, [&](const Configuration& c) {
      probe.setConfiguration(c);
      return Eigen::VectorXd::Constant(1, m->totalMass() * 9.81 * probe.centerOfMass().z());
    });
    const Eigen::VectorXd g = k.gravityTorques();
    EXPECT_LT(test::relativeError(g.transpose(), dV), 1e-6) << "trial " << trial;
    EXPECT_NEAR(g[2], m->totalMass() * 9.81, 1e-9);  // the base carries the whole weight
  }
}

TEST(Hrp2Model, IntegrateAndDifferenceAreInverse) {
  auto m = hrp2();
  std::mt19937 rng(3);
  const Configuration a = randomConfiguration(*m, rng);
  Eigen::VectorXd dq = Eigen::VectorXd::Random(a.tangentSize()) * 0.3;
  const Configuration b = integrate(a, dq);
  EXPECT_LT((difference(a, b) - dq).norm(), 1e-12);
}

TEST(Hrp2Model, KinematicsOnTwoThreadsAgreeWithOneThread) {
  auto m = hrp2();
  std::mt19937 rng(5);
  std::vector<Configuration> qs;
  for (int i = 0; i < 50; ++i) qs.push_back(randomConfiguration(*m, rng));
  auto run = [&](std::vector<Eigen::Vector3d>& out) {
    Kinematics k(m);
    for (const auto& q : qs) {
      k.setConfiguration(q);
      out.push_back(k.centerOfMass() + k.linkPose(m->linkIndex("LARM_LINK6")).translation());
    }
  };
  std::vector<Eigen::Vector3d> ref, a, b;
  run(ref);
  std::thread ta([&] { run(a); }), tb([&] { run(b); });
  ta.join();
  tb.join();
  for (std::size_t i = 0; i < ref.size(); ++i) {
    EXPECT_EQ(ref[i], a[i]);
    EXPECT_EQ(ref[i], b[i]);
  }
}

TEST(Hrp2Model, ChainJacobiansMatchSimbody) {
  // The posture generator's fast Jacobians (from cached joint axes) against
  // Simbody's, and the gradient helpers against finite differences.
  auto m = hrp2();
  Kinematics k(m), probe(m);
  std::mt19937 rng(23);
  for (int trial = 0; trial < 5; ++trial) {
    const Configuration q = randomConfiguration(*m, rng);
    k.setConfiguration(q);
    for (const auto& l : m->links()) {
      const Eigen::Vector3d local(0.02, -0.03, -0.05);
      const Eigen::Vector3d world = k.linkPose(l.index) * local;
      EXPECT_LT(test::relativeError(k.chainPointJacobian(l.index, world), k.pointJacobian(l.index, local)), 1e-12)
          << l.name;
      const Eigen::Vector3d v(0.3, -1.2, 0.7);
      Eigen::VectorXd g = Eigen::VectorXd::Zero(q.tangentSize());
      k.addPointGradient(l.index, world, v, g);
      EXPECT_LT(test::relativeError(g.transpose(), v.transpose() * k.pointJacobian(l.index, local)), 1e-12);
    }
    // d(u . w)/dq for the z axis of a contact spot, against finite differences.
    const int spot = m->spotIndex("l_palm");
    const Eigen::Vector3d w(0.2, 0.5, -0.8);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(q.tangentSize());
    k.addAxisGradient(m->spots()[spot].link, k.spotPose(spot).linear().col(2), w, g);
    const Eigen::MatrixXd num = numericJacobian(q, 1, [&](const Configuration& c) {
      probe.setConfiguration(c);
      return Eigen::VectorXd::Constant(1, probe.spotPose(spot).linear().col(2).dot(w));
    });
    EXPECT_LT(test::relativeError(g.transpose(), num), 1e-6);
  }
}

// Poses composed along the tree from the joints' origins (setPoses, the
// limb planner's clearance checks) are Simbody's to rounding; Simbody's
// queries refuse a state setPoses left behind, until setConfiguration.
TEST(Hrp2Model, PosesWithoutSimbodyAgreeWithSimbodyAndStaleQueriesThrow) {
  const auto m = hrp2();
  std::mt19937 rng(11);
  Kinematics simbody(m), poses(m);
  for (int trial = 0; trial < 20; ++trial) {
    const Configuration q = randomConfiguration(*m, rng);
    simbody.setConfiguration(q);
    poses.setPoses(q);
    for (const auto& l : m->links()) {
      EXPECT_LT((poses.linkPose(l.index).matrix() - simbody.linkPose(l.index).matrix()).cwiseAbs().maxCoeff(), 1e-12)
          << l.name;
    }
    for (const auto& j : m->joints()) {
      EXPECT_LT((poses.jointAxis(j.index) - simbody.jointAxis(j.index)).norm(), 1e-12) << j.name;
      EXPECT_LT((poses.jointOrigin(j.index) - simbody.jointOrigin(j.index)).norm(), 1e-12) << j.name;
    }
    const int spot = m->spotIndex("r_sole");
    EXPECT_LT((poses.spotPose(spot).matrix() - simbody.spotPose(spot).matrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
  EXPECT_THROW(poses.pointJacobian(0, Eigen::Vector3d::Zero()), std::logic_error);
  EXPECT_THROW(poses.frameJacobian(0, Eigen::Vector3d::Zero()), std::logic_error);
  EXPECT_THROW(poses.centerOfMass(), std::logic_error);
  EXPECT_THROW(poses.centerOfMassJacobian(), std::logic_error);
  EXPECT_THROW(poses.gravityTorques(), std::logic_error);
  poses.setConfiguration(simbody.configuration());
  EXPECT_LT((poses.centerOfMass() - simbody.centerOfMass()).norm(), 1e-15);
  EXPECT_THROW(poses.setPoses(Configuration{}), std::invalid_argument);
}

// Acceleration limits: the robot file's default and per-joint overrides;
// a bad value or an unknown joint is named with the file and the field.
TEST(Hrp2Model, AccelerationLimitsFromTheRobotFile) {
  for (const auto& j : hrp2()->joints()) EXPECT_EQ(j.acceleration, 4.0) << j.name;
  const std::string yaml = test::readFile(test::sourcePath("models/hrp2/hrp2.yaml"));
  const std::string line = "acceleration_limits: {default: 4.0}";
  ASSERT_NE(yaml.find(line), std::string::npos);
  auto load = [&](const std::string& replacement) {
    test::TempDir dir;
    std::string text = yaml;
    text.replace(text.find(line), line.size(), replacement);
    dir.write("hrp2.urdf", test::readFile(test::sourcePath("models/hrp2/hrp2.urdf")));
    return RobotModel::load(dir.write("hrp2.yaml", text));
  };
  const auto m = load("acceleration_limits: {default: 2.5, RARM_JOINT6: 9}");
  EXPECT_EQ(m->joints()[m->jointIndex("RARM_JOINT6")].acceleration, 9.0);
  EXPECT_EQ(m->joints()[m->jointIndex("LLEG_JOINT3")].acceleration, 2.5);
  EXPECT_EQ(m->accelerationLimits()[m->jointIndex("RARM_JOINT6")], 9.0);
  for (const auto& [text, needle] : std::vector<std::pair<std::string, std::string>>{
           {"acceleration_limits: {default: -1}", "acceleration_limits.default"},
           {"acceleration_limits: {default: .nan}", "acceleration_limits.default"},
           {"acceleration_limits: {RARM_JOINT9: 3}", "acceleration_limits.RARM_JOINT9"}}) {
    try {
      load(text);
      ADD_FAILURE() << text << " was accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("hrp2.yaml"), std::string::npos) << e.what();
    }
  }
}
