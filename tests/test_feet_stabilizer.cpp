// The model of HRP-2's stabilizer (hrp2_bridge/sim/feet_stabilizer.h), one
// control law at a time, from measured wrenches made up here: a foot that
// carries load the plan does not want rises relative to the waist; a sole
// whose centre of pressure lies behind the wanted one turns its toe down, but
// not when it is already past a wanted ZMP pulled inside the sole; the centre
// of mass is judged against where the feet are; a swinging sole is placed
// where the plan has it relative to the supporting sole, and yields when it
// meets the floor early; switched off, its offsets fade; bad options are refused
// by name.
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

// The start stance's left sole alone: the right foot in the air.
std::vector<ContactSpec> leftSoleOnly() {
  std::vector<ContactSpec> contacts;
  for (const auto& c : standing().start_stance)
    if (standing().robot->spots()[c.spot].name == "l_sole") contacts.push_back(c);
  return contacts;
}

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
  const std::vector<ContactSpec> contacts = leftSoleOnly();
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

// Staggered feet (5.4 cm), the wanted ZMP 7 mm behind the front sole's heel
// and in line with it (as in a chair plan's double support): the loads and
// centres of pressure the soles are asked for combine to the ZMP, each inside
// its sole, and the rear sole takes over a fifth of the load (22%). Sharing by
// where the ZMP lies between the ankles gave it 12%, leaving the front heel
// to hold the rest.
TEST(FeetStabilizer, StaggeredFeetShareAZmpBehindTheFrontHeelWithTheRearSole) {
  const Scenario& sc = standing();
  const RobotModel& m = *sc.robot;
  Configuration q = sc.start;
  q.joints[m.jointIndex("LLEG_JOINT2")] -= 0.1;  // the left foot forward, kept level
  q.joints[m.jointIndex("LLEG_JOINT4")] += 0.1;
  Kinematics kin(sc.robot);
  kin.setConfiguration(q);
  const Eigen::Isometry3d front = kin.spotPose(spot("l_sole")), rear = kin.spotPose(spot("r_sole"));
  ASSERT_GT(front.translation().x() - rear.translation().x(), 0.03);
  const Eigen::Vector3d heel = front * Eigen::Vector3d(-0.077, 0, 0);
  const Eigen::Vector2d zmp(heel.x() - 0.007, heel.y());
  // The measured CoM that makes the wanted ZMP that point (no velocity).
  const hrp2::FeetStabilizerOptions o;
  const Eigen::Vector3d plan_com = kin.centerOfMass();
  Eigen::Vector3d com = plan_com;
  com.head<2>() += (zmp - plan_com.head<2>()) / o.zmp_com_gain;
  std::vector<hrp2::SpotWrench> w(m.spots().size());
  w[spot("l_sole")] = soleWrench(q, "l_sole", 570, {-0.07, 0});
  w[spot("r_sole")] = soleWrench(q, "r_sole", 0, {0, 0});
  hrp2::FeetStabilizer st(sc.robot, sc.scene, o);
  for (int k = 0; k < 10; ++k) st.update(0.005, true, q, sc.start_stance, com, w);
  EXPECT_LT((st.wantedZmp() - zmp).norm(), 1e-6);
  // The soles' wanted loads and centres of pressure put the combined centre
  // of pressure at the ZMP, each inside its sole, the rear sole taking a share.
  const int l = spot("l_sole"), r = spot("r_sole");
  const double total = st.wantedLoad(l) + st.wantedLoad(r);
  EXPECT_NEAR(total, 570, 1e-6);
  const Eigen::Vector2d combined = (st.wantedLoad(l) * st.wantedCop(l) + st.wantedLoad(r) * st.wantedCop(r)) / total;
  EXPECT_LT((combined - zmp).norm(), 1e-4) << combined.transpose() << " vs " << zmp.transpose();
  EXPECT_GT(st.wantedLoad(r), 0.17 * total);
  for (int s : {l, r}) {
    const Eigen::Isometry3d X = kin.spotPose(s);
    const Eigen::Vector3d local = X.inverse() * Eigen::Vector3d(st.wantedCop(s).x(), st.wantedCop(s).y(), X.translation().z());
    EXPECT_TRUE(m.spots()[s].polygon.contains(local.head<2>(), 1e-9)) << m.spots()[s].name;
  }
  // Measured with the whole load on the front sole: it rises, the rear one is pressed down.
  EXPECT_GT(st.lift(l), 1e-5);
  EXPECT_LT(st.lift(r), -1e-5);
}

// The robot standing 12 mm forward of the plan, feet and body alike (its
// footholds drifted over earlier steps): relative to its feet the centre of
// mass is where the plan has it, and the stabilizer, told where the soles
// are, wants the plan's ZMP. Judged in the world frame (origins not given),
// the same state reads as a 12 mm error and moves the wanted ZMP 21 mm
// forward, toward the toes.
TEST(FeetStabilizer, TheCentreOfMassIsJudgedAgainstWhereTheFeetAreNotWhereThePlanPutThem) {
  const Scenario& sc = standing();
  const Configuration& q = sc.start;
  const Eigen::Vector3d drift(0.012, 0, 0);
  const Eigen::Vector3d com = plannedCom(q) + drift;
  Kinematics kin(sc.robot);
  kin.setConfiguration(q);
  std::vector<hrp2::SpotWrench> w(sc.robot->spots().size());
  for (const std::string sole : {"r_sole", "l_sole"}) w[spot(sole)] = soleWrench(q, sole, 285, {0.01, 0});
  hrp2::FeetStabilizer blind(sc.robot, sc.scene, {});
  for (int k = 0; k < 10; ++k) blind.update(0.005, true, q, sc.start_stance, com, w);
  EXPECT_NEAR(blind.wantedZmp().x() - plannedCom(q).x(), 1.73 * 0.012, 1e-6);
  for (const std::string sole : {"r_sole", "l_sole"}) w[spot(sole)].frame = Eigen::Translation3d(drift) * kin.spotPose(spot(sole));
  hrp2::FeetStabilizer st(sc.robot, sc.scene, {});
  for (int k = 0; k < 10; ++k) st.update(0.005, true, q, sc.start_stance, com, w);
  EXPECT_LT((st.wantedZmp() - plannedCom(q).head<2>()).norm(), 1e-9);
}

// The measured centre of mass behind the plan's so that the wanted ZMP lies
// 6 mm behind a single sole's heel: it is pulled 5 mm inside the heel, and
// the measured centre of pressure is already on the heel's edge. The sole
// must not turn its toe down to bring the pressure back inside: that would
// tip the body further back, the opposite of what the wanted ZMP asks (the
// feet-only chair fell backward so).
TEST(FeetStabilizer, APressureAlreadyPastAWantedZmpPulledInsideTheSoleIsLeftThere) {
  const Scenario& sc = standing();
  const Configuration& q = sc.start;
  const std::vector<ContactSpec> contacts = leftSoleOnly();
  Kinematics kin(sc.robot);
  kin.setConfiguration(q);
  const Eigen::Isometry3d X = kin.spotPose(spot("l_sole"));
  const Eigen::Vector3d target = X * Eigen::Vector3d(-0.083, 0, 0);
  const hrp2::FeetStabilizerOptions o;
  Eigen::Vector3d com = plannedCom(q);
  com.head<2>() += (target.head<2>() - com.head<2>()) / o.zmp_com_gain;
  std::vector<hrp2::SpotWrench> w(sc.robot->spots().size());
  w[spot("l_sole")] = soleWrench(q, "l_sole", 570, {-0.077, 0});
  hrp2::FeetStabilizer st(sc.robot, sc.scene, o);
  for (int k = 0; k < 20; ++k) st.update(0.005, true, q, contacts, com, w);
  ASSERT_LT((st.wantedZmp() - target.head<2>()).norm(), 1e-9);
  EXPECT_LE(st.tilt(spot("l_sole")).y(), 0.0);  // not toe-down
  // Measured 10 mm inside the pulled point instead, the sole turns toe-up to
  // move the pressure back toward the heel.
  w[spot("l_sole")] = soleWrench(q, "l_sole", 570, {-0.062, 0});
  hrp2::FeetStabilizer inside(sc.robot, sc.scene, o);
  for (int k = 0; k < 20; ++k) inside.update(0.005, true, q, contacts, com, w);
  EXPECT_LT(inside.tilt(spot("l_sole")).y(), -1e-3);
}

// A swinging sole (not among the phase's contacts) that meets the floor early
// yields: it rises relative to the waist at its measured load over the force
// damping, and once unloaded its rise fades out.
TEST(FeetStabilizer, ASwingingSoleThatMeetsTheFloorEarlyYields) {
  const Scenario& sc = standing();
  const Configuration& q = sc.start;
  const std::vector<ContactSpec> contacts = leftSoleOnly();
  std::vector<hrp2::SpotWrench> w(sc.robot->spots().size());
  w[spot("l_sole")] = soleWrench(q, "l_sole", 470, {0, 0});
  w[spot("r_sole")] = soleWrench(q, "r_sole", 100, {0, 0});
  hrp2::FeetStabilizer st(sc.robot, sc.scene, {});
  Eigen::VectorXd dq;
  for (int k = 0; k < 20; ++k) dq = st.update(0.005, true, q, contacts, plannedCom(q), w);
  // 100 N / 2e4 N s/m over 0.1 s = 0.5 mm.
  EXPECT_NEAR(st.lift(spot("r_sole")), 5e-4, 1e-6);
  const double rise = (relativeToWaist(q, dq, "r_sole").translation() - relativeToWaist(q, Eigen::VectorXd::Zero(dq.size()), "r_sole").translation()).z();
  EXPECT_NEAR(rise, st.lift(spot("r_sole")), 5e-5);
  w[spot("r_sole")] = {};
  for (int k = 0; k < 400; ++k) st.update(0.005, true, q, contacts, plannedCom(q), w);
  EXPECT_LT(st.lift(spot("r_sole")), 1e-5);
}

// The waist measured 1 cm ahead of where the plan has it over the supporting
// left sole (the body leans on its compliant servos): the right sole, in the
// air, would land 1 cm ahead of its planned place relative to the left one.
// The stabilizer moves it back relative to the waist until it lands where the
// plan puts it relative to the supporting sole; once it touches, it is held.
TEST(FeetStabilizer, ASwingingSoleIsPlacedWhereThePlanHasItRelativeToTheSupportingSole) {
  const Scenario& sc = standing();
  const Configuration& q = sc.start;
  const std::vector<ContactSpec> contacts = leftSoleOnly();
  Kinematics kin(sc.robot);
  kin.setConfiguration(q);
  std::vector<hrp2::SpotWrench> w(sc.robot->spots().size());
  w[spot("l_sole")] = soleWrench(q, "l_sole", 570, {0, 0});
  w[spot("l_sole")].frame = kin.spotPose(spot("l_sole"));
  const Eigen::Isometry3d waist = Eigen::Translation3d(0.01, 0, 0) * q.basePose();
  hrp2::FeetStabilizer st(sc.robot, sc.scene, {});
  Eigen::VectorXd dq;
  for (int k = 0; k < 200; ++k) dq = st.update(0.005, true, q, contacts, plannedCom(q), w, waist);
  const Eigen::Matrix<double, 6, 1> x = st.placement(spot("r_sole"));
  EXPECT_NEAR(x[0], -0.01, 1e-5);  // 1 s of a 0.1 s lag: within e^-10
  EXPECT_NEAR(x.segment<4>(1).norm(), 0, 1e-9);
  const Eigen::Vector3d moved = relativeToWaist(q, dq, "r_sole").translation() -
                                relativeToWaist(q, Eigen::VectorXd::Zero(dq.size()), "r_sole").translation();
  EXPECT_NEAR(moved.x(), -0.01, 2e-4);
  EXPECT_NEAR(moved.y(), 0, 2e-4);
  // Touching the floor, the sole stays where it was put even if the waist comes back.
  w[spot("r_sole")] = soleWrench(q, "r_sole", 20, {0, 0});
  for (int k = 0; k < 100; ++k) st.update(0.005, true, q, contacts, plannedCom(q), w, q.basePose());
  EXPECT_NEAR(st.placement(spot("r_sole"))[0], x[0], 1e-12);
  // Without the measured waist there is nothing to place against: no move.
  hrp2::FeetStabilizer blind(sc.robot, sc.scene, {});
  w[spot("r_sole")] = {};
  for (int k = 0; k < 200; ++k) blind.update(0.005, true, q, contacts, plannedCom(q), w);
  EXPECT_EQ(blind.placement(spot("r_sole")).norm(), 0.0);
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
