// The HRP-2 bridge and the simulated controller as processes, on LCM udpm in
// a private network namespace (packets never leave it): a trajectory played
// end to end with the tracking error reported; robot state that stops ->
// holding within 3 control periods; an e-stop mid-motion freezes and the
// release resumes to the end; a NaN or a limit violation is refused and
// nothing moves; a second trajectory while streaming is refused (not queued).
// The trajectories are synthetic (the chair's start posture, one arm joint
// moving) and short: each test takes a few seconds.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <deque>
#include <cmath>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <thread>

#include "acyclic/hrp2_bridge_status_t.hpp"
#include "acyclic/hrp2_command_t.hpp"
#include "acyclic/hrp2_estop_t.hpp"
#include "acyclic/hrp2_state_t.hpp"
#include "acyclic/process_status_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "channels.hpp"
#include "processes/lcm_convert.h"
#include "fuzz_support.h"
#include "test_support.h"

extern char** environ;

using namespace acyclic;

namespace {

const char* kUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
constexpr double kDt = 0.005;

const Scenario& chair() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

// The chair's start posture with RARM_JOINT0 moving by `amplitude` (half
// cosine, at rest at both ends) over `duration`, starting `offset` away.
Trajectory armMotion(double duration, double amplitude, double offset = 0, int joint = 16) {
  const Scenario& sc = chair();
  Trajectory tr;
  tr.scenario = sc.path;
  tr.dt = kDt;
  TrajectoryPhase p;
  p.contacts = sc.start_stance;
  p.t_end = duration;
  tr.phases = {p};
  const int n = static_cast<int>(std::lround(duration / kDt));
  for (int i = 0; i <= n; ++i) {
    TrajectorySample s;
    s.t = i * kDt;
    s.q = sc.start;
    const double a = M_PI * s.t / duration;
    s.q.joints[joint] += offset + amplitude * (1 - std::cos(a)) / 2;
    s.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
    s.dq[joint] = amplitude * M_PI / duration * std::sin(a) / 2;
    tr.samples.push_back(s);
  }
  return tr;
}

struct Child {
  pid_t pid = -1;
  std::string log;
};

// What the test hears on the bus, with the test's receive time.
struct Heard {
  std::vector<hrp2_command_t> commands;
  std::vector<hrp2_state_t> states;
  std::vector<hrp2_bridge_status_t> statuses;
  std::vector<process_status_t> process;
};

class Hrp2Processes : public ::testing::Test {
 protected:
  void SetUp() override {
    // Each test runs in its own process under ctest: its own namespace.
    if (unshare(CLONE_NEWNET) != 0)
      GTEST_SKIP() << "cannot create a network namespace here (needs root or user namespaces): "
                   << std::strerror(errno);
    ASSERT_EQ(std::system("ip link set lo up && ip route add 224.0.0.0/4 dev lo"), 0);
    lcm_ = std::make_unique<lcm::LCM>(kUrl);
    ASSERT_TRUE(lcm_->good());
    lcm_->subscribe(channels::kHrp2Command, &Hrp2Processes::onCommand, this);
    lcm_->subscribe(channels::kHrp2State, &Hrp2Processes::onState, this);
    lcm_->subscribe(channels::kHrp2BridgeStatus, &Hrp2Processes::onStatus, this);
    lcm_->subscribe(channels::kStatus, &Hrp2Processes::onProcess, this);
  }
  void TearDown() override {
    for (Child& c : children_)
      if (c.pid > 0) {
        kill(c.pid, SIGKILL);
        waitpid(c.pid, nullptr, 0);
      }
  }

  void onCommand(const lcm::ReceiveBuffer*, const std::string&, const hrp2_command_t* m) { heard_.commands.push_back(*m); }
  void onState(const lcm::ReceiveBuffer*, const std::string&, const hrp2_state_t* m) { heard_.states.push_back(*m); }
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const hrp2_bridge_status_t* m) {
    heard_.statuses.push_back(*m);
  }
  void onProcess(const lcm::ReceiveBuffer*, const std::string&, const process_status_t* m) { heard_.process.push_back(*m); }

  Child& spawn(const std::string& exe, std::vector<std::string> args) {
    Child c;
    c.log = dir_.path() + "/" + exe + "-" + std::to_string(children_.size()) + ".log";
    args.insert(args.begin(), test::binaryPath("processes/" + exe));
    args.push_back("--lcm-url");
    args.push_back(kUrl);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, c.log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    // The child starts with no signal blocked and SIGINT/SIGTERM at their
    // defaults, whatever this process (and LCM's threads) did with them.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t none, term;
    sigemptyset(&none);
    sigemptyset(&term);
    sigaddset(&term, SIGTERM);
    sigaddset(&term, SIGINT);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setsigdefault(&attr, &term);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    EXPECT_EQ(posix_spawn(&c.pid, argv[0], &fa, &attr, argv.data(), environ), 0) << argv[0];
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&attr);
    children_.push_back(c);
    return children_.back();
  }
  // Waits for the child's exit (at most `seconds`, serving LCM meanwhile); its exit status, -1 on timeout.
  int wait(Child& c, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      int st = 0;
      if (waitpid(c.pid, &st, WNOHANG) == c.pid) {
        c.pid = -1;
        return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
      }
      lcm_->handleTimeout(10);
    }
    return -1;
  }
  int stop(Child& c) {
    kill(c.pid, SIGTERM);
    return wait(c, 5);
  }
  // Serves LCM until pred() or the timeout; pred's value.
  bool serveUntil(const std::function<bool()>& pred, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (pred()) return true;
      lcm_->handleTimeout(5);
    }
    return pred();
  }
  void serveFor(double seconds) {
    serveUntil([] { return false; }, seconds);
  }
  std::string trajectoryFile(const Trajectory& tr, const std::string& name) {
    const std::string p = dir_.path() + "/" + name;
    writeTrajectory(tr, chair(), p);
    return p;
  }
  Child& sim(std::vector<std::string> extra = {}) {
    std::vector<std::string> a = {"--scenario", chair().path};
    a.insert(a.end(), extra.begin(), extra.end());
    Child& c = spawn("acyclic-hrp2-sim", a);
    // Up when its states arrive.
    EXPECT_TRUE(serveUntil([&] { return !heard_.states.empty(); }, 10)) << test::readFile(c.log);
    return c;
  }
  // A shared machine stalls a process for 10-40 ms now and then
  // (bench_bridge_jitter: max wake-up delay), which the default 10 ms state
  // watchdog rightly calls stale. Tests that are not about the watchdog use
  // the configuration for a simulator on such a machine (100 ms); the watchdog
  // test keeps the default.
  std::string tolerantConfig(bool contract = true) {
    const std::string simulated = test::sourcePath("hrp2_bridge/config/simulated.yaml");
    if (contract) return simulated;
    return dir_.write("bridge-no-contract.yaml", test::readFile(simulated) + "check_contract: false\n");
  }
  void publish(const trajectory_t& m) { lcm_->publish(channels::kTrajectory, &m); }
  trajectory_t message(const Trajectory& tr, std::int64_t id) {
    trajectory_t m = convert::toMessage(tr, chair());
    m.request_id = id;
    m.status = trajectory_t::OK;
    return m;
  }
  bool bridgeIn(int8_t state) {
    return !heard_.statuses.empty() && heard_.statuses.back().state == state;
  }
  std::string logs() {
    std::string s;
    for (const Child& c : children_) s += "--- " + c.log + "\n" + test::readFile(c.log);
    return s;
  }

  test::TempDir dir_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::deque<Child> children_;  // references stay valid as children are added
  Heard heard_;
};

double maxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

}  // namespace

TEST_F(Hrp2Processes, TrajectoryPlayedEndToEndWithTrackingErrorReported) {
  // Two phases: seated (feet and thighs: the stabilizer off), then the thighs
  // released at 0.75 s (feet only: on again 0.1 s later, the default lag).
  // Released while seated and moving, this is not a valid motion (no
  // equilibrium on the feet alone, no rest at the contact change): the
  // contract check is off for it, the schedule is what is tested. Valid
  // motions are streamed with the check on below.
  Trajectory tr = armMotion(1.5, -0.4);
  TrajectoryPhase feet = tr.phases[0];
  feet.contacts.resize(2);
  ASSERT_EQ(chair().robot->spots()[feet.contacts[1].spot].name, "l_sole");
  tr.phases[0].t_end = feet.t_start = 0.75;
  tr.phases.push_back(feet);
  for (auto& s : tr.samples) s.phase = s.t < 0.75 - 1e-9 ? 0 : 1;
  const std::string file = trajectoryFile(tr, "arm.json");
  Child& s = sim();
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file, "--config", tolerantConfig(false)});
  EXPECT_EQ(wait(b, 20), 0) << logs();
  serveFor(0.2);
  std::size_t streamed = 0;
  for (const auto& c : heard_.commands) {
    if (c.mode != hrp2_command_t::STREAM) continue;
    // The stabilizer flag and the references travel with every command.
    const double t = kDt * streamed++;
    EXPECT_EQ(bool(c.stabilizer), t >= 0.85 - 1e-9) << "t = " << t;
    EXPECT_NEAR(c.waist_position[2], chair().start.base_position.z(), 1e-9);
    EXPECT_NEAR(c.zmp_waist[2], -chair().start.base_position.z(), 1e-6) << "the ZMP is on the floor, in the waist frame";
  }
  EXPECT_EQ(streamed, tr.samples.size());
  // The simulator's contact wrenches carry the weight (at the start: feet and thighs).
  // (the LP runs on its own thread: the first states may come before its first result)
  std::size_t k = 0;
  while (k + 1 < heard_.states.size() && heard_.states[k].num_wrenches == 0) ++k;
  EXPECT_LT(k, 40u) << "no wrenches in the first 0.2 s";
  const hrp2_state_t& first = heard_.states[k];
  EXPECT_EQ(first.num_wrenches, 4);
  double fz = 0;
  for (int i = 0; i < first.num_wrenches; ++i) fz += first.wrenches[i][2];  // spot z is the normal: level spots
  EXPECT_NEAR(fz, chair().robot->totalMass() * 9.81, 1.0);
  ASSERT_FALSE(heard_.statuses.empty());
  const hrp2_bridge_status_t& last = heard_.statuses.back();
  EXPECT_EQ(last.state, +hrp2_bridge_status_t::IDLE) << last.reason;
  EXPECT_EQ(last.safety_events, 0) << logs();
  EXPECT_DOUBLE_EQ(last.progress, 1.0);
  // Tracking error: reported, positive (the simulator lags), small (first-order tracking with feed-forward).
  EXPECT_GT(last.tracking_error_max, 0.0);
  EXPECT_LT(last.tracking_error_max, 0.02);
  std::printf("tracking error (worst, rad): %.5f\n", last.tracking_error_max);
  EXPECT_NE(test::readFile(b.log).find("worst tracking error"), std::string::npos);
  // The simulated robot ended where the trajectory ends.
  ASSERT_FALSE(heard_.states.empty());
  const std::vector<double> end(tr.samples.back().q.joints.data(), tr.samples.back().q.joints.data() + 30);
  EXPECT_LT(maxAbsDiff(heard_.states.back().q, end), 1e-3);
  // Commands at the controller rate: sequence +1 each, utime spaced by about 5 ms.
  for (std::size_t i = 1; i < heard_.commands.size(); ++i)
    EXPECT_EQ(heard_.commands[i].sequence, heard_.commands[i - 1].sequence + 1);
  const double span = (heard_.commands.back().utime - heard_.commands.front().utime) * 1e-6;
  EXPECT_NEAR(span / (heard_.commands.size() - 1), kDt, 0.0005);
  EXPECT_EQ(stop(s), 0) << logs();
}

TEST_F(Hrp2Processes, StateStopsBridgeHoldsWithinThreePeriods) {
  const std::string file = trajectoryFile(armMotion(2.0, -0.4), "arm.json");
  Child& s = sim({"--freeze-after", "0.5"});
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file});
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::HOLDING); }, 10)) << logs();
  serveFor(0.1);
  const std::int64_t last_state = heard_.states.back().utime;
  std::size_t first_hold = 0, after = 0;
  for (std::size_t i = 0; i < heard_.commands.size(); ++i) {
    // Commands from the tick that read the last state are not after it: when
    // the state lands just before a tick, that tick's command is stamped
    // a few microseconds later (seen in CI: a hold 15.03 ms after the last
    // state counted as the fourth command). 1 ms covers that tick's work.
    if (heard_.commands[i].utime <= last_state + 1000) continue;
    ++after;
    if (heard_.commands[i].mode == hrp2_command_t::HOLD) {
      first_hold = i;
      break;
    }
  }
  ASSERT_GT(first_hold, 0u);
  const std::int64_t hold = heard_.commands[first_hold].utime;
  // The bridge's own account of the silence when it held ("none for X ms"):
  // never before its state_timeout (10 ms).
  const std::string& why = heard_.statuses.back().reason;
  const std::size_t none_at = why.find("none for ");
  ASSERT_NE(none_at, std::string::npos) << why;
  const double none_ms = std::stod(why.substr(none_at + 9));
  EXPECT_GE(none_ms, 10.0 - 0.05) << why;
  // Its watchdog counts from the later of the last state as the bridge heard
  // it (a receipt that a stalled machine delayed lags the state's stamp) and
  // its last late tick (more than 1.5 periods after the one before: the
  // bridge or the machine stalled, and a watchdog fires only after the
  // bridge has run on time for its whole timeout, design.md section 11).
  // On time, that is the last state itself (seen in CI: a hold 23 ms after
  // the last state's stamp, 5 commands, once).
  std::int64_t since = std::max(last_state, hold - static_cast<std::int64_t>(none_ms * 1000));
  for (std::size_t i = 1; i <= first_hold; ++i)
    if (heard_.commands[i].utime > last_state &&
        heard_.commands[i].utime - heard_.commands[i - 1].utime > static_cast<std::int64_t>(1.5 * kDt * 1e6))
      since = std::max(since, heard_.commands[i].utime);
  std::size_t counted = 0;
  for (std::size_t i = 0; i <= first_hold; ++i) counted += heard_.commands[i].utime > since + 1000;
  // The hold is at most the third command after that, within 3 periods (+ 2
  // ms for scheduling on a shared machine).
  EXPECT_LE(counted, 3u);
  const double delay = (hold - since) * 1e-6;
  EXPECT_LE(delay, 3 * kDt + 0.002);
  std::printf("hold after the last state: %.2f ms, command %zu after it; after the watchdog's start: %.2f ms, command %zu\n",
              (hold - last_state) * 1e-3, after, delay * 1e3, counted);
  // It holds the last streamed posture and says why.
  EXPECT_EQ(heard_.commands[first_hold].q, heard_.commands[first_hold - 1].q);
  EXPECT_NE(heard_.statuses.back().reason.find("stale"), std::string::npos) << heard_.statuses.back().reason;
  EXPECT_GE(heard_.statuses.back().safety_events, 1);
  // Interrupted before the end: exit 1.
  EXPECT_EQ(stop(b), 1) << logs();
  EXPECT_EQ(stop(s), 0);
}

TEST_F(Hrp2Processes, EstopFreezesAndReleaseResumesToTheEnd) {
  const Trajectory tr = armMotion(1.5, -0.4);
  const std::string file = trajectoryFile(tr, "arm.json");
  Child& s = sim();
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file, "--config", tolerantConfig()});
  ASSERT_TRUE(serveUntil([&] { return heard_.commands.size() > 100; }, 10)) << logs();
  hrp2_estop_t e{};
  e.utime = 0, e.request_id = -1, e.engage = true, e.source = "test", e.reason = "mid-motion";
  lcm_->publish(channels::kHrp2Estop, &e);
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::STOPPED); }, 2)) << logs();
  const std::size_t frozen_from = heard_.commands.size();
  serveFor(0.4);
  ASSERT_GT(heard_.commands.size(), frozen_from + 40);
  const auto& freeze = heard_.commands[frozen_from];
  EXPECT_EQ(freeze.mode, +hrp2_command_t::FREEZE);
  for (std::size_t i = frozen_from; i < heard_.commands.size(); ++i) {
    EXPECT_EQ(heard_.commands[i].mode, +hrp2_command_t::FREEZE);
    EXPECT_EQ(heard_.commands[i].q, freeze.q);
  }
  // The robot has stopped (the last 0.1 s of states are still).
  const auto& st = heard_.states;
  EXPECT_LT(maxAbsDiff(st.back().q, st[st.size() - 20].q), 1e-4);
  EXPECT_LT(maxAbsDiff(st.back().q, freeze.q), 1e-3);
  const double progress = heard_.statuses.back().progress;
  EXPECT_GT(progress, 0.2);
  EXPECT_LT(progress, 0.9);
  e.engage = false;
  lcm_->publish(channels::kHrp2Estop, &e);
  EXPECT_EQ(wait(b, 10), 0) << logs();
  serveFor(0.1);
  EXPECT_EQ(heard_.statuses.back().state, +hrp2_bridge_status_t::IDLE);
  EXPECT_DOUBLE_EQ(heard_.statuses.back().progress, 1.0);
  EXPECT_EQ(heard_.statuses.back().safety_events, 2);  // engage and release
  const std::vector<double> end(tr.samples.back().q.joints.data(), tr.samples.back().q.joints.data() + 30);
  EXPECT_LT(maxAbsDiff(heard_.states.back().q, end), 1e-3);
  EXPECT_EQ(stop(s), 0);
}

TEST_F(Hrp2Processes, NanOrLimitViolationIsRefusedAndNothingMoves) {
  Child& s = sim();
  Child& b = spawn("acyclic-hrp2-bridge", {"--scenario", chair().path, "--config", tolerantConfig()});
  ASSERT_TRUE(serveUntil([&] { return !heard_.statuses.empty(); }, 10)) << logs();
  // A NaN: the message does not even convert.
  trajectory_t nan = message(armMotion(1.0, -0.5), 5);
  nan.joints[40][16] = std::nan("");
  publish(nan);
  ASSERT_TRUE(serveUntil([&] { return heard_.statuses.back().reason.find("refused request 5") != std::string::npos; }, 3))
      << logs();
  // Beyond RARM_JOINT0's upper limit (60 deg) from the start (15 deg): refused by the check.
  publish(message(armMotion(2.0, 1.0), 6));
  ASSERT_TRUE(serveUntil([&] { return heard_.statuses.back().reason.find("refused request 6") != std::string::npos; }, 5))
      << logs();
  EXPECT_NE(heard_.statuses.back().reason.find("RARM_JOINT0"), std::string::npos) << heard_.statuses.back().reason;
  EXPECT_NE(heard_.statuses.back().reason.find("limits"), std::string::npos) << heard_.statuses.back().reason;
  serveFor(0.3);
  EXPECT_TRUE(heard_.commands.empty()) << "a refused trajectory must not command anything";
  EXPECT_EQ(heard_.statuses.back().state, +hrp2_bridge_status_t::IDLE);
  EXPECT_EQ(heard_.statuses.back().safety_events, 2);
  // Nothing moved: the simulated robot is where it started.
  const std::vector<double> start(chair().start.joints.data(), chair().start.joints.data() + 30);
  EXPECT_LT(maxAbsDiff(heard_.states.back().q, start), 1e-12);
  // File mode: a limit violation exits 1 with the reason.
  const std::string file = trajectoryFile(armMotion(2.0, 1.0), "bad.json");
  Child& f = spawn("acyclic-hrp2-bridge", {"--trajectory", file});
  EXPECT_EQ(wait(f, 10), 1) << logs();
  EXPECT_NE(test::readFile(f.log).find("outside its limits"), std::string::npos) << test::readFile(f.log);
  EXPECT_EQ(stop(b), 0) << logs();
  EXPECT_EQ(stop(s), 0);
}

TEST_F(Hrp2Processes, SecondTrajectoryWhileStreamingIsRefusedNotQueued) {
  Child& s = sim();
  Child& b = spawn("acyclic-hrp2-bridge", {"--scenario", chair().path, "--config", tolerantConfig()});
  ASSERT_TRUE(serveUntil([&] { return !heard_.statuses.empty(); }, 10)) << logs();
  publish(message(armMotion(1.0, -0.4), 1));
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::STREAMING); }, 5)) << logs();
  publish(message(armMotion(1.0, -0.4, -0.4), 2));
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::IDLE); }, 5)) << logs();
  bool refused = false;
  for (const auto& p : heard_.process)
    refused |= p.state == process_status_t::ERROR && p.request_id == 2 && p.reason.find("not queued") != std::string::npos;
  EXPECT_TRUE(refused) << logs();
  for (const auto& c : heard_.commands) EXPECT_EQ(c.request_id, 1);
  // Sent again when idle (from where the first ended): played.
  const std::size_t before = heard_.commands.size();
  publish(message(armMotion(1.0, 0.4, -0.4), 2));
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::STREAMING); }, 5)) << logs();
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::IDLE); }, 5)) << logs();
  ASSERT_GT(heard_.commands.size(), before + 200);
  EXPECT_EQ(heard_.commands.back().request_id, 2);
  EXPECT_EQ(heard_.statuses.back().safety_events, 0);
  EXPECT_EQ(stop(b), 0) << logs();
  EXPECT_EQ(stop(s), 0);
}

TEST_F(Hrp2Processes, LatencyAndDroppedCommandsAreRiddenThrough) {
  // 20 ms of latency and a fifth of the commands lost: each command supersedes
  // the last, so the motion still plays to the end without a safety event.
  const Trajectory tr = armMotion(1.0, -0.4);
  const std::string file = trajectoryFile(tr, "arm.json");
  Child& s = sim({"--latency", "0.02", "--drop-rate", "0.2", "--seed", "3"});
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file, "--config", tolerantConfig()});
  EXPECT_EQ(wait(b, 20), 0) << logs();
  serveFor(0.3);
  const hrp2_bridge_status_t& last = heard_.statuses.back();
  EXPECT_EQ(last.safety_events, 0) << logs();
  EXPECT_GT(last.tracking_error_max, 0.0);
  EXPECT_LT(last.tracking_error_max, 0.05);
  const std::vector<double> end(tr.samples.back().q.joints.data(), tr.samples.back().q.joints.data() + 30);
  EXPECT_LT(maxAbsDiff(heard_.states.back().q, end), 1e-3);
  EXPECT_EQ(stop(s), 0);
  // The simulator counted what it lost.
  const std::string log = test::readFile(s.log);
  const auto at = log.find(" dropped");
  ASSERT_NE(at, std::string::npos) << log;
  const long dropped = std::stol(log.substr(log.rfind(' ', at - 1) + 1));
  EXPECT_GT(dropped, 10) << log;
}

TEST_F(Hrp2Processes, AMotionIntoTheTableIsRefusedByTheContractAndNothingMoves) {
  // Within every joint limit, but the forearm reaches the table top.
  const std::string file = trajectoryFile(armMotion(1.5, -0.6), "into_table.json");
  Child& s = sim();
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file});
  EXPECT_EQ(wait(b, 20), 1) << logs();
  EXPECT_NE(test::readFile(b.log).find("table_top"), std::string::npos) << logs();
  serveFor(0.1);
  EXPECT_TRUE(heard_.commands.empty());
  EXPECT_EQ(stop(s), 0);
}

TEST_F(Hrp2Processes, StartGuardRefusesAServoOffRobotAndNothingMoves) {
  const std::string file = trajectoryFile(armMotion(1.0, -0.4), "arm.json");
  Child& s = sim({"--servo-off"});
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file});
  EXPECT_EQ(wait(b, 10), 1) << logs();
  EXPECT_NE(test::readFile(b.log).find("start guard: servo off"), std::string::npos) << logs();
  serveFor(0.1);
  EXPECT_TRUE(heard_.commands.empty());
  EXPECT_EQ(stop(s), 0);
}

TEST_F(Hrp2Processes, HelpAndBadInput) {
  for (const char* exe : {"acyclic-hrp2-bridge", "acyclic-hrp2-sim", "acyclic-hrp2-export"}) {
    const auto r = test::runProcess(test::binaryPath(std::string("processes/") + exe) + " --help");
    EXPECT_EQ(r.status, 0) << exe;
    EXPECT_NE(r.output.find("Exit status"), std::string::npos) << exe;
  }
  const std::string bad = dir_.write("bad.json", "{\"format\": \"acyclic.trajectory/1\", \"scenario\": \"" + chair().path +
                                                     "\", \"dt\": -1}");
  const auto r = test::runProcess(test::binaryPath("processes/acyclic-hrp2-bridge") + " --trajectory " + bad);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
  const auto x = test::runProcess(test::binaryPath("processes/acyclic-hrp2-export") + " --in " + bad + " --out " +
                                  dir_.path() + "/x");
  EXPECT_EQ(x.status, 2) << x.output;
}

namespace {

template <class Msg>
void publishMalformed(lcm::LCM& lcm, const char* channel, const Msg& good, std::uint64_t seed) {
  int k = 0;
  for (const auto& b : test::malformed(test::encoded(good), seed)) {
    lcm.publish(channel, b.data(), static_cast<unsigned>(b.size()));
    if (++k % 25 == 0) lcm.handleTimeout(5);
  }
}

bool processError(const Heard& h, const std::string& process, const std::string& needle) {
  for (const auto& p : h.process)
    if (p.process == process && p.state == process_status_t::ERROR && p.reason.find(needle) != std::string::npos)
      return true;
  return false;
}

}  // namespace

TEST_F(Hrp2Processes, FuzzOnEveryChannelLeavesBridgeAndSimulatorUpAndAGoodTrajectoryStillPlays) {
  Child& s = sim();
  Child& b = spawn("acyclic-hrp2-bridge", {"--scenario", chair().path, "--config", tolerantConfig()});
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::IDLE); }, 10)) << logs();
  const long bridge_peak = test::residentKib(b.pid), sim_peak = test::residentKib(s.pid);

  hrp2_state_t st{};
  st.num_joints = 2;
  st.q = {0.1, 0.2};
  st.dq = {0, 0};
  st.base_orientation[0] = 1;
  st.num_wrenches = 1;
  st.wrench_names = {"rfsensor"};
  st.wrenches = {std::vector<double>(6, 1.0)};
  publishMalformed(*lcm_, channels::kHrp2State, st, 21);
  hrp2_estop_t es{};
  es.source = "fuzz";
  es.reason = "fuzz";
  publishMalformed(*lcm_, channels::kHrp2Estop, es, 22);
  trajectory_t tr{};
  tr.request_id = 900;
  tr.status = trajectory_t::ERROR;  // decodable variants: nothing to do (or refused)
  tr.reason = "fuzz";
  tr.num_joints = 1;
  tr.joint_names = {"J"};
  publishMalformed(*lcm_, channels::kTrajectory, tr, 23);
  hrp2_command_t cmd{};
  cmd.request_id = 900;
  cmd.num_joints = 2;
  cmd.q = {0.1, 0.2};
  cmd.dq = {0, 0};
  publishMalformed(*lcm_, channels::kHrp2Command, cmd, 24);
  // Past the reports' rate limit (10 a second), one more on each channel: its
  // report is not lost in the flood this test's own socket may drop.
  serveFor(1.2);
  heard_.process.clear();
  heard_.states.clear();
  const char garbage[] = "not an LCM message";
  for (const char* channel :
       {channels::kHrp2State, channels::kHrp2Estop, channels::kTrajectory, channels::kHrp2Command})
    lcm_->publish(channel, garbage, sizeof garbage);
  // A well-formed foreign command driving the chest past its limit.
  const int chest = chair().robot->jointIndex("CHEST_JOINT0");
  const double chest_max = chair().robot->upperLimits()[chest];
  hrp2_command_t foreign{};
  foreign.request_id = 901;
  foreign.mode = hrp2_command_t::HOLD;
  foreign.num_joints = chair().robot->numJoints();
  foreign.q.assign(chair().start.joints.data(), chair().start.joints.data() + foreign.num_joints);
  foreign.dq.assign(foreign.num_joints, 0.0);
  foreign.q[chest] = 1.5;
  for (int i = 0; i < 20; ++i) lcm_->publish(channels::kHrp2Command, &foreign);
  serveFor(1.0);

  int st_bridge = 0, st_sim = 0;
  ASSERT_EQ(waitpid(b.pid, &st_bridge, WNOHANG), 0) << "the bridge died\n" << logs();
  ASSERT_EQ(waitpid(s.pid, &st_sim, WNOHANG), 0) << "the simulator died\n" << logs();
  EXPECT_TRUE(processError(heard_, "acyclic-hrp2-bridge", "HRP2_STATE: a message of")) << logs();
  EXPECT_TRUE(processError(heard_, "acyclic-hrp2-bridge", "ACYCLIC_TRAJECTORY: a message of")) << logs();
  EXPECT_TRUE(processError(heard_, "acyclic-hrp2-bridge", "HRP2_ESTOP")) << logs();
  EXPECT_TRUE(processError(heard_, "acyclic-hrp2-sim", "HRP2_COMMAND: a message of")) << logs();
  EXPECT_TRUE(processError(heard_, "acyclic-hrp2-sim", "beyond the joint limits")) << logs();
  ASSERT_FALSE(heard_.states.empty());
  for (const auto& m : heard_.states) {
    ASSERT_EQ(m.num_joints, chair().robot->numJoints());
    ASSERT_LE(m.q[chest], chest_max + 1e-9) << "the foreign command moved the chest";
  }
  const long bridge_grown = test::residentKib(b.pid) - bridge_peak, sim_grown = test::residentKib(s.pid) - sim_peak;
  EXPECT_LT(bridge_grown, 64 * 1024) << "KiB";
  EXPECT_LT(sim_grown, 64 * 1024) << "KiB";
  std::printf("peak memory under fuzz: bridge %+ld KiB, simulator %+ld KiB\n", bridge_grown, sim_grown);

  // The undecodable e-stops engaged it: reset (engage, release), then a good
  // trajectory plays to the end.
  hrp2_estop_t reset{};
  reset.engage = true;
  reset.source = "test";
  lcm_->publish(channels::kHrp2Estop, &reset);
  serveFor(0.2);
  reset.engage = false;
  lcm_->publish(channels::kHrp2Estop, &reset);
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::IDLE); }, 10)) << logs();
  heard_ = Heard{};
  publish(message(armMotion(1.0, -0.3), 5));
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::STREAMING); }, 10)) << logs();
  ASSERT_TRUE(serveUntil([&] { return bridgeIn(hrp2_bridge_status_t::IDLE); }, 10)) << logs();
  EXPECT_EQ(heard_.statuses.back().reason.rfind("done: request 5 ", 0), 0u) << heard_.statuses.back().reason;
  EXPECT_EQ(heard_.statuses.back().finished_request_id, 5);  // what acyclic-launch waits for
  EXPECT_EQ(stop(b), 0) << logs();
  EXPECT_EQ(stop(s), 0);
}

TEST_F(Hrp2Processes, ABridgeKilledMidMotionLeavesTheSimulatorHoldingTheLastCommandedPosture) {
  const std::string file = trajectoryFile(armMotion(2.0, -0.4), "arm.json");
  Child& s = sim();
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file, "--config", tolerantConfig(false)});
  ASSERT_TRUE(serveUntil([&] { return heard_.commands.size() > 140; }, 10)) << logs();  // 0.7 s into the motion
  kill(b.pid, SIGKILL);
  waitpid(b.pid, nullptr, 0);
  b.pid = -1;
  serveFor(0.6);
  const hrp2_command_t last = heard_.commands.back();
  ASSERT_EQ(last.mode, +hrp2_command_t::STREAM);
  ASSERT_GT(std::abs(last.dq[16]), 0.1) << "killed while the arm moves";
  EXPECT_NE(test::readFile(s.log).find("holding the last commanded posture"), std::string::npos) << logs();
  // At rest on the last commanded posture, not T * dq past it (the stale
  // feed-forward of the last command).
  const hrp2_state_t& now = heard_.states.back();
  EXPECT_NEAR(now.q[16], last.q[16], 1e-3) << "feed-forward offset would be " << 0.02 * last.dq[16];
  double dq_max = 0;
  for (double v : now.dq) dq_max = std::max(dq_max, std::abs(v));
  EXPECT_LT(dq_max, 1e-3);
  EXPECT_EQ(stop(s), 0) << logs();
}

// The simulator's dynamic mode: the same stream drives a dynamics simulation
// (free base, PD servos, compliant contact); the seated robot moves its arm
// and stays seated, and the state is the simulated robot's.
TEST_F(Hrp2Processes, DynamicsModeFollowsTheStreamWithAFreeBase) {
  const Trajectory tr = armMotion(1.5, -0.4);
  const std::string file = trajectoryFile(tr, "arm.json");
  Child& s = sim({"--dynamics"});
  Child& b = spawn("acyclic-hrp2-bridge", {"--trajectory", file, "--config",
                                           test::sourcePath("hrp2_bridge/config/simulated_dynamics.yaml")});
  EXPECT_EQ(wait(b, 30), 0) << logs();
  serveFor(0.3);
  ASSERT_FALSE(heard_.states.empty());
  const hrp2_state_t& last = heard_.states.back();
  // The arm's servo ends near the end (its own error under gravity), not exactly there.
  const double arm_error = std::abs(last.q[16] - tr.samples.back().q.joints[16]);
  EXPECT_LT(arm_error, 0.02);
  EXPECT_GT(arm_error, 0.0);
  // The base is free: it settled on the compliant seat and feet, a little lower than planned, and stayed.
  const Eigen::Vector3d base(last.base_position[0], last.base_position[1], last.base_position[2]);
  EXPECT_LT((base - chair().start.base_position).norm(), 0.01);
  EXPECT_NE(base, chair().start.base_position);
  EXPECT_NE(test::readFile(s.log).find("dynamics"), std::string::npos);
  EXPECT_EQ(stop(s), 0) << logs();
  std::printf("%s", test::readFile(s.log).c_str());  // how far the dynamics' periods were from the period
}
