// The model of HRP-2's stabilizer (hrp2_bridge/sim/feet_stabilizer.h), one
// control law at a time, from measured wrenches made up here: a foot that
// carries load the plan does not want rises relative to the waist; a sole
// whose centre of pressure lies behind the wanted one turns its toe down;
// switched off, its offsets fade; bad options are refused by name.
#include <gtest/gtest.h>

#include <cmath>

#include "hrp2_bridge/sim/feet_stabilizer.h"
#include "planner/model/kinematics.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& standing() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  return sc;
}

int spot(const std::string& name) { return standing().robot->spotIndex(name); }

// A sole's wrench: `fz` newtons straight up, applied at `cop` in the sole's
// frame (x forward, y left), at the plan's posture.
hrp2::SpotWrench soleWrench(const Configuration& q, const std::string& sole, double fz, const Eigen::Vector2d& cop) {
  Kinematics kin(standing().robot);
  kin.setConfiguration(q);
  const Eigen::Isometry3d X = kin.spotPose(spot(sole));
  hrp2::SpotWrench w;
  w.force = Eigen::Vector3d(0, 0, fz);
  w.moment = (X.linear() * Eigen::Vector3d(cop.x(), cop.y(), 0)).cross(w.force);
  return w;
}

// The spot's pose relative to the waist at the plan's joints plus `dq`.
Eigen::Isometry3d relativeToWaist(const Configuration& q, const Eigen::VectorXd& dq, const std::string& name) {
  Kinematics kin(standing().robot);
  Configuration x = q;
  x.joints += dq;
  kin.setConfiguration(x);
  return kin.linkPose(0).inverse() * kin.spotPose(spot(name));
}

Eigen::Vector3d plannedCom(const Configuration& q) {
  Kinematics kin(standing().robot);
  kin.setConfiguration(q);
  return kin.centerOfMass();
}

}  // namespace

TEST(FeetStabilizer, AFootLoadedAgainstThePlanRisesAndTheOtherStays) {
  const Scenario& sc = standing();
  const Configuration& q = sc.start;
  std::vector<ContactSpec> contacts = sc.start_stance;  // r_sole, l_sole
  for (auto& c : contacts) c.supporting = sc.robot->spots()[c.spot].name == "l_sole";  // r_sole released
  std::vector<hrp2::SpotWrench> w(sc.robot->spots().size());
  w[spot("r_sole")] = soleWrench(q, "r_sole", 150, {0.03, 0});
  w[spot("l_sole")] = soleWrench(q, "l_sole", 420, {0.03, 0});
  hrp2::FeetStabilizer st(sc.robot, sc.scene, {});
  Eigen::VectorXd dq;
  for (int k = 0; k < 40; ++k) dq = st.update(0.005, true, q, contacts, plannedCom(q), w);
  // (f - f*) / D over 0.2 s, less the leak: 150 N / 2e4 N s/m * 0.2 s = 1.5 mm.
  EXPECT_GT(st.lift(spot("r_sole")), 1e-3);
  EXPECT_LT(st.lift(spot("r_sole")), 1.6e-3);
  EXPECT_LT(st.lift(spot("l_sole")), 0);  // wanted the whole load: pressed down
  const double rise = (relativeToWaist(q, dq, "r_sole").translation() - relativeToWaist(q, Eigen::VectorXd::Zero(dq.size()), "r_sole").translation()).z();
  EXPECT_NEAR(rise, st.lift(spot("r_sole")), 5e-5);
  // Played open-loop (off), the offsets fade out.
  for (int k = 0; k < 400; ++k) dq = st.update(0.005, false, q, contacts, plannedCom(q), w);
  EXPECT_LT(std::abs(st.lift(spot("r_sole"))), 2e-4);
  EXPECT_LT(dq.norm(), 1e-3);
}

TEST(FeetStabilizer, ASoleLoadedBehindTheWantedPointTurnsItsToeDown) {
  const Scenario& sc = standing();
  const Configuration& q = sc.start;
  // One sole supporting, the measured centre of mass on the plan's: the
  // wanted centre of pressure is the CoM's projection (here between the
  // feet: the nearest point 5 mm inside the sole's inner edge), 2 cm ahead
  // of where the load is measured.
  std::vector<ContactSpec> contacts;
  for (const auto& c : sc.start_stance)
    if (sc.robot->spots()[c.spot].name == "l_sole") contacts.push_back(c);
  Kinematics kin(sc.robot);
  kin.setConfiguration(q);
  Eigen::Vector3d com_in_sole = kin.spotPose(spot("l_sole")).inverse() * plannedCom(q);
  ASSERT_LT(com_in_sole.y(), -0.064);
  com_in_sole.y() = -0.064;
  std::vector<hrp2::SpotWrench> w(sc.robot->spots().size());
  w[spot("l_sole")] = soleWrench(q, "l_sole", 570, com_in_sole.head<2>() - Eigen::Vector2d(0.02, 0));
  hrp2::FeetStabilizer st(sc.robot, sc.scene, {});
  Eigen::VectorXd dq;
  for (int k = 0; k < 20; ++k) dq = st.update(0.005, true, q, contacts, plannedCom(q), w);
  EXPECT_GT(st.tilt(spot("l_sole")).y(), 0);                  // about +y: toe down
  EXPECT_NEAR(st.tilt(spot("l_sole")).x(), 0, 1e-6);          // no error across the sole
  EXPECT_DOUBLE_EQ(st.lift(spot("l_sole")), 0.0);             // a single foot's force is the weight
  const Eigen::Vector3d toe_before = relativeToWaist(q, Eigen::VectorXd::Zero(dq.size()), "l_sole") * Eigen::Vector3d(0.14, 0, 0);
  const Eigen::Vector3d toe_after = relativeToWaist(q, dq, "l_sole") * Eigen::Vector3d(0.14, 0, 0);
  EXPECT_LT(toe_after.z(), toe_before.z() - 1e-4);
  // The right leg, in the air, is left alone.
  for (const std::string j : {"RLEG_JOINT2", "RLEG_JOINT3", "RLEG_JOINT4"}) EXPECT_EQ(dq[sc.robot->jointIndex(j)], 0.0) << j;
}

TEST(FeetStabilizer, BadOptionsAreRefusedByName) {
  hrp2::FeetStabilizerOptions o;
  o.force_damping = 0;
  try {
    o.validate();
    FAIL() << "accepted a zero force damping";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("force_damping"), std::string::npos) << e.what();
  }
  o = {};
  o.cop_gain = -1;
  EXPECT_THROW(o.validate(), std::invalid_argument);
}
