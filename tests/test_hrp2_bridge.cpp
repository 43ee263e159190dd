// The HRP-2 bridge library (hrp2_bridge/): limit, NaN and jump refusal, the
// stabilizer schedule, the quasi-static references, the state machine under
// explicit time (watchdogs, e-stop and blend, start guard, a second
// trajectory), the SequencePlayer files parsed back, and the simulated
// controller. Every time is passed in: no test depends on the machine's speed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "hrp2_bridge/bridge.h"
#include "hrp2_bridge/contract_check.h"
#include "hrp2_bridge/prepared_trajectory.h"
#include "hrp2_bridge/references.h"
#include "hrp2_bridge/sequence_player.h"
#include "hrp2_bridge/sim/simulated_controller.h"
#include "hrp2_bridge/stabilizer_schedule.h"
#include "hrp2_bridge/trajectory_check.h"
#include "planner/check/validity.h"
#include "planner/common/format_error.h"
#include "test_support.h"

using namespace acyclic;
using namespace acyclic::hrp2;

namespace {

const Scenario& chair() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

ContactSpec contact(const std::string& spot, const std::string& surface, bool supporting) {
  ContactSpec c;
  c.spot = chair().robot->spotIndex(spot);
  c.surface = chair().scene->surfaceIndex(surface);
  c.supporting = supporting;
  return c;
}

// The chair's start posture with one joint moving by `amplitude` along a
// half cosine over `duration` (zero velocity at both ends), one phase: the
// start stance (feet on the floor, thighs on the seat).
Trajectory synthetic(double duration = 1.0, int joint = 14, double amplitude = 0.2, double dt = 0.005) {
  const Scenario& sc = chair();
  Trajectory tr;
  tr.scenario = sc.path;
  tr.dt = dt;
  TrajectoryPhase p;
  p.contacts = sc.start_stance;
  p.t_end = duration;
  tr.phases = {p};
  const int n = static_cast<int>(std::lround(duration / dt));
  for (int i = 0; i <= n; ++i) {
    TrajectorySample s;
    s.t = i * dt;
    s.q = sc.start;
    const double a = M_PI * s.t / duration;
    s.q.joints[joint] += amplitude * (1 - std::cos(a)) / 2;
    s.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
    s.dq[joint] = amplitude * M_PI / duration * std::sin(a) / 2;
    tr.samples.push_back(s);
  }
  return tr;
}

PreparedTrajectory prepared(const Trajectory& tr, const BridgeConfig& cfg = {}) {
  PrepareResult r = prepareTrajectory(tr, chair().robot, chair().scene, cfg);
  EXPECT_TRUE(r.check.ok) << r.check.reason;
  return r.prepared;
}

}  // namespace

// ---------------------------------------------------------------- checks

TEST(Hrp2Check, AValidTrajectoryPasses) {
  const CheckResult r = checkTrajectory(synthetic(), *chair().robot, BridgeConfig{});
  EXPECT_TRUE(r.ok) << r.reason;
}

TEST(Hrp2Check, TheValidityContractRefusesAMotionIntoTheTable) {
  // RARM_JOINT0 -0.4 rad from the seated start: clear of the table, valid
  // (the independent check, sample by sample); -0.6 rad: the forearm goes
  // into it (about 2 cm).
  BridgeConfig cfg;
  const PrepareResult ok = prepareChecked(synthetic(1.0, 16, -0.4), chair(), cfg);
  EXPECT_TRUE(ok.check.ok) << ok.check.reason;
  EXPECT_FALSE(ok.prepared.samples.empty());
  const PrepareResult bad = prepareChecked(synthetic(1.5, 16, -0.6), chair(), cfg);
  ASSERT_FALSE(bad.check.ok);
  EXPECT_NE(bad.check.reason.find("table_top"), std::string::npos) << bad.check.reason;
  EXPECT_TRUE(bad.prepared.samples.empty());
  // Within the robot's limits: only the contract sees it.
  EXPECT_TRUE(prepareTrajectory(synthetic(1.5, 16, -0.6), chair().robot, chair().scene, cfg).check.ok);
  cfg.check_contract = false;
  EXPECT_TRUE(prepareChecked(synthetic(1.5, 16, -0.6), chair(), cfg).check.ok);
}

TEST(Hrp2Check, NanIsRefusedNamingSampleAndJoint) {
  Trajectory tr = synthetic();
  tr.samples[37].q.joints[20] = std::nan("");
  const CheckResult r = checkTrajectory(tr, *chair().robot, BridgeConfig{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.sample, 37);
  EXPECT_EQ(r.joint, 20);
  EXPECT_NE(r.reason.find("RARM_JOINT4"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("NaN"), std::string::npos) << r.reason;
  tr = synthetic();
  tr.samples[3].dq[2] = INFINITY;
  EXPECT_FALSE(checkTrajectory(tr, *chair().robot, BridgeConfig{}).ok);
  tr = synthetic();
  tr.samples[3].q.base_position.x() = std::nan("");
  EXPECT_FALSE(checkTrajectory(tr, *chair().robot, BridgeConfig{}).ok);
}

TEST(Hrp2Check, PositionBeyondALimitIsRefusedNotClamped) {
  const RobotModel& m = *chair().robot;
  // HEAD_JOINT0 moved by more than its range: refused at the first sample beyond.
  const double range = m.upperLimits()[14] - chair().start.joints[14];
  Trajectory tr = synthetic(4.0, 14, range + 0.05);
  const CheckResult r = checkTrajectory(tr, m, BridgeConfig{});
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.joint, 14);
  EXPECT_GT(tr.samples[r.sample].q.joints[14], m.upperLimits()[14]);
  EXPECT_LE(tr.samples[r.sample - 1].q.joints[14], m.upperLimits()[14]);
  EXPECT_NE(r.reason.find("outside its limits"), std::string::npos) << r.reason;
  // The same motion within a margin is refused earlier: margins apply.
  BridgeConfig cfg;
  cfg.position_margin = 0.1;
  EXPECT_LT(checkTrajectory(tr, m, cfg).sample, r.sample);
  // And the bridge's preparation refuses it as a whole.
  EXPECT_FALSE(prepareTrajectory(tr, chair().robot, chair().scene, BridgeConfig{}).check.ok);
}

TEST(Hrp2Check, VelocityBeyondALimitIsRefused) {
  const RobotModel& m = *chair().robot;
  const double vmax = m.velocityLimits()[14];
  // Peak velocity amplitude*pi/(2T): 1.2 vmax.
  const double T = 0.1, amplitude = 1.2 * vmax * 2 * T / M_PI;
  const CheckResult r = checkTrajectory(synthetic(T, 14, amplitude), m, BridgeConfig{});
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("velocity"), std::string::npos) << r.reason;
  // 0.9 vmax passes, but not with a 0.8 velocity margin.
  const Trajectory slower = synthetic(T, 14, 0.9 * vmax * 2 * T / M_PI);
  EXPECT_TRUE(checkTrajectory(slower, m, BridgeConfig{}).ok);
  BridgeConfig cfg;
  cfg.velocity_margin = 0.8;
  EXPECT_FALSE(checkTrajectory(slower, m, cfg).ok);
}

TEST(Hrp2Check, AJumpBetweenSamplesIsRefusedEvenWithSmallVelocities) {
  Trajectory tr = synthetic();
  for (std::size_t i = 100; i < tr.samples.size(); ++i) tr.samples[i].q.joints[3] += 0.05;  // a 5 cm... rad step
  const CheckResult r = checkTrajectory(tr, *chair().robot, BridgeConfig{});
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.sample, 100);
  EXPECT_EQ(r.joint, 3);
  EXPECT_NE(r.reason.find("jumps"), std::string::npos) << r.reason;
}

TEST(Hrp2Check, StartFarFromTheMeasuredPostureIsRefused) {
  const RobotModel& m = *chair().robot;
  const Eigen::VectorXd first = chair().start.joints;
  Eigen::VectorXd measured = first;
  measured[16] += 0.019;
  EXPECT_TRUE(checkStart(first, measured, m, BridgeConfig{}).ok);
  measured[16] += 0.002;
  const CheckResult r = checkStart(first, measured, m, BridgeConfig{});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("RARM_JOINT0"), std::string::npos) << r.reason;
  EXPECT_FALSE(checkMeasured(Eigen::VectorXd::Constant(30, NAN), Eigen::VectorXd::Zero(30), m).ok);
  EXPECT_FALSE(checkMeasured(Eigen::VectorXd::Zero(29), Eigen::VectorXd::Zero(29), m).ok);
}

// ---------------------------------------------------------------- stabilizer

TEST(Hrp2Stabilizer, CoplanarityOfSurfacesAndStances) {
  const Scene& s = *chair().scene;
  const RobotModel& m = *chair().robot;
  const Surface& floor = s.surfaces()[s.surfaceIndex("floor")];
  const Surface& table = s.surfaces()[s.surfaceIndex("table_top")];
  EXPECT_TRUE(coplanar(floor, floor, 1e-3));
  EXPECT_FALSE(coplanar(floor, table, 1e-3));  // parallel, 0.63 m apart
  EXPECT_TRUE(onlyCoplanarFeet({contact("r_sole", "floor", true), contact("l_sole", "floor", true)}, m, s, 1e-3));
  EXPECT_TRUE(onlyCoplanarFeet({contact("r_sole", "floor", true)}, m, s, 1e-3));
  EXPECT_FALSE(onlyCoplanarFeet({contact("r_sole", "floor", true), contact("l_sole", "chair_seat", true)}, m, s, 1e-3));
  // A touching (non-supporting) wrist already needs the stabilizer off.
  EXPECT_FALSE(onlyCoplanarFeet({contact("r_sole", "floor", true), contact("l_sole", "floor", true),
                                 contact("r_wrist", "table_top", false)}, m, s, 1e-3));
  EXPECT_FALSE(onlyCoplanarFeet({}, m, s, 1e-3));
}

TEST(Hrp2Stabilizer, OffJustBeforeANonCoplanarContactOnJustAfterItsRelease) {
  // Phases: feet [0, 1), feet + wrist touching [1, 2), wrist supporting
  // [2, 3), feet only again [3, 4].
  Trajectory tr = synthetic(4.0);
  const auto feet = std::vector<ContactSpec>{contact("r_sole", "floor", true), contact("l_sole", "floor", true)};
  auto with = [&](bool sup) {
    auto c = feet;
    c.push_back(contact("r_wrist", "table_top", sup));
    return c;
  };
  tr.phases.resize(4);
  const std::vector<std::vector<ContactSpec>> contacts = {feet, with(false), with(true), feet};
  for (int k = 0; k < 4; ++k) tr.phases[k].contacts = contacts[k], tr.phases[k].t_start = k, tr.phases[k].t_end = k + 1;
  for (auto& s : tr.samples) s.phase = std::min(3, static_cast<int>(std::floor(s.t + 1e-9)));
  BridgeConfig cfg;
  cfg.stabilizer_lead = 0.1;
  cfg.stabilizer_lag = 0.2;
  const StabilizerSchedule sch = scheduleStabilizer(tr, *chair().robot, *chair().scene, cfg);
  EXPECT_EQ(sch.phase_coplanar, (std::vector<bool>{true, false, false, true}));
  for (std::size_t i = 0; i < tr.samples.size(); ++i) {
    const double t = tr.samples[i].t;
    const bool expected = t < 0.9 - 1e-9 || t >= 3.2 - 1e-9;
    EXPECT_EQ(sch.sample_on[i], expected) << "t = " << t;
  }
  ASSERT_EQ(sch.switches.size(), 2u);
  EXPECT_FALSE(sch.switches[0].on);
  EXPECT_NEAR(sch.switches[0].t, 0.9, 1e-9);
  EXPECT_TRUE(sch.switches[1].on);
  EXPECT_NEAR(sch.switches[1].t, 3.2, 1e-9);
  // The prepared trajectory (and so every command) carries the same flags.
  const PreparedTrajectory p = prepared(tr, cfg);
  for (std::size_t i = 0; i < p.samples.size(); ++i) EXPECT_EQ(p.samples[i].stabilizer, sch.sample_on[i]);
}

TEST(Hrp2Stabilizer, SittingStartIsOffFromTheFirstSample) {
  const StabilizerSchedule sch = scheduleStabilizer(synthetic(), *chair().robot, *chair().scene, BridgeConfig{});
  for (bool on : sch.sample_on) EXPECT_FALSE(on);
  ASSERT_EQ(sch.switches.size(), 1u);
  EXPECT_EQ(sch.switches[0].t, 0.0);
}

// ---------------------------------------------------------------- references

TEST(Hrp2References, CoplanarFeetZmpIsTheComProjection) {
  const Scenario& sc = chair();
  ReferenceModel refs(sc.robot, sc.scene);
  Configuration q = sc.robot->posture("half_sitting");
  q.base_position.x() += 0.3;
  q.base_orientation = rpyToQuaternion(Eigen::Vector3d(0, 0, 0.4));
  const WaistZmp r = refs.compute(q, {contact("r_sole", "floor", true), contact("l_sole", "floor", true)}, true);
  Kinematics kin(sc.robot);
  kin.setConfiguration(q);
  const Eigen::Vector3d com = kin.centerOfMass();
  EXPECT_NEAR(r.zmp_world.x(), com.x(), 1e-12);
  EXPECT_NEAR(r.zmp_world.y(), com.y(), 1e-12);
  EXPECT_NEAR(r.zmp_world.z(), 0.0, 1e-12);
  EXPECT_FALSE(r.from_forces);
  // In the waist frame: the waist pose maps it back to the world.
  EXPECT_LT((q.basePose() * r.zmp_waist - r.zmp_world).norm(), 1e-12);
  EXPECT_NEAR(r.waist_rpy.z(), 0.4, 1e-12);
  EXPECT_EQ(r.waist_position, q.base_position);
}

TEST(Hrp2References, WithThighsOnTheSeatZmpIsTheFeetCentreOfPressure) {
  const Scenario& sc = chair();
  ReferenceModel refs(sc.robot, sc.scene);
  const WaistZmp r = refs.compute(sc.start, sc.start_stance, false);
  ASSERT_TRUE(r.from_forces);
  EXPECT_FALSE(r.lp_failed);
  EXPECT_NEAR(r.zmp_world.z(), 0.0, 1e-9);
  // Inside the box around the feet's corners (positive normal forces).
  Kinematics kin(sc.robot);
  kin.setConfiguration(sc.start);
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const char* f : {"r_sole", "l_sole"}) {
    const int spot = sc.robot->spotIndex(f);
    for (const auto& v : sc.robot->spots()[spot].polygon.vertices()) {
      const Eigen::Vector3d w = kin.spotPose(spot) * Eigen::Vector3d(v.x(), v.y(), 0);
      lo = lo.cwiseMin(w.head<2>());
      hi = hi.cwiseMax(w.head<2>());
    }
  }
  EXPECT_GE(r.zmp_world.x(), lo.x());
  EXPECT_LE(r.zmp_world.x(), hi.x());
  EXPECT_GE(r.zmp_world.y(), lo.y());
  EXPECT_LE(r.zmp_world.y(), hi.y());
  // Not the CoM projection: the seat carries most of the weight, the CoM is behind the feet.
  EXPECT_GT(std::abs(r.zmp_world.x() - kin.centerOfMass().x()), 0.02);
}

// ---------------------------------------------------------------- state machine

namespace {

constexpr std::int64_t kPeriod = 5000;  // us

// The bridge against a robot that applies every command at once (the state
// it reports at the next period is the last command).
struct Rig {
  Bridge bridge;
  MeasuredState robot;
  std::int64_t now = 10'000'000;
  std::vector<Command> sent;
  bool robot_alive = true;
  bool robot_acks = true;

  explicit Rig(BridgeConfig cfg = {}) : bridge(chair().robot, cfg) {
    robot.q = chair().start.joints;
    robot.dq = Eigen::VectorXd::Zero(robot.q.size());
    period();
  }
  void period() {
    now += kPeriod;
    if (robot_alive) bridge.onState(robot, now);
    if (auto c = bridge.tick(now)) {
      sent.push_back(*c);
      if (robot_acks) {
        robot.dq = (c->q - robot.q) / (kPeriod * 1e-6);
        robot.q = c->q;
        robot.command_sequence = c->sequence;
        robot.request_id = c->request_id;
      }
    } else {
      robot.dq.setZero();
    }
  }
  void periods(int n) {
    for (int i = 0; i < n; ++i) period();
  }
  bool load(const Trajectory& tr, std::int64_t id, const BridgeConfig& cfg = {}) {
    if (!bridge.beginCheck(id, now)) return false;
    bridge.endCheck(id, prepareTrajectory(tr, chair().robot, chair().scene, cfg), now);
    return bridge.state() == BridgeState::Streaming;
  }
};

}  // namespace

TEST(Hrp2Bridge, StreamsEveryPreparedSampleOncePerPeriodThenIdles) {
  Rig rig;
  EXPECT_EQ(rig.bridge.state(), BridgeState::Idle);
  EXPECT_TRUE(rig.sent.empty()) << "idle: nothing is commanded";
  const Trajectory tr = synthetic(0.5);
  ASSERT_TRUE(rig.load(tr, 7)) << rig.bridge.status(rig.now).reason;
  const PreparedTrajectory& p = rig.bridge.trajectory();
  rig.periods(static_cast<int>(p.samples.size()) + 5);
  ASSERT_EQ(rig.sent.size(), p.samples.size());
  for (std::size_t i = 0; i < p.samples.size(); ++i) {
    EXPECT_EQ(rig.sent[i].q, p.samples[i].q);
    EXPECT_EQ(rig.sent[i].request_id, 7);
    EXPECT_EQ(rig.sent[i].mode, CommandMode::Stream);
    EXPECT_EQ(rig.sent[i].stabilizer, p.samples[i].stabilizer);
    EXPECT_EQ(rig.sent[i].zmp_waist, p.samples[i].zmp_waist);
    if (i > 0) {
      EXPECT_EQ(rig.sent[i].sequence, rig.sent[i - 1].sequence + 1);
      EXPECT_EQ(rig.sent[i].utime - rig.sent[i - 1].utime, kPeriod);
    }
  }
  EXPECT_TRUE(rig.sent.back().dq.isZero());
  const BridgeStatus st = rig.bridge.status(rig.now);
  EXPECT_EQ(st.state, BridgeState::Idle);
  EXPECT_DOUBLE_EQ(st.progress, 1.0);
  EXPECT_EQ(st.safety_events, 0);
  EXPECT_NE(st.reason.find("done"), std::string::npos) << st.reason;
  const auto events = rig.bridge.takeEvents();
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.back().done);
  EXPECT_EQ(events.back().request_id, 7);
}

TEST(Hrp2Bridge, StaleStateHoldsWithinThreePeriods) {
  Rig rig;
  ASSERT_TRUE(rig.load(synthetic(1.0), 1));
  rig.periods(40);
  const std::int64_t last_state = rig.now;  // the state of this period was the last
  rig.robot_alive = false;
  const std::size_t before = rig.sent.size();
  rig.periods(6);
  ASSERT_EQ(rig.bridge.state(), BridgeState::Holding);
  std::size_t first_hold = before;
  while (rig.sent[first_hold].mode != CommandMode::Hold) ++first_hold;
  EXPECT_LE(rig.sent[first_hold].utime - last_state, 3 * kPeriod);
  // It holds the last streamed posture, still, and says why.
  EXPECT_EQ(rig.sent[first_hold].q, rig.sent[first_hold - 1].q);
  EXPECT_TRUE(rig.sent[first_hold].dq.isZero());
  EXPECT_EQ(rig.sent.back().mode, CommandMode::Hold);
  const BridgeStatus st = rig.bridge.status(rig.now);
  EXPECT_EQ(st.safety_events, 1);
  EXPECT_FALSE(st.state_fresh);
  EXPECT_NE(st.reason.find("stale"), std::string::npos) << st.reason;
  // The state comes back: still holding (the interrupted motion is dropped).
  rig.robot_alive = true;
  rig.periods(5);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Holding);
}

TEST(Hrp2Bridge, ABridgeThatWasItselfStalledDoesNotBlameTheRobot) {
  Rig rig;
  ASSERT_TRUE(rig.load(synthetic(1.0), 1));
  rig.periods(20);
  // The bridge does not run for 30 ms (the machine stalled); the robot's
  // states were queued meanwhile and arrive just after its next tick.
  rig.now += 30000 - kPeriod;
  rig.robot_alive = false;
  rig.period();
  EXPECT_EQ(rig.bridge.state(), BridgeState::Streaming);
  EXPECT_EQ(rig.bridge.lateTicks(), 1);
  rig.robot_alive = true;
  rig.periods(5);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Streaming);
  // But a robot that stays silent is caught once the bridge has listened on
  // time for the whole timeout (two more periods here).
  rig.now += 30000 - kPeriod;
  rig.robot_alive = false;
  rig.periods(3);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Holding);
}

TEST(Hrp2Bridge, AControllerThatStopsApplyingCommandsIsAStall) {
  BridgeConfig cfg;
  cfg.stall_timeout = 0.03;
  Rig rig(cfg);
  ASSERT_TRUE(rig.load(synthetic(1.0), 1));
  rig.periods(20);
  rig.robot_acks = false;  // states keep coming, the acknowledged sequence stops
  const std::int64_t stop = rig.now + kPeriod;  // the last new acknowledgement arrives then
  rig.periods(10);
  ASSERT_EQ(rig.bridge.state(), BridgeState::Holding);
  std::size_t first_hold = 0;
  while (rig.sent[first_hold].mode != CommandMode::Hold) ++first_hold;
  EXPECT_GT(rig.sent[first_hold].utime - stop, 30000 - kPeriod);
  EXPECT_LE(rig.sent[first_hold].utime - stop, 30000 + kPeriod);
  EXPECT_NE(rig.bridge.status(rig.now).reason.find("stalled"), std::string::npos);
}

TEST(Hrp2Bridge, EstopFreezesAndReleaseBlendsBackToTheEnd) {
  BridgeConfig cfg;
  cfg.release_blend = 0.5;
  Rig rig(cfg);
  const Trajectory tr = synthetic(1.0);
  ASSERT_TRUE(rig.load(tr, 3, cfg));
  rig.periods(100);  // mid-motion: 0.5 s of 1 s
  const Command last_stream = rig.sent.back();
  const double progress = rig.bridge.status(rig.now).progress;
  rig.bridge.onEstop(true, "operator", rig.now);
  rig.periods(40);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Stopped);
  for (std::size_t i = rig.sent.size() - 40; i < rig.sent.size(); ++i) {
    EXPECT_EQ(rig.sent[i].mode, CommandMode::Freeze);
    EXPECT_EQ(rig.sent[i].q, last_stream.q);
    EXPECT_TRUE(rig.sent[i].dq.isZero());
  }
  EXPECT_EQ(rig.bridge.status(rig.now).progress, progress);
  // A trajectory is refused while stopped.
  EXPECT_FALSE(rig.bridge.beginCheck(4, rig.now));
  rig.bridge.onEstop(false, "operator", rig.now);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Streaming);
  const std::size_t resume = rig.sent.size();
  rig.periods(400);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Idle);
  // Speed ramps up: the steps grow from nothing to the trajectory's own, and
  // the motion ends where the trajectory ends.
  const double first_step = (rig.sent[resume].q - last_stream.q).cwiseAbs().maxCoeff();
  const double plain_step = (tr.samples[101].q.joints - tr.samples[100].q.joints).cwiseAbs().maxCoeff();
  EXPECT_LT(first_step, 0.05 * plain_step);
  for (std::size_t i = resume + 1; i < rig.sent.size(); ++i)
    EXPECT_LE((rig.sent[i].q - rig.sent[i - 1].q).cwiseAbs().maxCoeff(), plain_step * 1.05 + 1e-12);
  EXPECT_LT((rig.sent.back().q - tr.samples.back().q.joints).norm(), 1e-12);
  // Blending took longer than plain playback of the rest (0.5 s): by about
  // half the blend time.
  std::size_t streamed = 0;
  for (std::size_t i = resume; i < rig.sent.size(); ++i) streamed += rig.sent[i].mode == CommandMode::Stream;
  EXPECT_NEAR(streamed * 0.005, 0.5 + 0.25, 0.02);
  EXPECT_EQ(rig.bridge.status(rig.now).safety_events, 2);  // engage, release
}

TEST(Hrp2Bridge, EstopWhileIdleFreezesWhereTheRobotStands) {
  Rig rig;
  rig.robot.q[20] += 0.01;  // not the start posture: the measured one counts
  rig.period();
  rig.bridge.onEstop(true, "", rig.now);
  rig.periods(3);
  ASSERT_EQ(rig.sent.size(), 3u);
  for (const Command& c : rig.sent) {
    EXPECT_EQ(c.mode, CommandMode::Freeze);
    EXPECT_EQ(c.q, rig.robot.q);
  }
  rig.bridge.onEstop(false, "", rig.now);
  rig.periods(3);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Idle);
  EXPECT_EQ(rig.sent.size(), 3u) << "idle again: nothing commanded";
}

TEST(Hrp2Bridge, NanOrLimitViolationIsRefusedAndNothingMoves) {
  Rig rig;
  Trajectory bad = synthetic(0.5);
  bad.samples[50].q.joints[5] = std::nan("");
  EXPECT_FALSE(rig.load(bad, 11));
  const double range = chair().robot->upperLimits()[14] - chair().start.joints[14];
  EXPECT_FALSE(rig.load(synthetic(4.0, 14, range + 0.05), 12));
  rig.periods(20);
  EXPECT_TRUE(rig.sent.empty());
  const BridgeStatus st = rig.bridge.status(rig.now);
  EXPECT_EQ(st.state, BridgeState::Idle);
  EXPECT_EQ(st.safety_events, 2);
  EXPECT_NE(st.reason.find("refused request 12"), std::string::npos) << st.reason;
  EXPECT_NE(st.reason.find("HEAD_JOINT0"), std::string::npos) << st.reason;
  const auto events = rig.bridge.takeEvents();
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.back().refused);
  EXPECT_EQ(events.back().request_id, 12);
  // A good one afterwards goes.
  EXPECT_TRUE(rig.load(synthetic(0.5), 13));
}

TEST(Hrp2Bridge, ASecondTrajectoryWhileStreamingIsRefusedNotQueued) {
  Rig rig;
  ASSERT_TRUE(rig.load(synthetic(0.5), 1));
  rig.periods(20);
  std::string why;
  EXPECT_FALSE(rig.bridge.beginCheck(2, rig.now, &why));
  EXPECT_NE(why.find("not queued"), std::string::npos) << why;
  rig.periods(200);
  for (const Command& c : rig.sent) EXPECT_EQ(c.request_id, 1);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Idle);
  // Idle again: the next one is taken (it starts where the first ended).
  Trajectory back = synthetic(0.5);
  std::reverse(back.samples.begin(), back.samples.end());
  for (std::size_t i = 0; i < back.samples.size(); ++i) back.samples[i].t = 0.005 * i, back.samples[i].dq *= -1;
  EXPECT_TRUE(rig.load(back, 2)) << rig.bridge.status(rig.now).reason;
}

TEST(Hrp2Bridge, StartGuardAndStartJump) {
  {  // The start posture differs from the measured one.
    Rig rig;
    rig.robot.q[16] += 0.1;
    rig.period();
    EXPECT_FALSE(rig.load(synthetic(0.5), 1));
    EXPECT_NE(rig.bridge.status(rig.now).reason.find("refusing to jump"), std::string::npos);
  }
  {  // The robot is moving: something else drives it.
    Rig rig;
    rig.robot.dq[3] = 0.2;
    rig.period();
    EXPECT_FALSE(rig.load(synthetic(0.5), 1));
    EXPECT_NE(rig.bridge.status(rig.now).reason.find("moving"), std::string::npos);
  }
  {  // Another source's commands are being applied.
    Rig rig;
    rig.robot.command_sequence = 500, rig.robot.request_id = 99;
    rig.period();
    rig.robot.command_sequence = 501;
    rig.period();
    EXPECT_FALSE(rig.load(synthetic(0.5), 1));
    EXPECT_NE(rig.bridge.status(rig.now).reason.find("not from this bridge"), std::string::npos);
    rig.periods(110);  // 0.55 s quiet: accepted
    EXPECT_TRUE(rig.load(synthetic(0.5), 1)) << rig.bridge.status(rig.now).reason;
  }
  {  // Servo off, and no state at all.
    Rig rig;
    rig.robot.servo_on = false;
    rig.period();
    EXPECT_FALSE(rig.load(synthetic(0.5), 1));
    Rig dead;
    dead.robot_alive = false;
    dead.periods(3);
    EXPECT_FALSE(dead.load(synthetic(0.5), 1));
  }
}

TEST(Hrp2Bridge, TrackingErrorBeyondTheLimitFaultsAndEstopResets) {
  Rig rig;
  ASSERT_TRUE(rig.load(synthetic(1.0), 1));
  rig.periods(10);
  rig.robot.q[14] += 0.2;  // the robot is pushed away
  rig.periods(2);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Fault);
  EXPECT_EQ(rig.sent.back().mode, CommandMode::Hold);
  EXPECT_FALSE(rig.bridge.beginCheck(2, rig.now));
  rig.bridge.onEstop(true, "reset", rig.now);
  rig.bridge.onEstop(false, "reset", rig.now);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Idle);
}

TEST(Hrp2Bridge, BadMeasuredStateWhileStreamingFaults) {
  Rig rig;
  ASSERT_TRUE(rig.load(synthetic(1.0), 1));
  rig.periods(10);
  MeasuredState bad = rig.robot;
  bad.q[2] = std::nan("");
  rig.bridge.onState(bad, rig.now + 1);
  EXPECT_EQ(rig.bridge.state(), BridgeState::Fault);
}

TEST(Hrp2Bridge, SameInputsSameCommands) {
  auto run = [] {
    Rig rig;
    rig.load(synthetic(0.3), 1);
    rig.periods(30);
    rig.bridge.onEstop(true, "", rig.now);
    rig.periods(5);
    rig.bridge.onEstop(false, "", rig.now);
    rig.periods(200);
    return rig.sent;
  };
  const auto a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].q, b[i].q);
    EXPECT_EQ(a[i].sequence, b[i].sequence);
    EXPECT_EQ(a[i].mode, b[i].mode);
  }
}

TEST(Hrp2Bridge, ConfigFileFieldsAreNamedOnError) {
  test::TempDir dir;
  const BridgeConfig c = BridgeConfig::load(dir.write("ok.yaml", "format: acyclic.hrp2_bridge/1\ndt: 0.004\n"));
  EXPECT_EQ(c.dt, 0.004);
  try {
    BridgeConfig::load(dir.write("bad.yaml", "format: acyclic.hrp2_bridge/1\nvelocity_margin: 1.5\n"));
    FAIL() << "accepted a velocity margin of 1.5";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "velocity_margin");
  }
  EXPECT_THROW(BridgeConfig::load(dir.write("typo.yaml", "format: acyclic.hrp2_bridge/1\ndtt: 0.004\n")), FormatError);
  EXPECT_FALSE(BridgeConfig::load(dir.write("nc.yaml", "format: acyclic.hrp2_bridge/1\ncheck_contract: false\n")).check_contract);
  try {
    BridgeConfig::load(dir.write("nb.yaml", "format: acyclic.hrp2_bridge/1\ncheck_contract: maybe\n"));
    FAIL() << "accepted check_contract: maybe";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "check_contract");
  }
}

// ---------------------------------------------------------------- export

namespace {
std::vector<std::vector<double>> readRows(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::vector<double> r;
    double v;
    while (ls >> v) r.push_back(v);
    EXPECT_TRUE(ls.eof()) << path << ": not a number in '" << line << "'";
    rows.push_back(r);
  }
  return rows;
}
}  // namespace

TEST(Hrp2Export, SequencePlayerFilesParseBackWithColumnsRateAndContinuity) {
  const Trajectory tr = synthetic(1.0, 16, -0.3, 0.01);  // the trajectory at 10 ms: resampled to 5 ms
  const PreparedTrajectory p = prepared(tr);
  test::TempDir dir;
  const auto files = writeSequencePlayer(p, dir.path() + "/motion");
  ASSERT_EQ(files.size(), 3u);
  const auto pos = readRows(dir.path() + "/motion.pos");
  const auto waist = readRows(dir.path() + "/motion.waist");
  const auto zmp = readRows(dir.path() + "/motion.zmp");
  ASSERT_EQ(pos.size(), 201u);
  ASSERT_EQ(waist.size(), pos.size());
  ASSERT_EQ(zmp.size(), pos.size());
  const Eigen::VectorXd vmax = chair().robot->velocityLimits();
  for (std::size_t i = 0; i < pos.size(); ++i) {
    ASSERT_EQ(pos[i].size(), 31u);
    ASSERT_EQ(waist[i].size(), 7u);
    ASSERT_EQ(zmp[i].size(), 4u);
    EXPECT_NEAR(pos[i][0], 0.005 * i, 1e-9);
    EXPECT_EQ(waist[i][0], pos[i][0]);
    EXPECT_EQ(zmp[i][0], pos[i][0]);
    // The file holds the interpolated trajectory (1e-8: 9 decimals).
    const TrajectorySample s = sampleAt(tr, 0.005 * i);
    for (int j = 0; j < 30; ++j) EXPECT_NEAR(pos[i][1 + j], s.q.joints[j], 1e-8);
    // The ZMP row in the waist frame maps back onto the floor.
    const Eigen::Isometry3d w = s.q.basePose();
    const Eigen::Vector3d zw = w * Eigen::Vector3d(zmp[i][1], zmp[i][2], zmp[i][3]);
    EXPECT_NEAR(zw.z(), 0.0, 1e-8);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(waist[i][1 + k], s.q.base_position[k], 1e-8);
    if (i == 0) continue;
    for (int j = 0; j < 30; ++j) EXPECT_LE(std::abs(pos[i][1 + j] - pos[i - 1][1 + j]), vmax[j] * 0.005 + 1e-8);
    EXPECT_LT((Eigen::Vector3d(zmp[i][1], zmp[i][2], zmp[i][3]) -
               Eigen::Vector3d(zmp[i - 1][1], zmp[i - 1][2], zmp[i - 1][3])).norm(), 0.005)
        << "ZMP jumps at row " << i;
  }
  EXPECT_EQ(p.zmp_lp_failures, 0);
  EXPECT_EQ(p.zmp_from_forces, static_cast<int>(p.samples.size()));
  // Same input, same files, byte for byte.
  writeSequencePlayer(prepared(tr), dir.path() + "/again");
  for (const char* ext : {".pos", ".waist", ".zmp"})
    EXPECT_EQ(test::readFile(dir.path() + "/motion" + ext), test::readFile(dir.path() + "/again" + ext)) << ext;
}

// ---------------------------------------------------------------- simulator

namespace {
SimCommand toSim(const Command& c) {
  SimCommand s;
  s.request_id = c.request_id, s.sequence = c.sequence, s.mode = static_cast<int>(c.mode);
  s.q = c.q, s.dq = c.dq, s.waist_position = c.waist_position, s.waist_rpy = c.waist_rpy;
  s.stabilizer = c.stabilizer;
  return s;
}
}  // namespace

TEST(Hrp2Sim, ContactForcesAtTheStartCarryTheWeight) {
  const Scenario& sc = chair();
  ContactForces cf(sc.robot, sc.scene);
  const auto found = cf.detect(sc.start);
  std::vector<std::string> names;
  for (const auto& c : found) names.push_back(sc.robot->spots()[c.spot].name);
  EXPECT_EQ(found.size(), 4u) << testing::PrintToString(names);
  bool eq = false;
  const auto w = cf.compute(sc.start, &eq);
  ASSERT_TRUE(eq);
  Kinematics kin(sc.robot);
  kin.setConfiguration(sc.start);
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < w.size(); ++i)
    total += kin.spotPose(found[i].spot).linear() * w[i].wrench.head<3>();
  EXPECT_NEAR(total.z(), sc.robot->totalMass() * 9.81, 1e-3 * sc.robot->totalMass() * 9.81);
  EXPECT_NEAR(total.head<2>().norm(), 0.0, 1e-3);
}

TEST(Hrp2Sim, TracksWithLatencyDropsAndFreezes) {
  const Scenario& sc = chair();
  SimOptions o;
  o.latency = 0.02;
  SimulatedController sim(sc.robot, sc.start, o);
  SimCommand c;
  c.q = sc.start.joints;
  c.q[14] += 0.1;
  c.dq = Eigen::VectorXd::Zero(30);
  c.sequence = 1;
  c.mode = 1;  // hold: the base stays
  std::int64_t now = 0;
  sim.receive(c, now);
  for (int i = 0; i < 3; ++i) sim.step(now += 5000);
  EXPECT_EQ(sim.state().command_sequence, -1) << "latency: not applied yet";
  EXPECT_EQ(sim.state().q[14], sc.start.joints[14]);
  for (int i = 0; i < 100; ++i) sim.step(now += 5000);
  EXPECT_EQ(sim.state().command_sequence, 1);
  EXPECT_NEAR(sim.state().q[14], c.q[14], 1e-4);  // 0.5 s = 25 time constants
  EXPECT_EQ(sim.state().configuration.base_position, sc.start.base_position);
  // A NaN command is ignored (counted), never applied.
  SimCommand bad = c;
  bad.q[3] = std::nan("");
  sim.receive(bad, now);
  EXPECT_EQ(sim.rejected(), 1);

  SimOptions d;
  d.drop_rate = 0.3;
  d.freeze_after = 1.0;
  SimulatedController lossy(sc.robot, sc.start, d);
  now = 0;
  for (int i = 0; i < 400; ++i) {
    c.sequence = i;
    lossy.receive(c, now);
    lossy.step(now += 5000);
  }
  EXPECT_TRUE(lossy.frozen(now));
  EXPECT_GT(lossy.dropped(), 40);
  EXPECT_LT(lossy.dropped(), 80);  // about 30% of the 200 before the freeze
  EXPECT_LT(lossy.state().command_sequence, 200);
}

TEST(Hrp2Sim, BridgeAndSimulatorEndToEndTrackingErrorIsSmall) {
  const Scenario& sc = chair();
  Bridge bridge(sc.robot, BridgeConfig{});
  SimulatedController sim(sc.robot, sc.start, SimOptions{});
  std::int64_t now = 0;
  auto period = [&] {
    now += kPeriod;
    sim.step(now);
    const SimState s = sim.state();
    MeasuredState m;
    m.q = s.q, m.dq = s.dq, m.request_id = s.request_id, m.command_sequence = s.command_sequence;
    m.servo_on = s.servo_on;
    bridge.onState(m, now);
    if (auto c = bridge.tick(now)) sim.receive(toSim(*c), now);
  };
  period();
  const Trajectory tr = synthetic(1.0, 16, -0.4);
  ASSERT_TRUE(bridge.beginCheck(1, now));
  bridge.endCheck(1, prepareTrajectory(tr, sc.robot, sc.scene, BridgeConfig{}), now);
  ASSERT_EQ(bridge.state(), BridgeState::Streaming) << bridge.status(now).reason;
  for (int i = 0; i < 260; ++i) period();
  const BridgeStatus st = bridge.status(now);
  EXPECT_EQ(st.state, BridgeState::Idle) << st.reason;
  EXPECT_EQ(st.safety_events, 0);
  // First-order tracking with feed-forward: the error is the one-period lag
  // of the acknowledged command, well under a hundredth of a radian here.
  EXPECT_GT(st.tracking_error_max, 0.0);
  EXPECT_LT(st.tracking_error_max, 0.01);
  EXPECT_NEAR(sim.state().q[16], tr.samples.back().q.joints[16], 1e-3);
}

TEST(Hrp2Sim, CommandsBeyondPositionOrVelocityLimitsAreRefusedAndCountedAndNoJointPassesItsLimits) {
  const Scenario& sc = chair();
  SimulatedController sim(sc.robot, sc.start, SimOptions{});
  const int chest = sc.robot->jointIndex("CHEST_JOINT0");
  ASSERT_GE(chest, 0);
  const double upper = sc.robot->upperLimits()[chest], vmax = sc.robot->velocityLimits()[chest];
  SimCommand c;
  c.q = sc.start.joints;
  c.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
  c.mode = 1;
  std::int64_t now = 0;
  // A foreign command driving the chest to 1.5 rad, past its limit.
  SimCommand far = c;
  far.q[chest] = 1.5;
  ASSERT_GT(1.5, upper);
  sim.receive(far, now);
  for (int i = 0; i < 100; ++i) sim.step(now += 5000);
  EXPECT_EQ(sim.refusedPosition(), 1);
  EXPECT_EQ(sim.applied(), 0);
  EXPECT_EQ(sim.state().q[chest], sc.start.joints[chest]);
  // A velocity beyond the limit.
  SimCommand fast = c;
  fast.dq[chest] = 1.5 * vmax;
  sim.receive(fast, now);
  sim.step(now += 5000);
  EXPECT_EQ(sim.refusedVelocity(), 1);
  EXPECT_EQ(sim.applied(), 0);
  // At the limit, with the largest velocity feed-forward allowed outwards: the
  // first-order law alone would settle T * vmax past the limit; the joint stops.
  SimCommand edge = c;
  edge.q[chest] = upper;
  edge.dq[chest] = vmax;
  for (int i = 0; i < 200; ++i) {
    edge.sequence = i;
    sim.receive(edge, now);
    sim.step(now += 5000);
    ASSERT_LE(sim.state().q[chest], upper) << "period " << i;
  }
  EXPECT_NEAR(sim.state().q[chest], upper, 1e-9);
  EXPECT_EQ(sim.refusedPosition(), 1);
  EXPECT_EQ(sim.refusedVelocity(), 1);
  EXPECT_EQ(sim.applied(), 200);
}

TEST(Hrp2Sim, HoldsTheLastCommandedPostureWhenTheCommandStreamStops) {
  const Scenario& sc = chair();
  auto run = [&](int hold_after) {
    SimOptions o;
    o.hold_after_missed = hold_after;
    auto sim = std::make_unique<SimulatedController>(sc.robot, sc.start, o);
    SimCommand c;
    c.q = sc.start.joints;
    c.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
    c.mode = 1;
    std::int64_t now = 0;
    // A stream moving an arm joint at 0.5 rad/s, then silence (the bridge died).
    for (int i = 0; i < 50; ++i) {
      c.sequence = i;
      c.q[16] = sc.start.joints[16] - 0.5 * 0.005 * i;
      c.dq[16] = -0.5;
      sim->receive(c, now);
      sim->step(now += 5000);
    }
    for (int i = 0; i < 19; ++i) sim->step(now += 5000);
    EXPECT_FALSE(sim->holdingForMissedCommands()) << "not before " << hold_after << " periods";
    for (int i = 0; i < 200; ++i) sim->step(now += 5000);
    return std::make_pair(std::move(sim), c.q[16]);
  };
  auto [held, last_ref] = run(20);
  EXPECT_TRUE(held->holdingForMissedCommands());
  EXPECT_EQ(held->missedHolds(), 1);
  EXPECT_NEAR(held->state().q[16], last_ref, 1e-6) << "holds the last commanded posture";
  EXPECT_LT(held->state().dq.cwiseAbs().maxCoeff(), 1e-6);
  // Without the hold the stale feed-forward keeps the joint T * 0.5 rad/s past it.
  auto [free_running, ref] = run(0);
  EXPECT_EQ(free_running->missedHolds(), 0);
  EXPECT_GT(std::abs(free_running->state().q[16] - ref), 5e-3);
  // A new command ends the hold.
  SimCommand c;
  c.q = held->state().q;
  c.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
  held->receive(c, 2'000'000);
  held->step(2'005'000);
  EXPECT_FALSE(held->holdingForMissedCommands());
}
