// bench_bridge_jitter: the HRP-2 bridge's command stream timing. Runs the
// bridge's own control loop (PeriodicLoop: clock_nanosleep on absolute
// CLOCK_MONOTONIC deadlines) at the controller rate with the bridge's real
// work each period (Bridge::tick on a streamed trajectory, the command
// encoded as HRP2_COMMAND), and prints the period jitter: how late each
// wake-up is after its deadline, and how far each period is from dt
// (median, 99th percentile, max), with an optional load on the other core:
// a busy loop, or the contact planner solving step_forward over and over.
// Not a Google Benchmark: the figure is a distribution over a fixed time.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

#include "acyclic/hrp2_command_t.hpp"
#include "hrp2_bridge/bridge.h"
#include "hrp2_bridge/periodic_loop.h"
#include "planner/scene/scenario.h"

extern char** environ;

using namespace acyclic;

namespace {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(std::floor(q * (v.size() - 1) + 0.5)))];
}

// A slow arm motion from the chair's start posture, long enough for the run.
Trajectory motion(const Scenario& sc, double duration, double dt) {
  Trajectory tr;
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
    s.q.joints[16] -= 0.4 * (1 - std::cos(a)) / 2;
    s.dq = Eigen::VectorXd::Zero(sc.robot->numJoints());
    s.dq[16] = -0.4 * M_PI / duration * std::sin(a) / 2;
    tr.samples.push_back(s);
  }
  return tr;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Period jitter of the HRP-2 bridge's command loop (median, p99, max), optionally under load."};
  double seconds = 20, dt = 0.005;
  std::string load = "none";
  int rt_priority = 20, cpu = -1;
  app.add_option("--seconds", seconds, "how long to run (default 20)");
  app.add_option("--dt", dt, "controller period, s (default 0.005)");
  app.add_option("--load", load, "none | busy (a spinning thread) | planner (acyclic-planner on step_forward, looped)")
      ->check(CLI::IsMember({"none", "busy", "planner"}));
  app.add_option("--rt-priority", rt_priority, "SCHED_FIFO priority of the loop, 0: none (default 20, as the bridge)");
  app.add_option("--cpu", cpu, "pin the loop to this CPU, and the load to the others (default: no pinning)");
  CLI11_PARSE(app, argc, argv);

  if (cpu >= sysconf(_SC_NPROCESSORS_ONLN)) {
    std::fprintf(stderr, "bench_bridge_jitter: --cpu %d: this machine has %ld CPUs\n", cpu, sysconf(_SC_NPROCESSORS_ONLN));
    return 2;
  }
  const Scenario sc = Scenario::load(std::string(ACYCLIC_SOURCE_DIR) + "/models/scenarios/chair_table.yaml");
  hrp2::BridgeConfig cfg;
  cfg.dt = dt;
  hrp2::Bridge bridge(sc.robot, cfg);

  std::atomic<bool> stop{false};
  std::thread busy;
  pid_t planner = -1;
  if (load == "busy") {
    busy = std::thread([&] {
      volatile double x = 0;
      while (!stop) x = x + 1;
    });
  } else if (load == "planner") {
    // A shell that runs the planner again and again (posix_spawn: nothing of
    // this process is shared copy-on-write with it).
    const std::string cmd = "while :; do '" + std::string(ACYCLIC_BINARY_DIR) + "/processes/acyclic-planner' --in '" +
                            std::string(ACYCLIC_SOURCE_DIR) + "/models/scenarios/step_forward.yaml' --out /dev/null -q "
                            ">/dev/null 2>&1; done";
    const char* argv_sh[] = {"/bin/sh", "-c", cmd.c_str(), nullptr};
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setpgroup(&attr, 0);  // its own group: killed as one at the end
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    if (posix_spawn(&planner, "/bin/sh", nullptr, &attr, const_cast<char* const*>(argv_sh), environ) != 0) planner = -1;
    posix_spawnattr_destroy(&attr);
  }
  if (cpu >= 0) {
    cpu_set_t others;
    CPU_ZERO(&others);
    for (int c = 0; c < CPU_SETSIZE && c < 64; ++c)
      if (c != cpu) CPU_SET(c, &others);
    if (planner > 0) sched_setaffinity(planner, sizeof others, &others);
    std::string why;
    if (!hrp2::pinToCpu(cpu, &why)) {  // as acyclic-hrp2-bridge --cpu
      std::fprintf(stderr, "bench_bridge_jitter: --cpu %d: %s\n", cpu, why.c_str());
      stop = true;
      if (busy.joinable()) busy.join();
      if (planner > 0) kill(-planner, SIGKILL), waitpid(planner, nullptr, 0);
      return 2;
    }
  }
  if (busy.joinable() && cpu >= 0) {
    cpu_set_t others;
    CPU_ZERO(&others);
    for (int c = 0; c < 64; ++c)
      if (c != cpu) CPU_SET(c, &others);
    pthread_setaffinity_np(busy.native_handle(), sizeof others, &others);
  }
  std::string rt = "normal priority";
  if (rt_priority > 0) {
    std::string why;
    rt = hrp2::setRealtimePriority(rt_priority, &why) ? "SCHED_FIFO " + std::to_string(rt_priority)
                                                     : "normal priority (SCHED_FIFO refused: " + why + ")";
    if (!hrp2::lockMemory(&why)) rt += " (memory not locked: " + why + ")";
  }

  // The bridge streams a trajectory against a robot that follows every command.
  hrp2::MeasuredState robot;
  robot.q = sc.start.joints;
  robot.dq = Eigen::VectorXd::Zero(robot.q.size());
  std::int64_t now = hrp2::monotonicMicros();
  bridge.onState(robot, now);
  bridge.beginCheck(1, now);
  bridge.endCheck(1, hrp2::prepareTrajectory(motion(sc, seconds + 5, dt), sc.robot, sc.scene, cfg), now);
  if (bridge.state() != hrp2::BridgeState::Streaming) {
    std::fprintf(stderr, "bench_bridge_jitter: %s\n", bridge.status(now).reason.c_str());
    return 1;
  }

  std::vector<double> late, period;  // us
  std::vector<char> buf;
  hrp2::PeriodicLoop loop(dt);
  std::int64_t prev = -1;
  const std::int64_t end = hrp2::monotonicMicros() + static_cast<std::int64_t>(seconds * 1e6);
  int warmup = 20;  // the first 0.1 s (first touches of the loop's memory) is not measured
  while ((now = loop.wait()) < end) {
    if (warmup > 0) {
      --warmup;
    } else {
      late.push_back(double(now - loop.deadline()));
      if (prev >= 0) period.push_back(double(now - prev));
    }
    prev = now;
    bridge.onState(robot, now);
    if (auto c = bridge.tick(now)) {
      hrp2_command_t m;
      m.utime = now, m.request_id = c->request_id, m.sequence = c->sequence, m.mode = int8_t(c->mode);
      m.num_joints = static_cast<int32_t>(c->q.size());
      m.q.assign(c->q.data(), c->q.data() + c->q.size());
      m.dq.assign(c->dq.data(), c->dq.data() + c->dq.size());
      buf.resize(m.getEncodedSize());
      m.encode(buf.data(), 0, static_cast<int>(buf.size()));
      robot.q = c->q;
      robot.command_sequence = c->sequence;
      robot.request_id = c->request_id;
    }
  }
  stop = true;
  if (busy.joinable()) busy.join();
  if (planner > 0) {
    kill(-planner, SIGKILL);  // the shell and the planner it runs
    waitpid(planner, nullptr, 0);
  }
  std::vector<double> dev;
  for (double p : period) dev.push_back(std::abs(p - dt * 1e6));
  std::printf("bench_bridge_jitter: %.0f s at %.0f Hz, load %s, %s, %s, %zu periods, %ld skipped\n", seconds, 1 / dt,
              load.c_str(), rt.c_str(), cpu >= 0 ? ("loop on CPU " + std::to_string(cpu) + ", load on the others").c_str() : "no pinning",
              period.size(), loop.skipped());
  std::printf("  wake-up after the deadline (us): median %.0f  p99 %.0f  max %.0f\n", quantile(late, 0.5),
              quantile(late, 0.99), quantile(late, 1.0));
  std::printf("  |period - dt| (us):              median %.0f  p99 %.0f  max %.0f\n", quantile(dev, 0.5),
              quantile(dev, 0.99), quantile(dev, 1.0));
  std::printf("  bridge state at the end: %s\n", hrp2::toString(bridge.state()));
  return 0;
}
