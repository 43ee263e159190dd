// The trajectory file format acyclic.trajectory/1: exact round trip, and bad
// input named by file and field.
#include <gtest/gtest.h>

#include <cmath>

#include "planner/common/format_error.h"
#include "planner/plan/trajectory.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& chair() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

// Three samples over two phases: the start stance, then a thigh released.
Trajectory smallTrajectory() {
  const Scenario& sc = chair();
  Trajectory tr;
  tr.scenario = "models/scenarios/chair_table.yaml";
  tr.plan = "plan.json";
  tr.dt = 0.005;
  TrajectoryPhase a, b;
  a.contacts = sc.start_stance;
  a.t_start = 0, a.t_end = 0.005, a.stance = 0;
  b = a;
  b.contacts[2].supporting = false;
  b.t_start = 0.005, b.t_end = 0.010, b.stance = 1;
  tr.phases = {a, b};
  for (int i = 0; i < 3; ++i) {
    TrajectorySample s;
    s.t = 0.005 * i;
    s.q = sc.start;
    s.q.base_position.x() += 1e-3 * i;
    s.q.joints[3] += 0.01 * i / 3.0;  // not representable in short decimals: exercises round trip
    s.dq = Eigen::VectorXd::Constant(sc.robot->numJoints(), 0.1 * i);
    s.phase = i < 2 ? 0 : 1;
    tr.samples.push_back(s);
  }
  tr.stats.stances_in = 3;
  tr.stats.stances_kept = 2;
  tr.stats.repairs = 1;
  return tr;
}

}  // namespace

TEST(TrajectoryFile, RoundTripIsExact) {
  const Scenario& sc = chair();
  const Trajectory tr = smallTrajectory();
  test::TempDir dir;
  const std::string path = dir.path() + "/t.json";
  writeTrajectory(tr, sc, path);
  const Trajectory back = readTrajectory(path, sc);
  EXPECT_EQ(back.dt, tr.dt);
  EXPECT_EQ(back.plan, "plan.json");
  ASSERT_EQ(back.phases.size(), 2u);
  EXPECT_EQ(back.phases[1].contacts.size(), 4u);
  EXPECT_FALSE(back.phases[1].contacts[2].supporting);
  EXPECT_EQ(back.phases[1].stance, 1);
  ASSERT_EQ(back.samples.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.samples[i].t, tr.samples[i].t);
    EXPECT_EQ(back.samples[i].q.joints, tr.samples[i].q.joints);
    EXPECT_EQ(back.samples[i].q.base_position, tr.samples[i].q.base_position);
    EXPECT_EQ(back.samples[i].dq, tr.samples[i].dq);
    EXPECT_EQ(back.samples[i].phase, tr.samples[i].phase);
  }
  EXPECT_EQ(back.stats.repairs, 1);
  EXPECT_DOUBLE_EQ(back.duration(), 0.010);
}

TEST(TrajectoryFile, BadFieldsAreNamed) {
  const Scenario& sc = chair();
  const std::string text = trajectoryToJson(smallTrajectory(), sc);
  auto expectField = [&](const std::string& from, const std::string& to, const std::string& field) {
    test::expectBadField([&](const std::string& t) { trajectoryFromJson(t, "t.json", sc); }, text, "t.json", from, to,
                         field);
  };
  expectField("\"acyclic.trajectory/1\"", "\"acyclic.plan/1\"", "format");
  expectField("\"phase\":[0,0,1]", "\"phase\":[0,0,2]", "samples.phase[2]");
  expectField("\"t\":[0.0,0.005,0.01]", "\"t\":[0.0,0.005,0.005]", "samples.t[2]");
  expectField("\"t\":[0.0,0.005,0.01]", "\"t\":[0.0,0.005]", "samples.phase");
  expectField("\"dt\":0.005", "\"dt\":0", "dt");
  expectField("\"spot\":\"r_sole\"", "\"spot\":\"r_foot\"", "phases[0].contacts[0].spot");
  expectField("\"RLEG_JOINT0\"", "\"RLEG_JOINT9\"", "joint_names[0]");
  EXPECT_THROW(trajectoryFromJson("[", "t.json", sc), FormatError);
}
