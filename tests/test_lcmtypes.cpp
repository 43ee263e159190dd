// Round trip of every message type: encode, decode, compare fields, and
// re-encode to the same bytes; a truncated buffer must not decode.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "acyclic/cancel_t.hpp"
#include "acyclic/guide_t.hpp"
#include "acyclic/hrp2_bridge_status_t.hpp"
#include "acyclic/hrp2_command_t.hpp"
#include "acyclic/hrp2_estop_t.hpp"
#include "acyclic/hrp2_state_t.hpp"
#include "acyclic/plan_t.hpp"
#include "acyclic/process_status_t.hpp"
#include "acyclic/progress_t.hpp"
#include "acyclic/request_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "channels.hpp"

namespace {

template <class T>
T roundTrip(const T& in) {
  std::vector<uint8_t> buf(in.getEncodedSize());
  EXPECT_EQ(in.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  T out;
  EXPECT_EQ(out.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  std::vector<uint8_t> again(out.getEncodedSize());
  out.encode(again.data(), 0, static_cast<int>(again.size()));
  EXPECT_EQ(buf, again) << "re-encoding changed the bytes";
  T truncated;
  EXPECT_LT(truncated.decode(buf.data(), 0, static_cast<int>(buf.size()) - 1), 0) << "truncated buffer decoded";
  return out;
}

acyclic::configuration_t config(int n, double base) {
  acyclic::configuration_t c;
  for (int i = 0; i < 3; ++i) c.base_position[i] = base + i;
  c.base_orientation[0] = 1;
  c.base_orientation[1] = c.base_orientation[2] = c.base_orientation[3] = 0;
  c.num_joints = n;
  for (int i = 0; i < n; ++i) c.joints.push_back(base + 0.01 * i);
  return c;
}

acyclic::contact_t contact(const std::string& spot, int points) {
  acyclic::contact_t c{};
  c.spot = spot;
  c.surface = "floor";
  c.supporting = points > 0;
  c.x = 0.1, c.y = -0.2, c.theta = 0.3;
  for (int i = 0; i < 3; ++i) c.position[i] = i;
  c.orientation[0] = 1;
  c.num_points = points;
  for (int i = 0; i < points; ++i) {
    c.points.push_back({double(i), 1, 2});
    c.forces.push_back({0, 0, 100.0 + i});
  }
  return c;
}

}  // namespace

TEST(LcmTypes, Request) {
  acyclic::request_t m{};
  m.utime = 1234567;
  m.request_id = 42;
  m.scenario_name = "chair_table";
  m.scenario_yaml = "format: acyclic.scenario/1\n";
  m.base_path = "/models/scenarios";
  m.seed = 7;
  m.time_budget_s = 60;
  auto o = roundTrip(m);
  EXPECT_EQ(o.utime, 1234567);
  EXPECT_EQ(o.request_id, 42);
  EXPECT_EQ(o.scenario_yaml, m.scenario_yaml);
  EXPECT_EQ(o.seed, 7);
}

TEST(LcmTypes, CancelAndEstop) {
  acyclic::cancel_t c{};
  c.utime = 5;
  c.request_id = acyclic::cancel_t::ALL_REQUESTS;
  c.reason = "operator";
  EXPECT_EQ(roundTrip(c).request_id, -1);
  acyclic::hrp2_estop_t e{};
  e.utime = 6;
  e.request_id = 3;
  e.engage = true;
  e.source = "pendant";
  e.reason = "test";
  auto eo = roundTrip(e);
  EXPECT_TRUE(eo.engage);
  EXPECT_EQ(eo.source, "pendant");
}

TEST(LcmTypes, GuideWithPostures) {
  acyclic::guide_t g{};
  g.utime = 1;
  g.request_id = 2;
  g.status = acyclic::guide_t::OK;
  g.source = "hand";
  g.num_postures = 3;
  for (int i = 0; i < 3; ++i) g.postures.push_back(config(30, i));
  auto o = roundTrip(g);
  ASSERT_EQ(o.postures.size(), 3u);
  EXPECT_EQ(o.postures[2].joints.size(), 30u);
  EXPECT_DOUBLE_EQ(o.postures[2].joints[29], 2 + 0.29);
}

TEST(LcmTypes, PlanWithStancesAndForces) {
  acyclic::plan_t p{};
  p.utime = 10;
  p.request_id = 11;
  p.status = acyclic::plan_t::OK;
  p.scenario_name = "chair_table";
  p.num_joints = 2;
  p.joint_names = {"A", "B"};
  p.num_stances = 2;
  for (int s = 0; s < 2; ++s) {
    acyclic::stance_t st{};
    st.num_contacts = 2;
    st.contacts = {contact("r_sole", 4), contact("l_wrist", 0)};
    st.configuration = config(2, s);
    st.potential = -s;
    p.stances.push_back(st);
  }
  p.nodes_generated = 100;
  p.posture_calls = 250;
  p.seconds = 3.5;
  auto o = roundTrip(p);
  ASSERT_EQ(o.stances.size(), 2u);
  EXPECT_EQ(o.stances[1].contacts[0].forces[3][2], 103.0);
  EXPECT_FALSE(o.stances[1].contacts[1].supporting);
  EXPECT_EQ(o.nodes_generated, 100);
}

TEST(LcmTypes, ProgressAndStatus) {
  acyclic::progress_t p{};
  p.utime = 1;
  p.request_id = 9;
  p.source = "acyclic-planner";
  p.stage = "search";
  p.fraction = -1;
  p.best_potential = -3.25;
  EXPECT_DOUBLE_EQ(roundTrip(p).best_potential, -3.25);
  acyclic::process_status_t s{};
  s.utime = 2;
  s.request_id = -1;
  s.process = "acyclic-planner";
  s.pid = 1234;
  s.state = acyclic::process_status_t::ERROR;
  s.reason = "scenario does not load";
  auto so = roundTrip(s);
  EXPECT_EQ(so.state, +acyclic::process_status_t::ERROR);
  EXPECT_EQ(so.reason, s.reason);
}

TEST(LcmTypes, TrajectoryWithPhases) {
  acyclic::trajectory_t t{};
  t.utime = 1;
  t.request_id = 4;
  t.dt = 0.005;
  t.num_joints = 3;
  t.joint_names = {"J0", "J1", "J2"};
  t.num_samples = 5;
  for (int i = 0; i < 5; ++i) {
    t.t.push_back(i * 0.005);
    t.phase.push_back(0);
    t.base_position.push_back({0, 0, 0.6});
    t.base_orientation.push_back({1, 0, 0, 0});
    t.joints.push_back({0.1 * i, 0, 0});
    t.joint_velocities.push_back({20, 0, 0});
  }
  acyclic::trajectory_phase_t ph{};
  ph.t_start = 0;
  ph.t_end = 0.02;
  ph.stabilizer = true;
  ph.num_contacts = 2;
  ph.spots = {"r_sole", "l_sole"};
  ph.surfaces = {"floor", "floor"};
  ph.supporting = {true, true};
  ph.x = {0.0, 0.0};
  ph.y = {-0.1, 0.1};
  ph.theta = {0.0, 0.0};
  ph.stance = 0;
  t.num_phases = 1;
  t.phases = {ph};
  auto o = roundTrip(t);
  EXPECT_EQ(o.joints[4][0], 0.4);
  EXPECT_EQ(o.phases[0].spots[1], "l_sole");
}

TEST(LcmTypes, Hrp2CommandStateStatus) {
  acyclic::hrp2_command_t c{};
  c.utime = 1;
  c.request_id = 2;
  c.sequence = 3;
  c.mode = acyclic::hrp2_command_t::STREAM;
  c.num_joints = 30;
  c.q.assign(30, 0.1);
  c.dq.assign(30, 0.0);
  c.stabilizer = false;
  auto co = roundTrip(c);
  EXPECT_EQ(co.q.size(), 30u);
  EXPECT_EQ(co.sequence, 3);
  acyclic::hrp2_state_t s{};
  s.utime = 1;
  s.num_joints = 30;
  s.q.assign(30, 0.2);
  s.dq.assign(30, 0.0);
  s.base_orientation[0] = 1;
  s.num_wrenches = 2;
  s.wrench_names = {"rfsensor", "lfsensor"};
  s.wrenches = {{0, 0, 280, 0, 0, 0}, {0, 0, 290, 0, 0, 0}};
  s.servo_on = true;
  EXPECT_EQ(roundTrip(s).wrenches[1][2], 290);
  acyclic::hrp2_bridge_status_t b{};
  b.utime = 1;
  b.state = acyclic::hrp2_bridge_status_t::HOLDING;
  b.reason = "stale state";
  EXPECT_EQ(roundTrip(b).state, +acyclic::hrp2_bridge_status_t::HOLDING);
}

TEST(LcmTypes, ChannelNamesAreDistinctUpperSnake) {
  namespace ch = acyclic::channels;
  const std::vector<std::string> names = {ch::kRequest, ch::kCancel, ch::kGuide, ch::kPlan,
                                          ch::kTrajectory, ch::kProgress, ch::kStatus, ch::kHrp2Command,
                                          ch::kHrp2State, ch::kHrp2Estop, ch::kHrp2BridgeStatus};
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  for (const auto& n : names)
    for (char c : n) EXPECT_TRUE((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_') << n;
}

TEST(LcmTypes, FingerprintsDifferBetweenTypes) {
  // lcm decodes by fingerprint: two types must never share one.
  std::set<int64_t> f = {acyclic::request_t::getHash(), acyclic::plan_t::getHash(), acyclic::guide_t::getHash(),
                         acyclic::trajectory_t::getHash(), acyclic::hrp2_command_t::getHash(),
                         acyclic::hrp2_state_t::getHash(), acyclic::cancel_t::getHash(),
                         acyclic::progress_t::getHash(), acyclic::process_status_t::getHash(),
                         acyclic::hrp2_bridge_status_t::getHash(), acyclic::hrp2_estop_t::getHash()};
  EXPECT_EQ(f.size(), 11u);
}

TEST(LcmTypes, JavaJarHoldsEveryTypeForLcmSpy) {
  const std::string jar = std::string(ACYCLIC_BINARY_DIR) + "/acyclic_lcmtypes.jar";
  FILE* p = popen(("jar tf " + jar + " 2>&1").c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string listing;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, p)) listing.append(buf, n);
  pclose(p);
  for (const char* t : {"request_t", "cancel_t", "guide_t", "plan_t", "stance_t", "contact_t", "configuration_t",
                        "progress_t", "process_status_t", "trajectory_t", "trajectory_phase_t", "hrp2_command_t",
                        "hrp2_state_t", "hrp2_bridge_status_t", "hrp2_estop_t"})
    EXPECT_NE(listing.find(std::string("acyclic/") + t + ".class"), std::string::npos) << t << "\n" << listing;
}
