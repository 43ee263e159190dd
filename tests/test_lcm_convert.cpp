// Plans and trajectories through their LCM messages and back (encoded and
// decoded, as on the wire): nothing lost, unknown names refused by field.
#include <gtest/gtest.h>

#include <vector>

#include "planner/common/format_error.h"
#include "processes/lcm_convert.h"
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
