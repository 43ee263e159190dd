// acyclic-replay: replays a recorded pipeline run (an LCM log) into fresh
// processes and checks that they answer exactly as logged: each logged
// ACYCLIC_REQUEST goes to a fresh acyclic-planner, whose ACYCLIC_PLAN must
// equal the logged one (stances, contacts, forces, postures, node and call
// counts; not wall time); where the log shows the plan interpolated, a fresh
// acyclic-interpolator interpolates the fresh planner's plan (with the
// transitions that planner verified, or, with --solve-transitions, solving
// them all itself), and its ACYCLIC_TRAJECTORY must equal the logged one.
// Both are deterministic, so any difference is a regression.
// Exit: 0 identical, 1 a difference or no answer, 2 bad input.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <type_traits>
#include <vector>

#include "processes/command_line.h"
#include "acyclic/plan_t.hpp"
#include "acyclic/process_status_t.hpp"
#include "acyclic/request_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "lcmtypes/channels.hpp"
#include "processes/lcm_process.h"
#include "processes/supervisor.h"

namespace fs = std::filesystem;
using namespace acyclic;

namespace {

void say(const std::string& s) {
  std::printf("acyclic-replay: %s\n", s.c_str());
  std::fflush(stdout);
}

// A message's encoding with the fields that legitimately differ between two
// runs (send time, wall-time figures) cleared.
template <class Msg>
std::vector<char> canonical(Msg m) {
  m.utime = 0;
  if constexpr (std::is_same_v<Msg, plan_t>) m.seconds = 0, m.base_path.clear();  // where the files were, not the plan
  std::vector<char> b(m.getEncodedSize());
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// Every message heard goes through proc::decode: one that does not decode is
// counted and reported, never the replay's end.
struct Ear {
  explicit Ear(proc::StatusReporter& s) : status(s) {}
  proc::StatusReporter& status;
  std::map<std::string, int> status_seen;
  std::optional<plan_t> plan;
  std::optional<trajectory_t> trajectory;
  std::int64_t want = -1;
  void onStatus(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    process_status_t m;
    if (proc::decode(rb, channel, m, status) && m.pid != getpid()) ++status_seen[m.process];
  }
  void onPlan(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    plan_t m;
    if (proc::decode(rb, channel, m, status) && m.request_id == want) plan = std::move(m);
  }
  void onTrajectory(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    trajectory_t m;
    if (proc::decode(rb, channel, m, status) && m.request_id == want) trajectory = std::move(m);
  }
};

// A logged event decoded as Msg; one that does not decode is said and skipped.
template <class Msg>
bool fromLog(const lcm::LogEvent* e, Msg& m, int& skipped) {
  const std::string why = proc::whyNotDecoded(e->data, static_cast<std::size_t>(e->datalen), m);
  if (why.empty()) return true;
  ++skipped;
  say("event " + std::to_string(e->eventnum) + " on " + e->channel + " does not decode as " + Msg::getTypeName() +
      ": " + why + ": skipped");
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Replays a recorded pipeline run (an LCM log written by acyclic-launch or lcm-logger) into fresh\n"
      "acyclic-planner and acyclic-interpolator processes and checks that their answers equal the logged\n"
      "ones (all but send times, wall-time figures and the folder the files were in). Exit status: 0 identical, 1 a difference or no\n"
      "answer, 2 bad input. Run it where LCM multicast works (scripts/netns-run)."};
  std::string log_path, url = proc::defaultLcmUrl(), bin_dir = executableDir();
  double timeout_s = 300;
  app.add_option("log", log_path, "LCM log file")->required();
  app.add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  app.add_option("--bin-dir", bin_dir, "where the acyclic-* executables are (default: beside this one)");
  app.add_option("--timeout", timeout_s, "seconds to wait for each answer")->capture_default_str();
  bool solve_transitions = false;
  app.add_flag("--solve-transitions", solve_transitions,
               "the fresh interpolator solves every transition itself (acyclic-interpolator\n"
               "--no-planner-transitions) instead of taking those the fresh planner verified: replays the\n"
               "interpolator's own solving too (slower; the same trajectory)");
  std::string base_path;
  app.add_option("--base-path", base_path,
                 "resolve the logged scenarios' relative paths (robot, scene) against this folder instead of the one\n"
                 "they were recorded in: a log recorded in another checkout or on another machine")
      ->check(CLI::ExistingDirectory);
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  // What the log holds.
  std::vector<request_t> requests;
  std::map<std::int64_t, plan_t> plans;
  std::map<std::int64_t, trajectory_t> trajectories;
  int skipped = 0;  // logged events that do not decode
  {
    lcm::LogFile log(log_path, "r");
    if (!log.good()) {
      std::fprintf(stderr, "acyclic-replay: %s: cannot read the log\n", log_path.c_str());
      return 2;
    }
    const lcm::LogEvent* e;
    while ((e = log.readNextEvent())) {
      if (e->channel == channels::kRequest) {
        request_t m;
        if (fromLog(e, m, skipped)) requests.push_back(m);
      } else if (e->channel == channels::kPlan) {
        plan_t m;
        if (fromLog(e, m, skipped)) plans[m.request_id] = m;
      } else if (e->channel == channels::kTrajectory) {
        trajectory_t m;
        if (fromLog(e, m, skipped)) trajectories[m.request_id] = m;
      }
    }
  }
  say(log_path + ": " + std::to_string(requests.size()) + " requests, " + std::to_string(plans.size()) +
      " plans, " + std::to_string(trajectories.size()) + " trajectories" +
      (skipped > 0 ? ", " + std::to_string(skipped) + " events that do not decode (skipped)" : ""));
  if (requests.empty()) {
    std::fprintf(stderr, "acyclic-replay: %s: no ACYCLIC_REQUEST to replay\n", log_path.c_str());
    return 2;
  }

  proc::installSignalHandlers();
  int differences = 0;
  try {
    proc::Bus bus(url);
    proc::StatusReporter own_status(bus, "acyclic-replay");
    Ear ear(own_status);
    bus.lcm().subscribe(channels::kStatus, &Ear::onStatus, &ear);
    bus.lcm().subscribe(channels::kPlan, &Ear::onPlan, &ear);
    bus.lcm().subscribe(channels::kTrajectory, &Ear::onTrajectory, &ear);
    Supervisor sup([](const std::string& s) { say(s); });
    const bool interpolate = !trajectories.empty();
    // The guide author serves logged requests whose scenario has no key postures.
    for (const char* name : {"acyclic-guide", "acyclic-planner", "acyclic-interpolator"}) {
      if (std::string(name) == "acyclic-interpolator" && !interpolate) continue;
      ChildSpec c{name, {(fs::path(bin_dir) / name).string(), "--lcm"}, ""};
      if (!url.empty()) c.argv.insert(c.argv.end(), {"--lcm-url", url});
      if (solve_transitions && std::string(name) == "acyclic-interpolator")
        c.argv.push_back("--no-planner-transitions");
      c.respawn = false;
      sup.start(c);
    }
    auto waitFor = [&](auto pred, const std::string& what) {
      const auto t0 = std::chrono::steady_clock::now();
      while (!pred()) {
        if (proc::stopRequested()) throw std::runtime_error("interrupted");
        if (std::chrono::steady_clock::now() - t0 > std::chrono::duration<double>(timeout_s))
          throw std::runtime_error("no " + what + " within " + std::to_string(static_cast<int>(timeout_s)) + " s");
        proc::handlePending(bus, 50);
        sup.poll();
      }
    };
    waitFor([&] { return ear.status_seen["acyclic-planner"] > 0 && ear.status_seen["acyclic-guide"] > 0 &&
                         (!interpolate || ear.status_seen["acyclic-interpolator"] > 0); },
            "status from the fresh processes");
    for (const auto& req : requests) {
      const auto logged = plans.find(req.request_id);
      if (logged == plans.end()) {
        say("request " + std::to_string(req.request_id) + ": the log holds no plan for it: skipped");
        continue;
      }
      ear.want = req.request_id;
      request_t sent = req;
      if (!base_path.empty()) sent.base_path = fs::absolute(base_path).lexically_normal().string();
      ear.plan.reset();
      ear.trajectory.reset();
      bus.publish(channels::kRequest, sent);
      waitFor([&] { return ear.plan.has_value(); }, "plan for request " + std::to_string(req.request_id));
      const bool same = canonical(*ear.plan) == canonical(logged->second);
      differences += !same;
      say("request " + std::to_string(req.request_id) + " (" + req.scenario_name + "): plan " +
          (same ? "identical" : "DIFFERS") + " (" + std::to_string(ear.plan->num_stances) + " stances, " +
          std::to_string(ear.plan->nodes_generated) + " nodes; logged " +
          std::to_string(logged->second.num_stances) + " stances, " +
          std::to_string(logged->second.nodes_generated) + " nodes)");
      const auto logged_tr = trajectories.find(req.request_id);
      if (logged_tr != trajectories.end() && ear.plan->status == plan_t::OK) {
        waitFor([&] { return ear.trajectory.has_value(); },
                "trajectory for request " + std::to_string(req.request_id));
        const bool same_tr = canonical(*ear.trajectory) == canonical(logged_tr->second);
        differences += !same_tr;
        say("request " + std::to_string(req.request_id) + ": trajectory " + (same_tr ? "identical" : "DIFFERS") +
            " (" + std::to_string(ear.trajectory->num_samples) + " samples; logged " +
            std::to_string(logged_tr->second.num_samples) + ")");
      }
    }
    sup.stopAll();
  } catch (const std::exception& e) {
    say(std::string("error: ") + e.what());
    return 1;
  }
  say(differences == 0 ? "every answer identical to the log" : std::to_string(differences) + " answers differ");
  return differences == 0 ? 0 : 1;
}
