// Plans and trajectories through their LCM messages and back (encoded and
// decoded, as on the wire): nothing lost, unknown names refused by field.
#include <gtest/gtest.h>

#include <vector>

#include "planner/common/format_error.h"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"
#ifdef ACYCLIC_HAVE_INTERPOLATOR
#include "processes/transitions_message.h"
#endif
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& chair() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

template <class Msg>
Msg wire(const Msg& m) {
  std::vector<char> buf(m.getEncodedSize());
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  Msg back;
  EXPECT_EQ(back.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return back;
}

}  // namespace

TEST(LcmConvert, PlanRoundTrip) {
  const Scenario& sc = chair();
  Plan plan;
  PlanStance s;
  s.configuration = sc.start;
  s.configuration.joints[5] = 0.123456789012345;
  for (const auto& spec : sc.start_stance) {
    PlanContact c;
    c.spec = spec;
    c.frame = contactFrame(sc.scene->surfaces()[spec.surface], spec.placement);
    c.points = {Eigen::Vector3d(0.1, 0.2, 0.0), Eigen::Vector3d(0.3, 0.2, 0.0)};
    c.forces = {Eigen::Vector3d(1, 2, 100), Eigen::Vector3d(-1, 0, 50)};
    s.contacts.push_back(c);
  }
  s.potential = 1.5;
  plan.stances = {s, s};
  plan.stances[1].contacts[3].spec.supporting = false;
  plan.stances[1].contacts[3].points.clear();
  plan.stances[1].contacts[3].forces.clear();
  plan.stats = {12, 5, 30, 4, 2.5};

  const Plan back = convert::fromMessage(wire(convert::toMessage(plan, sc)), sc);
  ASSERT_EQ(back.stances.size(), 2u);
  EXPECT_EQ(back.stances[0].configuration.joints, plan.stances[0].configuration.joints);
  EXPECT_EQ(back.stances[0].configuration.base_position, plan.stances[0].configuration.base_position);
  EXPECT_FALSE(back.stances[1].contacts[3].spec.supporting);
  EXPECT_TRUE(back.stances[1].contacts[3].forces.empty());
  EXPECT_EQ(back.stances[0].contacts[1].forces, plan.stances[0].contacts[1].forces);
  EXPECT_EQ(back.stances[0].contacts[2].spec.placement.theta, plan.stances[0].contacts[2].spec.placement.theta);
  EXPECT_EQ(back.stats.posture_calls, 30);
  EXPECT_EQ(back.stats.nodes_generated, 12);

  plan_t bad = convert::toMessage(plan, sc);
  bad.stances[1].contacts[0].spot = "r_foot";
  try {
    convert::fromMessage(bad, sc);
    FAIL() << "accepted an unknown spot";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "stances[1].contacts[0].spot");
  }
  bad = convert::toMessage(plan, sc);
  bad.joint_names[0] = "HEAD";
  EXPECT_THROW(convert::fromMessage(bad, sc), FormatError);
}

TEST(LcmConvert, TrajectoryRoundTrip) {
  const Scenario& sc = chair();
  Trajectory tr;
  tr.dt = 0.005;
  TrajectoryPhase p;
  p.contacts = sc.start_stance;
  p.t_start = 0, p.t_end = 0.005, p.stance = 0;
  tr.phases = {p, p};
  tr.phases[1].contacts.pop_back();
  tr.phases[1].t_start = 0.005, tr.phases[1].t_end = 0.01, tr.phases[1].stance = 2;
  for (int i = 0; i < 3; ++i) {
    TrajectorySample s;
    s.t = 0.005 * i;
    s.q = sc.start;
    s.q.joints[1] += 0.001 * i;
    s.dq = Eigen::VectorXd::Constant(sc.robot->numJoints(), 0.2 * i);
    s.phase = i == 2 ? 1 : 0;
    tr.samples.push_back(s);
  }
  const Trajectory back = convert::fromMessage(wire(convert::toMessage(tr, sc)), sc);
  ASSERT_EQ(back.samples.size(), 3u);
  ASSERT_EQ(back.phases.size(), 2u);
  EXPECT_EQ(back.phases[1].contacts.size(), 3u);
  EXPECT_EQ(back.phases[1].stance, 2);
  EXPECT_EQ(back.phases[0].contacts[2].placement.x, sc.start_stance[2].placement.x);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(back.samples[i].q.joints, tr.samples[i].q.joints);
    EXPECT_EQ(back.samples[i].dq, tr.samples[i].dq);
    EXPECT_EQ(back.samples[i].phase, tr.samples[i].phase);
  }
  trajectory_t bad = convert::toMessage(tr, sc);
  bad.phase[2] = 7;
  EXPECT_THROW(convert::fromMessage(bad, sc), FormatError);
  bad = convert::toMessage(tr, sc);
  bad.joints[1][4] = std::nan("");
  EXPECT_THROW(convert::fromMessage(bad, sc), FormatError);
}

// HRP-2's enums, value by value: every value there and back, and a value the
// other side does not know refused (message to enum) or mapped to the safest
// value (enum to message), never cast.
TEST(LcmConvert, BridgeStateEveryValueRoundTrips) {
  using S = hrp2::BridgeState;
  const std::vector<std::pair<S, int8_t>> pairs = {
      {S::Idle, +hrp2_bridge_status_t::IDLE},         {S::Checking, +hrp2_bridge_status_t::CHECKING},
      {S::Streaming, +hrp2_bridge_status_t::STREAMING}, {S::Holding, +hrp2_bridge_status_t::HOLDING},
      {S::Stopped, +hrp2_bridge_status_t::STOPPED},   {S::Fault, +hrp2_bridge_status_t::FAULT}};
  for (const auto& [state, constant] : pairs) {
    EXPECT_EQ(convert::toMessage(state), constant) << static_cast<int>(state);
    EXPECT_EQ(convert::bridgeStateFromMessage(constant), state) << int(constant);
  }
  try {
    convert::bridgeStateFromMessage(6);
    FAIL() << "an unknown state was accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "state");
    EXPECT_NE(std::string(e.what()).find("got 6"), std::string::npos) << e.what();
  }
  EXPECT_THROW(convert::bridgeStateFromMessage(-1), FormatError);
  EXPECT_EQ(convert::toMessage(static_cast<S>(42)), +hrp2_bridge_status_t::FAULT);
}

TEST(LcmConvert, CommandModeEveryValueRoundTrips) {
  using M = hrp2::CommandMode;
  const std::vector<std::pair<M, int8_t>> pairs = {
      {M::Stream, +hrp2_command_t::STREAM}, {M::Hold, +hrp2_command_t::HOLD}, {M::Freeze, +hrp2_command_t::FREEZE}};
  for (const auto& [mode, constant] : pairs) {
    EXPECT_EQ(convert::toMessage(mode), constant);
    EXPECT_EQ(convert::commandModeFromMessage(constant), mode);
  }
  try {
    convert::commandModeFromMessage(3);
    FAIL() << "an unknown mode was accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), "mode");
  }
  EXPECT_EQ(convert::toMessage(static_cast<M>(42)), +hrp2_command_t::FREEZE);
}

TEST(LcmConvert, Hrp2MessagesThereAndBack) {
  // The bridge's command, as the simulated controller reads it.
  hrp2::Command c;
  c.request_id = 7, c.sequence = 12, c.mode = hrp2::CommandMode::Hold;
  c.q = Eigen::VectorXd::LinSpaced(4, 0.1, 0.4);
  c.dq = Eigen::VectorXd::Constant(4, -0.5);
  c.waist_position = {1, 2, 3}, c.waist_rpy = {0.1, 0.2, 0.3}, c.zmp_waist = {4, 5, 6};
  c.stabilizer = false;
  const hrp2_command_t cm = wire(convert::toMessage(c, 99));
  EXPECT_EQ(cm.utime, 99);
  EXPECT_EQ(cm.mode, +hrp2_command_t::HOLD);
  EXPECT_EQ(cm.zmp_waist[2], 6);
  const hrp2::SimCommand sc = convert::fromMessage(cm);
  EXPECT_EQ(sc.request_id, 7);
  EXPECT_EQ(sc.sequence, 12);
  EXPECT_EQ(sc.mode, +hrp2_command_t::HOLD);
  EXPECT_EQ(sc.q, c.q);
  EXPECT_EQ(sc.dq, c.dq);
  EXPECT_EQ(sc.waist_position, c.waist_position);
  EXPECT_EQ(sc.waist_rpy, c.waist_rpy);
  EXPECT_FALSE(sc.stabilizer);
  hrp2_command_t unknown = cm;
  unknown.mode = 9;
  EXPECT_THROW(convert::fromMessage(unknown), FormatError);

  // The simulated controller's state, as the bridge reads it.
  hrp2::SimState s;
  s.request_id = 7, s.command_sequence = 11;
  s.q = c.q, s.dq = c.dq;
  s.configuration.base_position = {0.5, 0, 0.6};
  s.wrenches.push_back({"RF", Eigen::Matrix<double, 6, 1>::Constant(2)});
  s.servo_on = false;
  const hrp2_state_t sm = wire(convert::toMessage(s, 5));
  EXPECT_EQ(sm.num_wrenches, 1);
  EXPECT_EQ(sm.wrench_names.at(0), "RF");
  EXPECT_EQ(sm.base_position[2], 0.6);
  const hrp2::MeasuredState ms = convert::fromMessage(sm);
  EXPECT_EQ(ms.q, s.q);
  EXPECT_EQ(ms.dq, s.dq);
  EXPECT_EQ(ms.request_id, 7);
  EXPECT_EQ(ms.command_sequence, 11);
  EXPECT_FALSE(ms.servo_on);

  // The bridge's status, with the request it finished.
  hrp2::BridgeStatus st;
  st.request_id = 7, st.state = hrp2::BridgeState::Idle, st.reason = "done", st.progress = 1;
  st.commands_sent = 300, st.tracking_error_max = 0.01, st.safety_events = 2, st.finished_request_id = 7;
  const hrp2_bridge_status_t bm = wire(convert::toMessage(st, 8));
  EXPECT_EQ(bm.state, +hrp2_bridge_status_t::IDLE);
  EXPECT_EQ(bm.finished_request_id, 7);
  EXPECT_EQ(bm.commands_sent, 300);
  EXPECT_EQ(bm.safety_events, 2);
  EXPECT_EQ(bm.reason, "done");
}

// A service's refusal while busy names the request it is busy with; the
// launcher takes it for an answer to a second copy of its own work only when
// that request is its own (request 12 is not request 1).
TEST(LcmProcess, ABusyRefusalIsRecognisedForTheRequestItNamesOnly) {
  const std::string r = acyclic::proc::busyRefusal(12, "plan");
  EXPECT_EQ(r, "refused: busy with request 12 (one plan at a time)");
  EXPECT_TRUE(acyclic::proc::isBusyWith(r, 12));
  EXPECT_FALSE(acyclic::proc::isBusyWith(r, 1));
  EXPECT_FALSE(acyclic::proc::isBusyWith("no plan within 60 s", 12));
}

#ifdef ACYCLIC_HAVE_INTERPOLATOR
// The planner's transitions (ACYCLIC_TRANSITIONS) through the wire and into
// the interpolator's memo: the knots to the bit (their quaternions not
// normalized again, so that the trajectory is the one solving gives), keyed
// against the plan; a message with a bad field is refused by that field, and
// nothing of it stored.
TEST(LcmConvert, TransitionsRoundTripIntoAMemo) {
  const Scenario& sc = chair();
  Plan plan;
  for (int k = 0; k < 2; ++k) {
    PlanStance s;
    s.configuration = sc.start;
    s.configuration.joints[3] += 0.01 * k;
    for (const auto& spec : sc.start_stance) {
      PlanContact c;
      c.spec = spec;
      s.contacts.push_back(c);
    }
    plan.stances.push_back(s);
  }
  RememberedTransition t;
  t.design.kind = TransitionDesign::Kind::Move;
  t.design.from = 0;
  t.design.to = 1;
  t.outcome.ok = true;
  t.outcome.repaired = true;
  t.outcome.how = "raised 0.05 m";
  t.outcome.attempts = 2;
  t.outcome.refinements = 3;
  t.outcome.posture_calls = 17;
  for (int p = 0; p < 2; ++p) {
    MotionPiece piece;
    piece.stance = p;
    piece.contacts = sc.start_stance;
    for (int k = 0; k < 3; ++k) {
      Configuration q = plan.stances[0].configuration;
      q.joints[3] += 0.003 * k + 0.01 * p;
      q.base_orientation.coeffs() *= 1 + 3e-14;  // a solver's quaternion, not quite unit
      piece.knots.push_back(q);
    }
    t.outcome.pieces.push_back(piece);
  }
  InterpolatorOptions opt;
  opt.steps = 7;
  transitions_t m = wire(convert::toMessage({t}, opt, sc));
  m.request_id = 5;
  EXPECT_EQ(m.options, outcomeOptionsText(opt));
  TransitionMemo memo(opt, true, true);
  EXPECT_EQ(convert::fillMemo(m, plan, sc, memo), 1u);
  const std::optional<TransitionOutcome> back = memo.find(transitionKey(plan, t.design));
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(back->ok && back->repaired && !back->still);
  EXPECT_EQ(back->how, t.outcome.how);
  EXPECT_EQ(back->attempts, 2);
  EXPECT_EQ(back->refinements, 3);
  EXPECT_EQ(back->posture_calls, 17);
  ASSERT_EQ(back->pieces.size(), 2u);
  for (std::size_t p = 0; p < 2; ++p) {
    const MotionPiece &a = back->pieces[p], &b = t.outcome.pieces[p];
    EXPECT_EQ(a.stance, b.stance);
    ASSERT_EQ(a.contacts.size(), b.contacts.size());
    for (std::size_t c = 0; c < a.contacts.size(); ++c) {
      EXPECT_EQ(a.contacts[c].spot, b.contacts[c].spot);
      EXPECT_EQ(a.contacts[c].surface, b.contacts[c].surface);
      EXPECT_EQ(a.contacts[c].supporting, b.contacts[c].supporting);
      EXPECT_EQ(a.contacts[c].placement.theta, b.contacts[c].placement.theta);
    }
    ASSERT_EQ(a.knots.size(), b.knots.size());
    for (std::size_t k = 0; k < a.knots.size(); ++k) {
      EXPECT_EQ(a.knots[k].joints, b.knots[k].joints);
      EXPECT_EQ(a.knots[k].base_position, b.knots[k].base_position);
      EXPECT_EQ(a.knots[k].base_orientation.coeffs(), b.knots[k].base_orientation.coeffs());
    }
  }
  // A Fixed transition of the same stances is another key: not there.
  TransitionDesign fixed = t.design;
  fixed.kind = TransitionDesign::Kind::Fixed;
  EXPECT_FALSE(memo.find(transitionKey(plan, fixed)).has_value());

  auto refusedAt = [&](transitions_t bad, const std::string& field) {
    TransitionMemo empty(opt, true, true);
    try {
      convert::fillMemo(bad, plan, sc, empty);
      ADD_FAILURE() << "accepted; expected a refusal at " << field;
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
    EXPECT_EQ(empty.size(), 0u) << field;
  };
  transitions_t two = m;  // a good transition first: all or none
  two.transitions.push_back(m.transitions[0]);
  two.num_transitions = 2;
  transitions_t bad = two;
  bad.transitions[1].to = 2;
  refusedAt(bad, "transitions[1].from");
  bad = two;
  bad.transitions[1].pieces[1].contacts[0].spot = "tail";
  refusedAt(bad, "transitions[1].pieces[1].contacts[0].spot");
  bad = two;
  bad.transitions[1].pieces[0].knots[2].num_joints -= 1;
  bad.transitions[1].pieces[0].knots[2].joints.pop_back();
  refusedAt(bad, "transitions[1].pieces[0].knots[2]");
}
#endif
