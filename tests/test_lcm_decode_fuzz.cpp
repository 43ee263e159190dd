// Decode fuzz of every message type in-process: truncations, length and
// count fields overwritten with 0, -1, 2^27 and INT_MAX, bit flips, random
// bytes behind a right fingerprint, a wrong fingerprint. No decoder may
// throw, none may allocate more than a small multiple of the message's size
// (lcmtypes/harden_decoders.cmake bounds counts before allocation), and the
// guarded decode (processes/guarded_decode.h) refuses every one of them with
// a reason; good messages still decode to the same bytes. Seeded, bounded.
#include <gtest/gtest.h>

#include <chrono>
#include <climits>
#include <cstdlib>
#include <new>
#include <random>
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
#include "acyclic/transitions_t.hpp"
#include "channels.hpp"
#include "processes/lcm_process.h"

// The largest single allocation while `g_track` is set (this thread only).
// (GCC takes the replaced operator new for a mismatch with its free().)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
thread_local bool g_track = false;
thread_local std::size_t g_largest = 0;
}  // namespace
void* operator new(std::size_t n) {
  if (g_track && n > g_largest) g_largest = n;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using namespace acyclic;

template <class Msg>
std::vector<unsigned char> encode(const Msg& m) {
  std::vector<unsigned char> b(m.getEncodedSize());
  EXPECT_EQ(m.encode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

configuration_t config(int n) {
  configuration_t c{};
  c.base_orientation[0] = 1;
  c.num_joints = n;
  for (int i = 0; i < n; ++i) c.joints.push_back(0.01 * i);
  return c;
}

contact_t contact(const std::string& spot, int points) {
  contact_t c{};
  c.spot = spot;
  c.surface = "floor";
  c.supporting = points > 0;
  c.orientation[0] = 1;
  c.num_points = points;
  for (int i = 0; i < points; ++i) {
    c.points.push_back({double(i), 1, 2});
    c.forces.push_back({0, 0, 100.0 + i});
  }
  return c;
}

request_t request() {
  request_t m{};
  m.request_id = 7;
  m.scenario_name = "step";
  m.scenario_yaml = "format: acyclic.scenario/1\n";
  m.base_path = "/tmp";
  m.time_budget_s = 10;
  return m;
}
cancel_t cancel() {
  cancel_t m{};
  m.request_id = 7;
  m.reason = "operator";
  return m;
}
guide_t guide() {
  guide_t m{};
  m.source = "ompl";
  m.reason = "";
  m.num_postures = 2;
  m.postures = {config(4), config(4)};
  return m;
}
plan_t plan() {
  plan_t m{};
  m.reason = "solved";
  m.scenario_name = "s";
  m.scenario_yaml = "y";
  m.base_path = "/";
  m.num_joints = 3;
  m.joint_names = {"A", "B", "C"};
  stance_t s{};
  s.num_contacts = 2;
  s.contacts = {contact("r_sole", 4), contact("l_hand", 0)};
  s.configuration = config(3);
  m.num_stances = 2;
  m.stances = {s, s};
  return m;
}
transitions_t transitions() {
  transitions_t m{};
  m.options = "acyclic.transition-options/1;steps=0x1.4p+4;";
  transition_t t{};
  t.from = 0;
  t.to = 1;
  t.move = true;
  t.how = "as planned";
  transition_piece_t p{};
  p.stance = 1;
  p.num_contacts = 1;
  p.contacts = {contact("r_sole", 0)};
  p.num_knots = 2;
  p.knots = {config(3), config(3)};
  t.num_pieces = 2;
  t.pieces = {p, p};
  m.num_transitions = 2;
  m.transitions = {t, t};
  return m;
}
trajectory_t trajectory(int joints = 3, int samples = 4) {
  trajectory_t m{};
  m.reason = "ok";
  m.dt = 0.01;
  m.num_joints = joints;
  for (int j = 0; j < joints; ++j) m.joint_names.push_back("J" + std::to_string(j));
  m.num_samples = samples;
  for (int i = 0; i < samples; ++i) {
    m.t.push_back(0.01 * i);
    m.phase.push_back(0);
    m.base_position.push_back({0, 0, 0.6});
    m.base_orientation.push_back({1, 0, 0, 0});
    m.joints.push_back(std::vector<double>(joints, 0.1 * i));
    m.joint_velocities.push_back(std::vector<double>(joints, 0));
  }
  trajectory_phase_t p{};
  p.t_end = 1;
  p.num_contacts = 1;
  p.spots = {"r_sole"};
  p.surfaces = {"floor"};
  p.supporting = {true};
  p.x = {0};
  p.y = {0};
  p.theta = {0};
  m.num_phases = 1;
  m.phases = {p};
  return m;
}
hrp2_command_t command() {
  hrp2_command_t m{};
  m.num_joints = 3;
  m.q = {0.1, 0.2, 0.3};
  m.dq = {0, 0, 0};
  return m;
}
hrp2_state_t state() {
  hrp2_state_t m{};
  m.num_joints = 3;
  m.q = {0.1, 0.2, 0.3};
  m.dq = {0, 0, 0};
  m.base_orientation[0] = 1;
  m.num_wrenches = 2;
  m.wrench_names = {"rfsensor", "lfsensor"};
  m.wrenches = {std::vector<double>(6, 1.0), std::vector<double>(6, 2.0)};
  return m;
}
hrp2_estop_t estop() {
  hrp2_estop_t m{};
  m.engage = true;
  m.source = "operator";
  m.reason = "test";
  return m;
}
hrp2_bridge_status_t bridgeStatus() {
  hrp2_bridge_status_t m{};
  m.reason = "idle";
  return m;
}
process_status_t processStatus() {
  process_status_t m{};
  m.process = "acyclic-planner";
  m.reason = "r";
  return m;
}
progress_t progress() {
  progress_t m{};
  m.source = "acyclic-planner";
  m.stage = "search";
  m.message = "m";
  return m;
}
trajectory_phase_t phase() { return trajectory().phases[0]; }
stance_t stance() { return plan().stances[0]; }

// One decode of `bytes`: must not throw; returns whether the guarded decode
// accepted it; records the largest allocation.
template <class Msg>
bool tryDecode(const std::vector<unsigned char>& bytes, std::size_t* largest, std::string* why) {
  Msg raw;
  g_largest = 0;
  g_track = true;
  bool threw = false;
  try {
    raw.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
  } catch (...) {
    threw = true;
  }
  g_track = false;
  *largest = g_largest;
  EXPECT_FALSE(threw) << Msg::getTypeName() << ": the generated decoder threw on " << bytes.size() << " bytes";
  Msg m;
  *why = proc::whyNotDecoded(bytes.data(), bytes.size(), m);
  return why->empty();
}

template <class Msg>
void fuzz(const Msg& good, std::uint64_t seed, int random_cases) {
  SCOPED_TRACE(Msg::getTypeName());
  const std::vector<unsigned char> bytes = encode(good);
  std::size_t largest = 0;
  std::string why;
  ASSERT_TRUE(tryDecode<Msg>(bytes, &largest, &why)) << why;
  {
    Msg back;
    ASSERT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
    EXPECT_EQ(encode(back), bytes) << "a good message no longer decodes to the same bytes";
  }
  // Allocation allowed: every element is at most this many times the bytes it
  // took on the wire (std::string, std::vector headers, nested structs).
  const std::size_t bound = 64 * bytes.size() + 4096;
  int refused = 0, cases = 0;
  auto check = [&](const std::vector<unsigned char>& b, bool must_refuse, const std::string& what) {
    ++cases;
    const bool ok = tryDecode<Msg>(b, &largest, &why);
    EXPECT_LE(largest, bound) << what << ": allocated " << largest << " bytes for a message of " << b.size();
    if (must_refuse) {
      EXPECT_FALSE(ok) << what << " decoded";
      EXPECT_FALSE(why.empty());
    }
    refused += !ok;
  };
  // Every truncation.
  for (std::size_t n = 0; n < bytes.size(); ++n)
    check(std::vector<unsigned char>(bytes.begin(), bytes.begin() + n), true, "cut to " + std::to_string(n));
  // A byte after the end.
  {
    auto b = bytes;
    b.push_back(0);
    check(b, true, "a trailing byte");
  }
  // Wrong fingerprint.
  {
    auto b = bytes;
    b[3] ^= 0x40;
    check(b, true, "another fingerprint");
    EXPECT_NE(why.find("fingerprint"), std::string::npos) << why;
  }
  // Every 4-byte window after the fingerprint set to a length or count that
  // is never valid there... or might be: 0 can be a valid count, so only the
  // decoder's not throwing and the allocation bound are asserted for it.
  const std::uint32_t values[] = {0u, 0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 1u << 27, 1u << 20};
  for (std::size_t off = 8; off + 4 <= bytes.size(); ++off)
    for (const std::uint32_t v : values) {
      auto b = bytes;
      b[off] = v >> 24, b[off + 1] = (v >> 16) & 0xFF, b[off + 2] = (v >> 8) & 0xFF, b[off + 3] = v & 0xFF;
      check(b, false, "bytes " + std::to_string(off) + ".." + std::to_string(off + 3) + " = " + std::to_string(v));
    }
  // Random bit flips and random bodies behind the right fingerprint.
  std::mt19937_64 rng(seed);
  for (int k = 0; k < random_cases; ++k) {
    auto b = bytes;
    if (k % 2 == 0) {
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int f = 0; f < flips; ++f) {
        const std::size_t at = 8 + rng() % (b.size() - 8);
        b[at] ^= static_cast<unsigned char>(1u << (rng() % 8));
      }
    } else {
      b.resize(8 + rng() % (2 * bytes.size()));
      for (std::size_t i = 8; i < b.size(); ++i) b[i] = static_cast<unsigned char>(rng());
    }
    check(b, false, "random case " + std::to_string(k));
  }
  EXPECT_GT(refused, static_cast<int>(bytes.size()));  // at least every truncation
  std::printf("%s: %d mutated messages, %d refused\n", Msg::getTypeName(), cases, refused);
}

TEST(LcmDecodeFuzz, EveryTypeSurvivesMutationsWithinAnAllocationBound) {
  const auto t0 = std::chrono::steady_clock::now();
  fuzz(request(), 1, 1000);
  fuzz(cancel(), 2, 1000);
  fuzz(guide(), 3, 1000);
  fuzz(plan(), 4, 1000);
  fuzz(stance(), 5, 500);
  fuzz(config(5), 6, 500);
  fuzz(contact("r_sole", 2), 7, 500);
  fuzz(trajectory(), 8, 1000);
  fuzz(transitions(), 16, 1000);
  fuzz(phase(), 9, 500);
  fuzz(progress(), 10, 500);
  fuzz(processStatus(), 11, 500);
  fuzz(command(), 12, 1000);
  fuzz(state(), 13, 1000);
  fuzz(estop(), 14, 1000);
  fuzz(bridgeStatus(), 15, 500);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, 20.0);
  std::printf("%.2f s\n", s);
}

TEST(LcmDecodeFuzz, TheReportedCasesAreRefusedWithoutAllocating) {
  std::size_t largest = 0;
  std::string why;
  // A string length of 0 and of -1 (the reason of a cancel, the scenario of a request).
  for (const std::uint32_t len : {0u, 0xFFFFFFFFu}) {
    auto b = encode(cancel());
    const std::size_t at = 8 + 8 + 8;  // fingerprint, utime, request_id
    b[at] = len >> 24, b[at + 1] = (len >> 16) & 0xFF, b[at + 2] = (len >> 8) & 0xFF, b[at + 3] = len & 0xFF;
    EXPECT_FALSE(tryDecode<cancel_t>(b, &largest, &why));
    EXPECT_NE(why.find("out of bounds"), std::string::npos) << why;
  }
  // HRP2_STATE of a few hundred bytes claiming 2^27 joints, and -1 joints.
  for (const std::uint32_t n : {1u << 27, 0xFFFFFFFFu}) {
    auto b = encode(state());
    const std::size_t at = 8 + 3 * 8;  // fingerprint, utime, request_id, command_sequence
    b[at] = n >> 24, b[at + 1] = (n >> 16) & 0xFF, b[at + 2] = (n >> 8) & 0xFF, b[at + 3] = n & 0xFF;
    EXPECT_FALSE(tryDecode<hrp2_state_t>(b, &largest, &why));
    EXPECT_LT(largest, 4096u) << "allocated before refusing";
  }
}

TEST(LcmDecodeFuzz, ZeroSizedElementsStillDecode) {
  // Degenerate but well formed: no joints, more samples than bytes after the
  // sample times (the joints of each sample take no byte).
  const trajectory_t m = trajectory(0, 40);
  const auto b = encode(m);
  trajectory_t back;
  EXPECT_EQ(back.decode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  EXPECT_EQ(back.num_samples, 40);
  // Empty strings and arrays.
  hrp2_state_t s{};
  const auto e = encode(s);
  hrp2_state_t sb;
  EXPECT_EQ(sb.decode(e.data(), 0, static_cast<int>(e.size())), static_cast<int>(e.size()));
}

// The guarded decode path: counted, reported on ACYCLIC_STATUS with the
// channel and the reason, and the process goes on.
struct StatusEar {
  std::vector<process_status_t> seen;
  void on(const lcm::ReceiveBuffer* rb, const std::string&) {
    process_status_t m;
    if (m.decode(rb->data, 0, static_cast<int>(rb->data_size)) >= 0) seen.push_back(m);
  }
};

TEST(LcmDecodeFuzz, AnUndecodableMessageIsCountedAndReportedWithItsChannelAndReason) {
  proc::Bus bus("memq://");
  StatusEar ear;
  bus.lcm().subscribe(channels::kStatus, &StatusEar::on, &ear);
  proc::StatusReporter status(bus, "test-process");
  auto b = encode(state());
  b[8 + 24] = 0xFF, b[8 + 25] = 0xFF, b[8 + 26] = 0xFF, b[8 + 27] = 0xFF;  // num_joints = -1
  hrp2_state_t m;
  EXPECT_FALSE(proc::decode(b.data(), b.size(), channels::kHrp2State, m, status));
  const auto good = encode(state());
  EXPECT_TRUE(proc::decode(good.data(), good.size(), channels::kHrp2State, m, status));
  EXPECT_EQ(m.num_wrenches, 2);
  EXPECT_EQ(status.undecodableCount(), 1);
  EXPECT_EQ(status.errors(), 1);
  while (bus.lcm().handleTimeout(0) > 0) {
  }
  ASSERT_EQ(ear.seen.size(), 1u);
  EXPECT_EQ(ear.seen[0].state, +process_status_t::ERROR);
  EXPECT_NE(ear.seen[0].reason.find("HRP2_STATE"), std::string::npos) << ear.seen[0].reason;
  EXPECT_NE(ear.seen[0].reason.find("does not decode as hrp2_state_t"), std::string::npos)
      << ear.seen[0].reason;
  EXPECT_NE(ear.seen[0].reason.find("1 refused so far"), std::string::npos) << ear.seen[0].reason;
  // A flood: every one counted, reports limited.
  for (int i = 0; i < 100; ++i) proc::decode(b.data(), b.size(), channels::kHrp2State, m, status);
  EXPECT_EQ(status.undecodableCount(), 101);
  while (bus.lcm().handleTimeout(0) > 0) {
  }
  EXPECT_LE(ear.seen.size(), 12u);
}

}  // namespace
