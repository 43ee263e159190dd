// acyclic-plot: the figures of a run, as SVG: joint angles and velocities
// over a trajectory with their limits, the stability margin along it (the
// independent quasi-static check), and the planner's best potential and tree
// size over time from a run's LCM log (ACYCLIC_PROGRESS messages).
// Exit: 0 written, 1 cannot write or nothing to plot in the log, 2 bad input.
#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <filesystem>

#include "processes/command_line.h"
#include "acyclic/progress_t.hpp"
#include "processes/guarded_decode.h"
#include "lcmtypes/channels.hpp"
#include "planner/common/format_error.h"
#include "viewer/plot/figures.h"

using namespace acyclic;
namespace fs = std::filesystem;

namespace {

// The planner's ACYCLIC_PROGRESS messages of a log, in log order.
std::vector<PlannerProgressPoint> readProgress(const std::string& path, const std::string& source) {
  if (!fs::exists(path)) throw FormatError(path, "", "an LCM log file (not found)");
  lcm::LogFile log(path, "r");
  if (!log.good()) throw FormatError(path, "", "an LCM log file (cannot open)");
  std::vector<PlannerProgressPoint> out;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (ev->channel != channels::kProgress) continue;
    acyclic::progress_t m;
    const std::string why = proc::whyNotDecoded(ev->data, static_cast<std::size_t>(ev->datalen), m);
    if (!why.empty())
      throw FormatError(path, "event " + std::to_string(ev->eventnum),
                        "a progress_t message on " + std::string(channels::kProgress) + " (" + why + ")");
    if (m.source != source) continue;
    out.push_back({m.elapsed_s, static_cast<long>(m.nodes_generated), static_cast<long>(m.posture_calls),
                   m.best_potential});
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Writes the figures of a run as SVG into DIR:\n"
      "  with --trajectory: joint_angles.svg, joint_velocities.svg (with limits), stability.svg (friction margin,\n"
      "  worst ||f_t|| / (mu f_n) and worst torque ratio of the independent quasi-static check at each frame);\n"
      "  with --log (a run's run.lcmlog): planner_progress.svg (best potential, nodes generated, posture calls\n"
      "  over time, from the planner's ACYCLIC_PROGRESS messages).\n"
      "Exit: 0 written, 1 cannot write or no progress message in the log, 2 bad input."};
  std::string scenario_path, trajectory_path, log_path, out, source = "acyclic-planner";
  double fps = 25;
  app.add_option("--scenario", scenario_path, "scenario file (acyclic.scenario/1)")->required();
  app.add_option("--trajectory", trajectory_path, "trajectory file (acyclic.trajectory/1)");
  app.add_option("--log", log_path, "LCM log of a run (run.lcmlog)");
  app.add_option("--source", source, "process whose progress messages are plotted")->capture_default_str();
  app.add_option("--fps", fps, "frames per second where the stability margin is evaluated")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0));
  app.add_option("--out", out, "output folder (created)")->required();
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)
  if (trajectory_path.empty() && log_path.empty()) {
    std::fprintf(stderr, "acyclic-plot: nothing to plot: give --trajectory and/or --log\n");
    return 2;
  }
  Scenario sc;
  Trajectory tr;
  std::vector<PlannerProgressPoint> progress;
  try {
    sc = Scenario::load(scenario_path);
    if (!trajectory_path.empty()) tr = readTrajectory(trajectory_path, sc);
    if (!log_path.empty()) progress = readProgress(log_path, source);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-plot: %s\n", e.what());
    return 2;
  }
  try {
    fs::create_directories(out);
    auto write = [&](const PlotFigure& f, const char* name) {
      const std::string path = (fs::path(out) / name).string();
      writeSvg(f, path);
      std::fprintf(stderr, "acyclic-plot: wrote %s\n", path.c_str());
    };
    if (!trajectory_path.empty()) {
      write(jointAnglesFigure(sc, tr), "joint_angles.svg");
      write(jointVelocitiesFigure(sc, tr), "joint_velocities.svg");
      std::fprintf(stderr, "acyclic-plot: independent check at %g frames/s over %.2f s...\n", fps, tr.duration());
      write(stabilityFigure(sc, trajectoryFrames(sc, tr, fps)), "stability.svg");
    }
    if (!log_path.empty()) {
      if (progress.empty()) {
        std::fprintf(stderr, "acyclic-plot: %s: no %s message from %s\n", log_path.c_str(), channels::kProgress,
                     source.c_str());
        return 1;
      }
      write(plannerProgressFigure(sc.name + ": planner progress (" + std::to_string(progress.size()) + " messages)",
                                  progress),
            "planner_progress.svg");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-plot: %s\n", e.what());
    return 1;
  }
  return 0;
}
