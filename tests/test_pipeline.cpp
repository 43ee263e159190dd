// Process-level tests of the LCM pipeline (issue 6). Each test runs in its own
// private network namespace (tests/CMakeLists.txt wraps it with
// scripts/netns-run), starts the real executables, talks to them over udpm,
// and checks what they answer and the files and logs they write.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <thread>

#include "acyclic/cancel_t.hpp"
#include "acyclic/hrp2_bridge_status_t.hpp"
#include "acyclic/plan_t.hpp"
#include "acyclic/process_status_t.hpp"
#include "acyclic/request_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "lcmtypes/channels.hpp"
#include "processes/lcm_process.h"
#include "processes/supervisor.h"
#include "test_support.h"

using namespace acyclic;
namespace fs = std::filesystem;

namespace {

bool inNamespace() { return std::getenv("ACYCLIC_IN_NETNS") && std::string(std::getenv("ACYCLIC_IN_NETNS")) == "1"; }

#define REQUIRE_NETNS()                                                                              \
  if (!inNamespace()) GTEST_SKIP() << "process-level test: run it through scripts/netns-run (ctest " \
                                      "does), never on the host's network";

std::string exe(const std::string& name) { return test::binaryPath("processes/" + name); }

// The test's own ear and mouth on the pipeline's bus.
struct Client {
  proc::Bus bus{proc::defaultLcmUrl()};
  std::vector<process_status_t> statuses;
  std::map<std::int64_t, plan_t> plans;
  std::map<std::int64_t, trajectory_t> trajectories;
  Client() {
    bus.lcm().subscribe(channels::kStatus, &Client::onStatus, this);
    bus.lcm().subscribe(channels::kPlan, &Client::onPlan, this);
    bus.lcm().subscribe(channels::kTrajectory, &Client::onTrajectory, this);
  }
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const process_status_t* m) { statuses.push_back(*m); }
  void onPlan(const lcm::ReceiveBuffer*, const std::string&, const plan_t* m) { plans[m->request_id] = *m; }
  void onTrajectory(const lcm::ReceiveBuffer*, const std::string&, const trajectory_t* m) {
    trajectories[m->request_id] = *m;
  }
  // Serves LCM until pred() holds; false on timeout.
  template <class Pred>
  bool waitFor(Pred pred, double seconds) {
    const auto t0 = std::chrono::steady_clock::now();
    while (!pred()) {
      if (std::chrono::steady_clock::now() - t0 > std::chrono::duration<double>(seconds)) return false;
      bus.lcm().handleTimeout(20);
    }
    return true;
  }
  bool sawStatus(const std::string& process, int8_t state, std::int64_t request_id = -2) const {
    for (const auto& s : statuses)
      if (s.process == process && s.state == state && (request_id == -2 || s.request_id == request_id)) return true;
    return false;
  }
  const process_status_t* error(const std::string& process, const std::string& needle) const {
    for (const auto& s : statuses)
      if (s.process == process && s.state == process_status_t::ERROR && s.reason.find(needle) != std::string::npos)
        return &s;
    return nullptr;
  }
  request_t request(std::int64_t id, const std::string& scenario_rel, double budget_s = -1) {
    request_t r{};
    r.utime = proc::nowMicros();
    r.request_id = id;
    r.scenario_name = fs::path(scenario_rel).stem().string();
    r.scenario_yaml = test::readFile(test::sourcePath(scenario_rel));
    r.base_path = fs::path(test::sourcePath(scenario_rel)).parent_path().string();
    r.seed = -1;
    r.time_budget_s = budget_s;
    return r;
  }
};

struct Processes {
  Supervisor sup{[](const std::string& s) { std::fprintf(stderr, "[supervisor] %s\n", s.c_str()); }};
  void start(const std::string& name, std::vector<std::string> extra = {}) {
    ChildSpec c{name, {exe(name), "--lcm"}, ""};
    c.argv.insert(c.argv.end(), extra.begin(), extra.end());
    c.respawn = false;
    sup.start(c);
  }
};

bool haveInterpolator() { return fs::exists(exe("acyclic-interpolator")); }

}  // namespace

TEST(Pipeline, LaunchOnASmallScenarioWritesAValidPlanTrajectoryAndLog) {
  REQUIRE_NETNS();
  test::TempDir dir;
  const auto run = test::runProcess(exe("acyclic-launch") + " -q --scenario " +
                                    test::sourcePath("models/scenarios/step_forward.yaml") + " --out " + dir.path());
  ASSERT_EQ(run.status, 0) << run.output;
  ASSERT_TRUE(fs::exists(dir.path() + "/plan.json")) << run.output;
  const auto check = test::runProcess(exe("acyclic-check") + " " + test::sourcePath("models/scenarios/step_forward.yaml") +
                                      " --plan " + dir.path() + "/plan.json");
  EXPECT_EQ(check.status, 0) << check.output;
  if (haveInterpolator()) {
    ASSERT_TRUE(fs::exists(dir.path() + "/trajectory.json")) << run.output;
    const auto tcheck = test::runProcess(exe("acyclic-check") + " " +
                                         test::sourcePath("models/scenarios/step_forward.yaml") + " --trajectory " +
                                         dir.path() + "/trajectory.json");
    EXPECT_EQ(tcheck.status, 0) << tcheck.output;
  }
  // The log holds the request, the answers and the heartbeats.
  lcm::LogFile log(dir.path() + "/run.lcmlog", "r");
  ASSERT_TRUE(log.good());
  std::map<std::string, int> count;
  for (const lcm::LogEvent* e; (e = log.readNextEvent());) ++count[e->channel];
  EXPECT_EQ(count[channels::kRequest], 1);
  EXPECT_EQ(count[channels::kPlan], 1);
  EXPECT_GE(count[channels::kStatus], 2);
  if (haveInterpolator()) {
    EXPECT_EQ(count[channels::kTrajectory], 1);
  }
}

// The scenario with non-foot contacts that is small enough for the suite:
// HRP-2 sits down on a chair, its key postures left out so that the guide
// process authors them (OMPL). The whole pipeline: guided, planned (the goal
// needs both thighs supporting, which acyclic-check verifies), interpolated,
// checked sample by sample, and played by the bridge on the simulated
// controller without a safety event.
TEST(Pipeline, SitDownIsGuidedPlannedInterpolatedAndPlayedWithItsThighContacts) {
  REQUIRE_NETNS();
  if (!haveInterpolator()) GTEST_SKIP() << "built without the interpolator";
  test::TempDir dir;
  std::string text = test::scenarioText("models/scenarios/sit_down.yaml");
  text = text.substr(0, text.find("key_postures:"));
  const std::string scenario = dir.write("sit_down_no_keys.yaml", text);
  const auto run = test::runProcess(exe("acyclic-launch") + " -q --scenario " + scenario + " --out " + dir.path());
  ASSERT_EQ(run.status, 0) << run.output;
  const auto check = test::runProcess(exe("acyclic-check") + " " + scenario + " --plan " + dir.path() + "/plan.json");
  EXPECT_EQ(check.status, 0) << check.output;
  EXPECT_NE(check.output.find("supported by r_thigh and l_thigh"), std::string::npos) << check.output;
  const auto tcheck =
      test::runProcess(exe("acyclic-check") + " " + scenario + " --trajectory " + dir.path() + "/trajectory.json");
  EXPECT_EQ(tcheck.status, 0) << tcheck.output;
  // The bridge's last status in the log: every sample streamed, no safety event.
  lcm::LogFile log(dir.path() + "/run.lcmlog", "r");
  ASSERT_TRUE(log.good());
  std::optional<acyclic::hrp2_bridge_status_t> last;
  acyclic::trajectory_t traj;
  bool have_traj = false;
  int guides = 0;
  for (const lcm::LogEvent* e; (e = log.readNextEvent());) {
    guides += e->channel == channels::kGuide;
    if (e->channel == channels::kHrp2BridgeStatus) {
      acyclic::hrp2_bridge_status_t st;
      ASSERT_GE(st.decode(e->data, 0, e->datalen), 0);
      last = st;
    } else if (e->channel == channels::kTrajectory) {
      ASSERT_GE(traj.decode(e->data, 0, e->datalen), 0);
      have_traj = true;
    }
  }
  EXPECT_EQ(guides, 1);
  ASSERT_TRUE(last.has_value());
  ASSERT_TRUE(have_traj);
  EXPECT_GE(last->commands_sent, traj.num_samples);
  EXPECT_EQ(last->safety_events, 0);
  EXPECT_LT(last->tracking_error_max, 0.05);
}

TEST(Pipeline, ReplayOfTheCheckedInLogReproducesItsAnswers) {
  REQUIRE_NETNS();
  const auto run = test::runProcess(exe("acyclic-replay") + " " + test::sourcePath("logs/step_forward.lcmlog"));
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("plan identical"), std::string::npos) << run.output;
}

TEST(Pipeline, CorruptMessagesAndBadScenariosGetStatusErrorsAndTheProcessStaysUp) {
  REQUIRE_NETNS();
  Client c;
  Processes p;
  p.start("acyclic-planner");
  if (haveInterpolator()) p.start("acyclic-interpolator");
  ASSERT_TRUE(c.waitFor([&] { return c.sawStatus("acyclic-planner", process_status_t::IDLE); }, 20));
  if (haveInterpolator()) {
    ASSERT_TRUE(c.waitFor([&] { return c.sawStatus("acyclic-interpolator", process_status_t::IDLE); }, 20));
  }

  const char garbage[] = "not an LCM message";
  c.bus.publishRaw(channels::kRequest, garbage, sizeof garbage);
  ASSERT_TRUE(c.waitFor([&] { return c.error("acyclic-planner", "does not decode") != nullptr; }, 10));

  request_t bad = c.request(7, "models/scenarios/step_forward.yaml");
  bad.scenario_yaml.replace(bad.scenario_yaml.find("l_sole"), 6, "l_hoof");
  c.bus.publish(channels::kRequest, bad);
  ASSERT_TRUE(c.waitFor([&] { return c.plans.count(7) > 0; }, 10));
  EXPECT_EQ(c.plans[7].status, +plan_t::INVALID_INPUT);
  EXPECT_NE(c.plans[7].reason.find("l_hoof"), std::string::npos) << c.plans[7].reason;
  const process_status_t* e = c.error("acyclic-planner", "does not load");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->request_id, 7);

  if (haveInterpolator()) {
    c.bus.publishRaw(channels::kPlan, garbage, sizeof garbage);
    EXPECT_TRUE(c.waitFor([&] { return c.error("acyclic-interpolator", "does not decode") != nullptr; }, 10));
    // A plan whose scenario does not load: answered with an error trajectory.
    plan_t junk{};
    junk.request_id = 9;
    junk.status = plan_t::OK;
    junk.scenario_yaml = "format: acyclic.scenario/1\nname: [";
    c.bus.publish(channels::kPlan, junk);
    ASSERT_TRUE(c.waitFor([&] { return c.trajectories.count(9) > 0; }, 10));
    EXPECT_NE(c.trajectories[9].status, +trajectory_t::OK);
  }

  // Still up: a good request is answered.
  c.bus.publish(channels::kRequest, c.request(8, "models/scenarios/step_forward.yaml"));
  ASSERT_TRUE(c.waitFor([&] { return c.plans.count(8) > 0; }, 60));
  EXPECT_EQ(c.plans[8].status, +plan_t::OK) << c.plans[8].reason;
  EXPECT_GT(c.plans[8].num_stances, 2);
  EXPECT_TRUE(p.sup.running("acyclic-planner"));
}

TEST(Pipeline, ASecondRequestWhileBusyIsRefusedAndCancelStopsTheFirst) {
  REQUIRE_NETNS();
  Client c;
  Processes p;
  p.start("acyclic-planner");
  ASSERT_TRUE(c.waitFor([&] { return c.sawStatus("acyclic-planner", process_status_t::IDLE); }, 20));
  // The chair is not solved in 60 s: it keeps the planner busy.
  c.bus.publish(channels::kRequest, c.request(1, "models/scenarios/chair_table.yaml", 60));
  ASSERT_TRUE(c.waitFor([&] { return c.sawStatus("acyclic-planner", process_status_t::BUSY, 1); }, 20));
  c.bus.publish(channels::kRequest, c.request(2, "models/scenarios/step_forward.yaml"));
  ASSERT_TRUE(c.waitFor([&] { return c.plans.count(2) > 0; }, 10));
  EXPECT_EQ(c.plans[2].status, +plan_t::ERROR);
  EXPECT_NE(c.plans[2].reason.find("busy with request 1"), std::string::npos) << c.plans[2].reason;

  cancel_t cancel{};
  cancel.utime = proc::nowMicros();
  cancel.request_id = 1;
  cancel.reason = "test";
  const auto t0 = std::chrono::steady_clock::now();
  c.bus.publish(channels::kCancel, cancel);
  ASSERT_TRUE(c.waitFor([&] { return c.plans.count(1) > 0; }, 10));
  EXPECT_EQ(c.plans[1].status, +plan_t::CANCELLED) << c.plans[1].reason;
  std::printf("cancelled after %.2f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

TEST(Pipeline, APlannerKilledMidRequestIsRestartedAndTheLauncherResendsItsWork) {
  REQUIRE_NETNS();
  Client c;
  test::TempDir dir;
  // The launcher plans the chair with a short budget; the test kills the
  // planner once it is busy; the launcher restarts it and sends the request
  // again, which is then answered (with its time limit).
  std::thread killer([&] {
    Client watch;
    if (!watch.waitFor([&] { return watch.sawStatus("acyclic-planner", process_status_t::BUSY, 1); }, 30)) return;
    const std::int64_t pid = [&] {
      for (const auto& s : watch.statuses)
        if (s.process == "acyclic-planner" && s.state == process_status_t::BUSY) return s.pid;
      return std::int64_t{-1};
    }();
    if (pid > 0) kill(static_cast<pid_t>(pid), SIGKILL);
  });
  const auto run = test::runProcess(exe("acyclic-launch") + " -q --no-interpolate --max-seconds 3 --timeout 60 " +
                                    "--scenario " + test::sourcePath("models/scenarios/chair_table.yaml") +
                                    " --out " + dir.path());
  killer.join();
  EXPECT_NE(run.output.find("acyclic-planner killed by signal 9: restarting"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("request 1 sent"), std::string::npos);
  // The restarted planner answered the re-sent request (not solved in 3 s).
  EXPECT_NE(run.output.find("plan: status"), std::string::npos) << run.output;
  EXPECT_EQ(run.status, 1) << run.output;
}

namespace {

// Starts a process (no shell); returns its pid.
pid_t spawn(const std::vector<std::string>& argv) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  return pid;
}

// Waits for a pid; its exit status, or -1 if it is still running after `seconds`.
int waitExit(pid_t pid, double seconds) {
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::duration<double>(seconds)) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  return -1;
}

}  // namespace

TEST(Pipeline, ProcessesExitCleanlyOnSigintAndSigtermEvenMidRequest) {
  REQUIRE_NETNS();
  std::vector<std::string> names = {"acyclic-planner"};
  if (haveInterpolator()) names.push_back("acyclic-interpolator");
  for (const auto& name : names)
    for (const int sig : {SIGINT, SIGTERM}) {
      Client c;
      const pid_t pid = spawn({exe(name), "--lcm"});
      ASSERT_TRUE(c.waitFor([&] { return c.sawStatus(name, process_status_t::IDLE); }, 20)) << name;
      if (name == "acyclic-planner") {
        // Busy on the chair (not solved): the signal must cancel it, not wait for it.
        c.bus.publish(channels::kRequest, c.request(3, "models/scenarios/chair_table.yaml", 60));
        ASSERT_TRUE(c.waitFor([&] { return c.sawStatus(name, process_status_t::BUSY, 3); }, 20));
      }
      kill(pid, sig);
      EXPECT_EQ(waitExit(pid, 5), 0) << name << " after signal " << sig;
      EXPECT_TRUE(c.waitFor([&] { return c.sawStatus(name, process_status_t::STOPPING); }, 2)) << name;
    }
}

TEST(Pipeline, AScenarioWithoutKeyPosturesIsGuidedByTheOmplAuthor) {
  REQUIRE_NETNS();
  test::TempDir dir;
  // step_forward without its key postures: the guide process authors them.
  std::string text = test::scenarioText("models/scenarios/step_forward.yaml");
  text = text.substr(0, text.find("key_postures:"));
  const std::string scenario = dir.write("step_no_keys.yaml", text);
  const auto run = test::runProcess(exe("acyclic-launch") + " -q --scenario " + scenario + " --out " + dir.path() +
                                    "/run");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto check = test::runProcess(exe("acyclic-check") + " " + scenario + " --plan " + dir.path() + "/run/plan.json");
  EXPECT_EQ(check.status, 0) << check.output;
  lcm::LogFile log(dir.path() + "/run/run.lcmlog", "r");
  ASSERT_TRUE(log.good());
  int guides = 0;
  for (const lcm::LogEvent* e; (e = log.readNextEvent());) guides += e->channel == channels::kGuide;
  EXPECT_EQ(guides, 1);
}
