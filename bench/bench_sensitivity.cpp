// How much the contact search depends on the last bits of its witnesses: one
// scenario planned under perturbations that change no stance's validity,
// only the numbers the posture generator returns: the start's base moved by
// 1e-9 m, the other distance engine (FCL or the generator's own GJK), the
// other KKT variant (exact Hessian or L-BFGS in the KKT system), Ipopt's
// other barrier oracle, the seed (the search draws nothing at random with
// optimized candidates, so the seed is a control: the same nodes). Prints each run (result, nodes, seconds)
// and the spread: the median, and the largest and smallest over the median.
// A scenario with a portfolio (planner: portfolio) is planned with it, each
// member perturbed: the winner's nodes, and those of all the members
// (the loser stops past the winner's count); --member plans with one alone.
// Usage: bench_sensitivity [SCENARIO] [OPTIONS]   (default: chair_table); --help lists the options.
#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_checks.h"

#include "planner/plan/guide.h"
#include "planner/posture/heap_tuning.h"
#include "planner/search/planner_parameters.h"

using namespace acyclic;

namespace {

// A perturbation of the scenario, or of the planner's parameters: with a
// portfolio, of each member's (applied after the member's own changes).
struct Variant {
  std::string name;
  std::function<void(Scenario&)> scenario;
  std::function<void(PlannerParameters&)> params;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  std::string path = ACYCLIC_SOURCE_DIR "/models/scenarios/chair_table.yaml";
  double max_seconds = -1;
  int max_nodes = -1;
  int threads = 2;
  std::string member;  // of the scenario's portfolio, alone
  std::vector<std::string> settings;  // --set KEY=VALUE of its planner section
  std::vector<std::string> only;
  auto shift = [](int axis, double by) {
    return [axis, by](Scenario& sc) { sc.start.base_position[axis] += by; };
  };
  const std::vector<Variant> variants = {
      {"as shipped", {}, {}},
      {"start x + 1e-9 m", shift(0, 1e-9), {}},
      {"start y + 1e-9 m", shift(1, 1e-9), {}},
      {"start z + 1e-9 m", shift(2, 1e-9), {}},
      {"start x - 1e-9 m", shift(0, -1e-9), {}},
      {"start y - 1e-9 m", shift(1, -1e-9), {}},
      {"start z - 1e-9 m", shift(2, -1e-9), {}},
      // Each the other choice than the scenario's (the planner's defaults: FCL, exact Hessian, quality function).
      {"other distance engine", {},
       [](PlannerParameters& p) {
         p.posture.distance_engine =
             p.posture.distance_engine == DistanceEngine::Fcl ? DistanceEngine::Convex : DistanceEngine::Fcl;
       }},
      {"other KKT Hessian", {}, [](PlannerParameters& p) { p.posture.lbfgs_in_kkt = !p.posture.lbfgs_in_kkt; }},
      {"other mu oracle", {},
       [](PlannerParameters& p) {
         p.posture.mu_oracle = p.posture.mu_oracle == "probing" ? "quality-function" : "probing";
       }},
      {"seed 2", [](Scenario& sc) { sc.seed = 2; }, {}},
  };
  CLI::App app{"One scenario planned under perturbations that change only the last bits of the witnesses (the start\n"
               "moved by 1e-9 m, the other distance engine, KKT variant or barrier oracle, the seed): each run's\n"
               "result, nodes and time, and the spread of the node counts about their median."};
  app.add_option("scenario", path, "scenario file (acyclic.scenario/1; default: models/scenarios/chair_table.yaml)");
  app.add_option("--max-seconds", max_seconds, "time budget per run, s (default: the scenario's)")
      ->check(acyclic::bench::positive());
  app.add_option("--max-nodes", max_nodes, "node budget per run (default: the scenario's)")->check(CLI::PositiveNumber);
  std::vector<std::string> names;
  for (const auto& v : variants) names.push_back(v.name);
  app.add_option("--only", only, "run only these perturbations, by name (repeatable; default: all)")
      ->check(CLI::IsMember(names));
  app.add_option("--threads", threads, "posture generators at once (the plan does not depend on it)")->capture_default_str();
  app.add_option("--set", settings,
                 "a key of the scenario's planner section, as if its file said so (repeatable; VALUE read as "
                 "YAML, null for the key's default), applied before --member, as acyclic-planner --set")
      ->type_name("KEY=VALUE");
  app.add_option("--member", member,
                 "of the scenario's portfolio (planner: portfolio), plan with this member alone, by name "
                 "(default: the whole portfolio)");
  std::string guide_file, watch;
  app.add_option("--guide", guide_file,
                 "key postures from this guide file (acyclic.guide/1) instead of the scenario's, as acyclic-planner "
                 "--guide")
      ->check(CLI::ExistingFile);
  app.add_option("--watch", watch,
                 "SPOT@SURFACE: a column with the number of stances of each run's plan in which that contact "
                 "supports (e.g. r_palm@chair_seat: does the plan lean on the chair?)");
  CLI11_PARSE(app, argc, argv);

  // Loaded and read once, before any run (a bad scenario is said with its
  // file and field, not an abort); each run perturbs its own copy.
  Scenario loaded;
  PlannerParameters shipped;
  int watch_spot = -1, watch_surface = -1;
  try {
    loaded = Scenario::load(path);
    if (!guide_file.empty()) loaded.key_postures = readGuide(guide_file, loaded).key_postures;
    if (!watch.empty()) {
      const auto at = watch.find('@');
      watch_spot = at == std::string::npos ? -1 : loaded.robot->spotIndex(watch.substr(0, at));
      watch_surface = at == std::string::npos ? -1 : loaded.scene->surfaceIndex(watch.substr(at + 1));
      if (watch_spot < 0 || watch_surface < 0)
        throw std::invalid_argument("--watch " + watch + ": SPOT@SURFACE, a spot of " + path +
                                    "'s robot and a surface of its scene");
    }
    setPlannerKeys(loaded, settings);
    shipped = plannerParameters(loaded);
    if (!member.empty()) keepPortfolioMember(shipped, member, path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_sensitivity: %s\n", e.what());
    return 2;
  }
  const bool portfolio = !shipped.portfolio.empty();
  std::printf("%-22s %-16s %7s %9s%s%s\n", "perturbation", "result", "nodes", "seconds",
              watch.empty() ? "" : ("  stances on " + watch).c_str(),
              portfolio ? "  winner (nodes generated by all the members)" : "");
  std::vector<double> nodes, all_nodes;
  int solved = 0, runs = 0;
  for (const auto& v : variants) {
    if (!only.empty() && std::find(only.begin(), only.end(), v.name) == only.end()) continue;
    ++runs;
    Scenario sc = loaded;
    PlannerParameters p = shipped;
    if (max_seconds > 0) p.max_seconds = max_seconds;
    if (max_nodes > 0) p.max_nodes = max_nodes;
    p.threads = threads;
    if (v.scenario) v.scenario(sc);
    if (v.params && !portfolio) v.params(p);
    if (v.params && portfolio)
      for (PlannerVariant& m : p.portfolio)  // each member perturbed after its own changes
        m.apply = [own = m.apply, perturb = v.params](PlannerParameters& q) {
          if (own) own(q);
          perturb(q);
        };
    const PlanningResult r = ContactPlanner(sc, p).plan();
    std::printf("%-22s %-16s %7ld %9.2f", v.name.c_str(), toString(r.status), r.stats.nodes_generated,
                r.stats.seconds);
    if (!watch.empty()) {
      long on = 0;
      for (const auto& st : r.plan.stances)
        on += std::count_if(st.contacts.begin(), st.contacts.end(), [&](const PlanContact& c) {
          return c.spec.spot == watch_spot && c.spec.surface == watch_surface && c.spec.supporting;
        });
      std::printf("  %*ld", static_cast<int>(watch.size() + 11), on);
    }
    if (portfolio)
      std::printf("  %s (%ld)", r.winner >= 0 ? r.members[r.winner].name.c_str() : "none", r.portfolioNodes());
    std::printf("\n");
    std::fflush(stdout);
    if (r.solved()) {
      ++solved;
      nodes.push_back(static_cast<double>(r.stats.nodes_generated));
      all_nodes.push_back(static_cast<double>(r.portfolioNodes()));
    }
  }
  std::printf("solved %d of %d", solved, runs);
  if (!nodes.empty()) {
    const double m = median(nodes);
    std::printf("; nodes of the solved runs: median %.0f, largest %.2fx and smallest %.2fx the median", m,
                *std::max_element(nodes.begin(), nodes.end()) / m, *std::min_element(nodes.begin(), nodes.end()) / m);
    if (portfolio) {
      const double a = median(all_nodes);
      std::printf("; nodes generated by all the members: median %.0f, largest %.2fx and smallest %.2fx the median", a,
                  *std::max_element(all_nodes.begin(), all_nodes.end()) / a,
                  *std::min_element(all_nodes.begin(), all_nodes.end()) / a);
    }
  }
  std::printf("\n");
  return 0;
}
