// Every scenario shipped in models/scenarios planned by the full planner, one
// after the other in one run: result, wall time, nodes, posture calls and
// failures, plan length, the non-foot contacts the plan uses, and the
// independent check's verdict on the plan. A scenario without key postures
// is guided by the OMPL author first (planner/guide/guide_author.h); its
// time is in the wall time.
// Usage: bench_scenarios [SCENARIO...] [OPTIONS]   (default: every shipped scenario); --help lists the options.
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "scenario_runs.h"

#include "planner/common/fmt.h"
#include "planner/guide/guide_author.h"
#include "planner/plan/guide.h"
#include "planner/posture/heap_tuning.h"

using namespace acyclic;

namespace {

// The published run the scenario reproduces (its `published:` section), and
// this run against it (`seconds`: the row's, the guide's included): nodes
// (the plan's search, and with a portfolio every member's) and stances as
// ratios, time as a factor faster or slower.
void printPublished(const Scenario& sc, const PlanningResult& r, double seconds) {
  const PublishedRun& ref = *sc.published;
  std::string figures, against;
  auto add = [](std::string& to, const std::string& what) { to += (to.empty() ? "" : ", ") + what; };
  auto times = [](double x) { return fmt(x >= 10 ? "%.0f times" : "%.1f times", x); };
  if (ref.nodes > 0) {
    add(figures, fmt("%.0f nodes", static_cast<double>(ref.nodes)));
    if (r.solved())
      add(against, fmt("%.2f times its nodes", static_cast<double>(r.stats.nodes_generated) / ref.nodes) +
                       (r.members.empty() ? "" : fmt(" (%.2f with every member's)",
                                                     static_cast<double>(r.portfolioNodes()) / ref.nodes)) +
                       // The paper does not say whether its count includes the
                       // leaves it discarded as too close to a node; ours does.
                       fmt(", %.0f of ours dropped as duplicates of a node", static_cast<double>(r.stats.duplicates)));
  }
  if (ref.stances > 0) {
    add(figures, fmt("%.0f stances", static_cast<double>(ref.stances)));
    if (r.solved())
      add(against, fmt("%.2f times its stances", static_cast<double>(r.plan.stances.size()) / ref.stances));
  }
  if (ref.seconds > 0) {
    add(figures, fmt("%.0f s", ref.seconds) + (ref.machine.empty() ? "" : " on " + ref.machine));
    if (r.solved() && seconds > 0)
      add(against, ref.seconds >= seconds ? times(ref.seconds / seconds) + " faster"
                                          : times(seconds / ref.seconds) + " slower");
  }
  std::printf("%-14s   published: %s: %s%s\n", "", ref.source.c_str(), figures.empty() ? "no figures" : figures.c_str(),
              against.empty() ? "" : ("; this run " + against).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  std::vector<std::string> paths;
  bench::PlannerOverrides overrides;
  CLI::App app{"Every scenario shipped in models/scenarios planned by the full planner, one after the other in one\n"
               "run: result, wall time, nodes, posture calls and failures, plan length, the non-foot contacts the\n"
               "plan uses, and the independent check's verdict on the plan."};
  app.add_option("scenario", paths, "scenario files (acyclic.scenario/1; default: every models/scenarios/*.yaml)");
  overrides.addOptions(app, "scenario");
  GuideOptions guide_options;
  app.add_flag("--stable-guide", guide_options.stable,
               "scenarios without key postures: the OMPL guide through the statically stable subspace "
               "(acyclic-guide --stable)");
  app.add_flag("--edge-samples-guide", guide_options.sample_edges,
               "scenarios without key postures: the OMPL guide's key postures sampled along its edges as with "
               "--stable-guide, not projected (a control)");
  std::string guide_file;
  app.add_option("--guide", guide_file,
                 "key postures from this guide file (acyclic.guide/1) instead of the scenario's, as acyclic-planner "
                 "--guide (e.g. models/guides/chair_paper_hand_on_chair.guide.json for chair_paper)")
      ->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);
  if (paths.empty()) paths = bench::shippedScenarios();
  if (!overrides.acceptedBy(paths, "bench_scenarios")) return 2;
  std::printf("%-14s %-16s %9s %7s %7s %7s %8s %-7s %s\n", "scenario", "result", "seconds", "nodes", "calls",
              "failed", "stances", "check", "non-foot contacts used");
  for (const auto& path : paths) {
    Scenario sc;
    try {  // a bad file is said with its name and field, not an abort
      sc = Scenario::load(path);
      if (!guide_file.empty()) sc.key_postures = readGuide(guide_file, sc).key_postures;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_scenarios: %s\n", e.what());
      return 2;
    }
    double guide_seconds = 0;
    const bool guided = sc.key_postures.size() < 2;
    std::string guide_kind;
    if (guided) {
      const GuideResult g = authorGuide(sc, guide_options);
      guide_seconds = g.goal_seconds + g.path_seconds + g.stable_seconds;
      guide_kind = std::string(g.approach ? ", through an approach posture" : "") + (g.crouch ? ", crouched" : "") +
                   (g.crawl ? ", crawling" : "") +
                   (guide_options.stable ? fmt(", stable: %.0f projections, %.0f replans", g.stable_projections,
                                               g.stable_replans)
                                         : "");
      if (!g.success()) {
        std::printf("%-14s %-16s %9.2f  the OMPL guide author: %s\n", sc.name.c_str(), "no guide", guide_seconds,
                    g.reason.c_str());
        continue;
      }
      sc.key_postures = g.guide.key_postures;
    }
    const PlanningResult r = ContactPlanner(sc, overrides.parameters(sc)).plan();
    const std::string verdict = bench::planVerdict(r, sc);
    std::string used;
    if (r.solved()) {
      std::set<std::string> names;
      for (const auto& st : r.plan.stances)
        for (const auto& c : st.contacts) {
          const std::string& n = sc.robot->spots()[c.spec.spot].name;
          if (n != "r_sole" && n != "l_sole") names.insert(n + "@" + sc.scene->surfaces()[c.spec.surface].name);
        }
      for (const auto& n : names) used += (used.empty() ? "" : " ") + n;
    }
    std::printf("%-14s %-16s %9.2f %7ld %7ld %7ld %8zu %-7s %s\n", sc.name.c_str(), toString(r.status),
                guide_seconds + r.stats.seconds, r.stats.nodes_generated, r.stats.posture_calls, r.stats.posture_failures,
                r.plan.stances.size(), verdict.c_str(), used.empty() ? "none" : used.c_str());
    if (!guide_file.empty())
      std::printf("%-14s   guided by %s: %zu key postures\n", "", guide_file.c_str(), sc.key_postures.size());
    if (guided)
      std::printf("%-14s   guided by the OMPL author: %zu key postures in %.2f s%s\n", "", sc.key_postures.size(),
                  guide_seconds, guide_kind.c_str());
    if (!r.members.empty()) {
      std::string each;
      for (std::size_t i = 0; i < r.members.size(); ++i)
        each += std::string(i ? ", " : "") + r.members[i].name + " " +
                (static_cast<int>(i) == r.winner ? "(its plan)" : toString(r.members[i].status)) + " " +
                std::to_string(r.members[i].stats.nodes_generated);
      // A sequence's members after its winner did not run, and are not listed.
      std::printf("%-14s   the portfolio's searches that ran, %zu: %ld nodes generated by them (%s)\n", "", r.members.size(),
                  r.portfolioNodes(), each.c_str());
    }
    if (sc.published) printPublished(sc, r, guide_seconds + r.stats.seconds);
    bench::printVerification(r);
    std::fflush(stdout);
  }
  return 0;
}
