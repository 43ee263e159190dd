// acyclic-view: writes the viewer page for a scenario, its plan and
// optionally the plan's trajectory: DIR/index.html, DIR/viewer.js (three.js
// bundled in) and DIR/data.js (every pose computed here with the project's
// model). The page works offline, from file:// or any static server.
// Exit: 0 written, 1 cannot write (or the page is not built), 2 bad input.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "processes/command_line.h"
#include "planner/common/format_error.h"
#include "viewer/export/view_data.h"

#ifndef ACYCLIC_VIEWER_PAGE_DIR
#define ACYCLIC_VIEWER_PAGE_DIR ""
#endif

using namespace acyclic;
namespace fs = std::filesystem;

namespace {

void writeFile(const fs::path& path, const std::string& a, const std::string& b = "", const std::string& c = "") {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << a << b << c;
    if (!f.flush()) throw std::runtime_error(path.string() + ": cannot write");
  }
  fs::rename(tmp, path);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Writes the viewer page of a plan (and its trajectory): DIR/index.html, DIR/viewer.js, DIR/data.js.\n"
      "Open DIR/index.html in a browser (no network needed). Robot collision shapes, contacts (supporting: green,\n"
      "geometric only: orange), contact forces (the plan's for stances, the independent quasi-static check's\n"
      "for trajectory frames), centre of mass; a timeline to scrub and play; stance by stance.\n"
      "Page URL options: ?stance=I, ?frame=I, ?t=SECONDS, ?strip=I,J,K (stances side by side), &hud=0.\n"
      "Exit: 0 written, 1 cannot write (or the page is not built: scripts/build-viewer), 2 bad input."};
  std::string scenario_path, plan_path, trajectory_path, out, page_dir = ACYCLIC_VIEWER_PAGE_DIR;
  double fps = 25;
  app.add_option("--scenario", scenario_path, "scenario file (acyclic.scenario/1)")->required();
  app.add_option("--plan", plan_path, "plan file (acyclic.plan/1)")->required();
  app.add_option("--trajectory", trajectory_path, "trajectory file (acyclic.trajectory/1) of that plan");
  app.add_option("--out", out, "output folder (created)")->required();
  app.add_option("--fps", fps, "trajectory frames per second shown (each the nearest sample)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0));
  app.add_option("--page", page_dir, "folder holding the built page (index.html, viewer.js)")->capture_default_str();
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  Scenario sc;
  Plan plan;
  Trajectory tr;
  try {
    sc = Scenario::load(scenario_path);
    plan = readPlan(plan_path, sc);
    if (plan.stances.empty()) throw FormatError(plan_path, "stances", "at least one stance");
    if (!trajectory_path.empty()) {
      tr = readTrajectory(trajectory_path, sc);
      for (std::size_t i = 0; i < tr.phases.size(); ++i)
        if (tr.phases[i].stance >= static_cast<int>(plan.stances.size()))
          throw FormatError(trajectory_path, "phases[" + std::to_string(i) + "].stance",
                            "a stance of " + plan_path + " (it has " + std::to_string(plan.stances.size()) +
                                "): is this the trajectory of that plan?");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-view: %s\n", e.what());
    return 2;
  }

  const fs::path page(page_dir);
  for (const char* f : {"index.html", "viewer.js"})
    if (!fs::exists(page / f)) {
      std::fprintf(stderr, "acyclic-view: %s missing: build the page first (scripts/build-viewer %s) or give --page\n",
                   (page / f).c_str(), page_dir.c_str());
      return 1;
    }
  try {
    std::fprintf(stderr, "acyclic-view: %s: %zu stances", sc.name.c_str(), plan.stances.size());
    const auto stances = stancePostures(sc, plan);
    std::vector<ViewPosture> frames;
    if (!trajectory_path.empty()) {
      std::fprintf(stderr, ", trajectory of %.2f s at %g frames/s", tr.duration(), fps);
      frames = trajectoryFrames(sc, tr, fps);
      std::fprintf(stderr, " (%zu frames)", frames.size());
    }
    std::fprintf(stderr, "\n");
    const std::string json = viewDataJson(sc, plan, stances, frames, fps, {scenario_path, plan_path, trajectory_path});
    fs::create_directories(out);
    fs::copy_file(page / "index.html", fs::path(out) / "index.html", fs::copy_options::overwrite_existing);
    fs::copy_file(page / "viewer.js", fs::path(out) / "viewer.js", fs::copy_options::overwrite_existing);
    // A script, not a .json: browsers refuse to fetch files from a file:// page.
    writeFile(fs::path(out) / "data.js", "window.ACYCLIC_DATA = ", json, ";\n");
    std::fprintf(stderr, "acyclic-view: wrote %s (open it in a browser)\n", (fs::path(out) / "index.html").c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-view: %s\n", e.what());
    return 1;
  }
  return 0;
}
