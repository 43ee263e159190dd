// acyclic-launch: runs the whole pipeline on one machine (docs/design.md section 2).
// Starts lcm-logger and the pipeline's processes, sends the scenario as one
// ACYCLIC_REQUEST, follows progress, writes what comes back (plan,
// trajectory) under the output folder, restarts a process that dies (and
// re-sends it the work it lost), and stops everything it started on exit or
// on Ctrl-C. Exit: 0 all stages answered OK, 1 a stage failed or timed out,
// 2 bad input.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "processes/command_line.h"
#include "acyclic/hrp2_bridge_status_t.hpp"
#include "processes/bridge_outcome.h"
#include "acyclic/plan_t.hpp"
#include "acyclic/process_status_t.hpp"
#include "acyclic/progress_t.hpp"
#include "acyclic/request_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "lcmtypes/channels.hpp"
#include "planner/common/format_error.h"
#include "planner/plan/json_field.h"
#include "processes/lcm_convert.h"
#include "processes/lcm_process.h"
#include "processes/supervisor.h"

namespace fs = std::filesystem;
using namespace acyclic;

namespace {

void say(const std::string& s) {
  std::printf("acyclic-launch: %s\n", s.c_str());
  std::fflush(stdout);
}

// What the launcher hears on LCM. Every message goes through proc::decode:
// one that does not decode is counted and reported, never the launcher's end.
struct Listener {
  explicit Listener(proc::StatusReporter& s) : status(s) {}
  proc::StatusReporter& status;
  std::int64_t request_id = 0;
  std::map<std::string, int> status_seen;  // process -> status messages since (re)start
  // Idle reports since the launcher last handed that process work: a process
  // idle for three heartbeats without having answered never got the work, or
  // its answer never arrived (UDP drops a message when a socket's receive
  // buffer is full, e.g. under a flood).
  std::map<std::string, int> idle_since_work;
  std::optional<plan_t> plan;
  std::optional<trajectory_t> trajectory;
  std::optional<hrp2_bridge_status_t> played;   // the bridge's last status about our request
  bool tty = false;

  void onStatus(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    process_status_t m;
    if (!proc::decode(rb, channel, m, status)) return;
    if (m.pid == getpid()) return;  // its own reports (already said)
    ++status_seen[m.process];
    if (m.state == process_status_t::IDLE) ++idle_since_work[m.process];
    if (m.state == process_status_t::ERROR)
      say(m.process + " reports an error" +
          (m.request_id >= 0 ? " on request " + std::to_string(m.request_id) : std::string()) + ": " + m.reason);
  }
  void onProgress(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    progress_t m;
    if (!proc::decode(rb, channel, m, status)) return;
    if (m.request_id != request_id || !tty) return;
    std::fprintf(stderr, "\r%s %s: %6.1f s  nodes %ld  posture calls %ld  best %.3f  %s   ", m.source.c_str(),
                 m.stage.c_str(), m.elapsed_s, static_cast<long>(m.nodes_generated),
                 static_cast<long>(m.posture_calls), m.best_potential, m.message.c_str());
  }
  // A refusal because the service is busy with this very request answers a
  // second copy of the work (sent again when it looked lost), not the work:
  // the first copy's answer is still to come.
  bool busyWithOurs(const std::string& reason) const { return proc::isBusyWith(reason, request_id); }
  void onPlan(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    plan_t m;
    if (!proc::decode(rb, channel, m, status)) return;
    if (m.request_id == request_id && !busyWithOurs(m.reason)) plan = std::move(m);
  }
  void onTrajectory(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    trajectory_t m;
    if (!proc::decode(rb, channel, m, status)) return;
    if (m.request_id == request_id && !busyWithOurs(m.reason)) trajectory = std::move(m);
  }
  void onBridge(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    hrp2_bridge_status_t m;
    if (!proc::decode(rb, channel, m, status)) return;
    if (m.request_id != request_id) return;
    played = m;
    if (tty && m.state == hrp2_bridge_status_t::STREAMING)
      std::fprintf(stderr, "\racyclic-hrp2-bridge: streaming %5.1f %%  commands %ld  worst tracking error %.4f rad   ",
                   100 * m.progress, static_cast<long>(m.commands_sent), m.tracking_error_max);
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Runs the Acyclic pipeline on one machine: lcm-logger, acyclic-guide (for a scenario without key\n"
      "postures), acyclic-planner and acyclic-interpolator (each with --lcm), then sends the scenario as\n"
      "one ACYCLIC_REQUEST and waits for the plan and the trajectory. Writes under --out: plan.json\n"
      "(acyclic.plan/1), trajectory.json (acyclic.trajectory/1), run.lcmlog (every message of the run)\n"
      "and one log per process; then plays\n"
      "the trajectory through acyclic-hrp2-bridge on acyclic-hrp2-sim (the simulated controller) and\n"
      "reports the tracking error and any safety event (--no-execute: stop at the trajectory).\n"
      "A process that dies is restarted (3 times at most) and given again the work it lost; one that\n"
      "cannot be restarted fails the run at once (exit status 1, with the reason).\n"
      "Everything started is stopped on exit and on Ctrl-C.\n"
      "Exit status: 0 every stage answered OK, 1 a stage failed or timed out, 2 bad input.\n"
      "Multicast: run it inside a private network namespace (scripts/run-pipeline does) or on a lab\n"
      "network with ttl=1 (docs/design.md section 2, 'Across machines')."};
  std::string scenario_path, out_dir = "acyclic-run", url = proc::defaultLcmUrl(), bin_dir = executableDir();
  double timeout_s = 3600;  // the chair: planning takes minutes, and its motion plays in real time
  long seed = -1;
  double budget_s = -1;
  std::int64_t request_id = 1;
  bool no_interpolate = false, quiet = false, external = false, no_execute = false;
  std::vector<std::string> planner_args;
  // Against the simulator on a shared machine, the bridge's watchdogs get the
  // simulator's configuration (hrp2_bridge/config/simulated.yaml says why).
  std::string bridge_config = ACYCLIC_SOURCE_DIR "/hrp2_bridge/config/simulated.yaml";
  app.add_option("--scenario", scenario_path, "scenario file (acyclic.scenario/1)")->required();
  app.add_option("--out", out_dir, "output folder (created)")->capture_default_str();
  app.add_option("--lcm-url", url, "LCM URL for every process (default: $LCM_DEFAULT_URL, else LCM's default)");
  app.add_option("--bin-dir", bin_dir, "where the acyclic-* executables are (default: beside this one)");
  app.add_option("--timeout", timeout_s, "seconds to wait for the whole run")->capture_default_str();
  app.add_option("--seed", seed, "request seed (default: the scenario's)");
  app.add_option("--max-seconds", budget_s, "planning budget sent with the request (default: the scenario's)");
  app.add_option("--request-id", request_id, "id of the request")->capture_default_str();
  app.add_flag("--no-interpolate", no_interpolate, "stop after the plan");
  app.add_flag("--no-execute", no_execute,
               "stop after the trajectory (default: play it through acyclic-hrp2-bridge on acyclic-hrp2-sim)");
  app.add_flag("--external", external,
               "use pipeline processes already running (on this or other machines): start only lcm-logger");
  app.add_option("--bridge-config", bridge_config, "acyclic-hrp2-bridge's configuration (acyclic.hrp2_bridge/1)")
      ->capture_default_str();
  app.add_option("--planner-arg", planner_args, "extra argument for acyclic-planner (repeatable)");
  std::vector<std::string> settings;
  app.add_option("--set", settings,
                 "a key of the scenario's planner section, given to acyclic-planner and acyclic-interpolator alike "
                 "(their --set; repeatable), so that the plan is interpolated as it was verified")
      ->type_name("KEY=VALUE");
  app.add_flag("-q,--quiet", quiet, "no progress line");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  Scenario sc;
  try {
    sc = Scenario::load(scenario_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-launch: %s\n", e.what());
    return 2;
  }
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "acyclic-launch: cannot create %s: %s\n", out_dir.c_str(), ec.message().c_str());
    return 2;
  }
  proc::installSignalHandlers();

  Supervisor sup([](const std::string& s) { say(s); });
  // The guide author serves scenarios without key postures (it ignores the others).
  std::vector<std::string> stages = {"acyclic-guide", "acyclic-planner"};
  if (!no_interpolate) stages.push_back("acyclic-interpolator");
  // Execution: the HRP-2 bridge and the simulated controller, when built.
  const bool execute = !no_interpolate && !no_execute && fs::exists(fs::path(bin_dir) / "acyclic-hrp2-bridge") &&
                       fs::exists(fs::path(bin_dir) / "acyclic-hrp2-sim");
  int rc = 1;
  try {
    proc::Bus bus(url);
    proc::StatusReporter own_status(bus, "acyclic-launch");
    Listener ear(own_status);
    ear.request_id = request_id;
    ear.tty = !quiet && isatty(STDERR_FILENO);
    bus.lcm().subscribe(channels::kStatus, &Listener::onStatus, &ear);
    bus.lcm().subscribe(channels::kProgress, &Listener::onProgress, &ear);
    bus.lcm().subscribe(channels::kPlan, &Listener::onPlan, &ear);
    bus.lcm().subscribe(channels::kTrajectory, &Listener::onTrajectory, &ear);
    bus.lcm().subscribe(channels::kHrp2BridgeStatus, &Listener::onBridge, &ear);

    // The logger first, so that the log holds the whole run.
    const std::string log_path = (fs::path(out_dir) / "run.lcmlog").string();
    ChildSpec logger{"lcm-logger", {"/usr/bin/lcm-logger", "-f", "-q"}, (fs::path(out_dir) / "lcm-logger.log").string()};
    if (!url.empty()) logger.argv.push_back("--lcm-url=" + url);
    logger.argv.push_back(log_path);
    sup.start(logger);
    for (const auto& name : stages) {
      if (external) break;
      ChildSpec c{name, {(fs::path(bin_dir) / name).string(), "--lcm"}, (fs::path(out_dir) / (name + ".log")).string()};
      if (!url.empty()) c.argv.insert(c.argv.end(), {"--lcm-url", url});
      if (name == "acyclic-planner") c.argv.insert(c.argv.end(), planner_args.begin(), planner_args.end());
      if (name == "acyclic-planner" || name == "acyclic-interpolator")
        for (const auto& kv : settings) c.argv.insert(c.argv.end(), {"--set", kv});
      sup.start(c);
    }

    if (execute && !external)
      for (const char* name : {"acyclic-hrp2-sim", "acyclic-hrp2-bridge"}) {
        ChildSpec c{name, {(fs::path(bin_dir) / name).string(), "--scenario", fs::absolute(scenario_path).string()},
                    (fs::path(out_dir) / (std::string(name) + ".log")).string()};
        if (!url.empty()) c.argv.insert(c.argv.end(), {"--lcm-url", url});
        if (std::string(name) == "acyclic-hrp2-bridge" && !bridge_config.empty())
          c.argv.insert(c.argv.end(), {"--config", bridge_config});
        sup.start(c);
      }

    request_t req{};
    req.request_id = request_id;
    req.scenario_name = sc.name;
    req.scenario_yaml = json_field::readWholeFile(scenario_path);
    req.base_path = fs::absolute(scenario_path).parent_path().string();
    req.seed = seed;
    req.time_budget_s = budget_s;

    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    auto allUp = [&] {
      for (const auto& s : stages)
        if (ear.status_seen[s] == 0) return false;
      return true;
    };
    bool request_sent = false, plan_sent_on = false, failed = false, done = false;
    bool lost_work_plan = false, trajectory_written = false;
    int resent = 0;  // work handed again after it was lost on the way (kMaxResends at most)
    constexpr int kMaxResends = 3, kIdleReportsMeanLost = 3;
    double play_deadline = 0;
    while (!proc::stopRequested() && !done && !failed) {
      proc::handlePending(bus, 50);
      std::vector<std::string> gone;
      for (const auto& name : sup.poll(&gone)) {
        ear.status_seen[name] = 0;  // wait for the new instance's first status
        // The request again: the planner lost it. (A guide author that dies
        // leaves the planner waiting; the planner then answers with the reason.)
        if (name == "acyclic-planner" && request_sent && !ear.plan) request_sent = false;
        if (name == "acyclic-interpolator" && ear.plan && !ear.trajectory && !trajectory_written) lost_work_plan = true;
      }
      if (!gone.empty()) {
        // A stage that cannot be restarted fails the run now: waiting for its answer would last the whole timeout.
        say("failed: " + gone.front() + " (see its log in " + out_dir + ")");
        failed = true;
        break;
      }
      if (elapsed() > timeout_s) {
        say("timed out after " + std::to_string(static_cast<int>(timeout_s)) + " s");
        failed = true;
        break;
      }
      if (!request_sent) {
        if (!allUp()) {
          if (elapsed() > 30 && !ear.plan) {
            say("the pipeline's processes did not report within 30 s (see the logs in " + out_dir + ")");
            failed = true;
          }
          continue;
        }
        req.utime = proc::nowMicros();
        bus.publish(channels::kRequest, req);
        request_sent = true;
        ear.idle_since_work["acyclic-planner"] = 0;
        say("request " + std::to_string(request_id) + " sent: " + sc.name);
      }
      if (!ear.plan && ear.idle_since_work["acyclic-planner"] >= kIdleReportsMeanLost && resent < kMaxResends) {
        say("acyclic-planner is idle and no plan came: the request or the plan was lost on the way; sending it again");
        ++resent;
        request_sent = false;
        continue;
      }
      // Only once the plan has been handed on (plan_sent_on, below, restarts
      // the count): the interpolator reported idle all through the planning,
      // and a plan that had just arrived was sent again at once, refused as a
      // second copy ("busy with request N") and the run failed on it.
      if (plan_sent_on && ear.plan->status == plan_t::OK && !no_interpolate && !ear.trajectory &&
          !trajectory_written && ear.idle_since_work["acyclic-interpolator"] >= kIdleReportsMeanLost &&
          resent < kMaxResends) {
        say("acyclic-interpolator is idle and no trajectory came: the plan or the trajectory was lost on the way; "
            "sending the plan again");
        ++resent;
        lost_work_plan = true;
        ear.idle_since_work["acyclic-interpolator"] = 0;
      }
      // The interpolator restarted after the plan went out: hand it the plan again.
      if (lost_work_plan && ear.plan && ear.status_seen["acyclic-interpolator"] > 0) {
        bus.publish(channels::kPlan, *ear.plan);
        lost_work_plan = false;
      }
      if (ear.plan && !plan_sent_on) {
        plan_sent_on = true;
        ear.idle_since_work["acyclic-interpolator"] = 0;  // the interpolator heard the plan too
        if (ear.tty) std::fprintf(stderr, "\n");
        const plan_t& m = *ear.plan;
        say("plan: status " + std::to_string(m.status) + (m.reason.empty() ? "" : " (" + m.reason + ")") + ", " +
            std::to_string(m.num_stances) + " stances, " + std::to_string(m.nodes_generated) + " nodes, " +
            std::to_string(m.posture_calls) + " posture calls, " + std::to_string(m.seconds) + " s");
        if (m.status != plan_t::OK) {
          failed = true;
          break;
        }
        const std::string plan_path = (fs::path(out_dir) / "plan.json").string();
        Plan plan = convert::fromMessage(m, sc);
        plan.scenario = fs::absolute(scenario_path).string();
        writePlan(plan, sc, plan_path);
        say("wrote " + plan_path);
        if (no_interpolate) done = true;
      }
      if (ear.trajectory) {
        const trajectory_t& m = *ear.trajectory;
        if (ear.tty) std::fprintf(stderr, "\n");
        if (m.status != trajectory_t::OK) {
          say("trajectory: failed: " + m.reason);
          failed = true;
          break;
        }
        Trajectory tr = convert::fromMessage(m, sc);
        tr.scenario = fs::absolute(scenario_path).string();
        tr.plan = (fs::absolute(out_dir) / "plan.json").string();
        const std::string tr_path = (fs::path(out_dir) / "trajectory.json").string();
        writeTrajectory(tr, sc, tr_path);
        say("wrote " + tr_path + " (" + std::to_string(m.num_samples) + " samples, " +
            std::to_string(tr.duration()) + " s of motion)");
        if (!execute) {
          done = true;
        } else {
          say("playing it on the simulated controller (acyclic-hrp2-bridge -> acyclic-hrp2-sim)");
          play_deadline = elapsed() + tr.duration() + 60;
        }
        ear.trajectory.reset();
        trajectory_written = true;
      }
      if (trajectory_written && execute && ear.played) {
        const hrp2_bridge_status_t& b = *ear.played;
        const proc::BridgeOutcome outcome = proc::bridgeOutcome(b, request_id);
        const bool finished = outcome == proc::BridgeOutcome::Finished;
        if (outcome != proc::BridgeOutcome::Going) {
          if (ear.tty) std::fprintf(stderr, "\n");
          say(std::string("execution ") + (finished ? "done" : "FAILED") + ": " + b.reason + "; " +
              std::to_string(b.commands_sent) + " commands, worst tracking error " +
              std::to_string(b.tracking_error_max) + " rad, " + std::to_string(b.safety_events) + " safety events");
          if (finished) done = true;
          else failed = true;
        }
      }
      if (trajectory_written && execute && elapsed() > play_deadline) {
        say("execution: the bridge did not report the end of the motion in time (see acyclic-hrp2-bridge.log)");
        failed = true;
      }
    }
    if (proc::stopRequested()) say("interrupted: stopping every process");
    rc = done ? 0 : (proc::stopRequested() ? 130 : 1);
  } catch (const std::exception& e) {
    say(std::string("error: ") + e.what());
    rc = 1;
  }
  // Give lcm-logger a moment to write the last messages before it stops.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  sup.stopAll();
  say("log of every message: " + (fs::path(out_dir) / "run.lcmlog").string());
  return rc;
}
