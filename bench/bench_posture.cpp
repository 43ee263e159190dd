// The posture generator on a fixed, seeded set of problems from the chair
// scene (random contact subsets, start guesses, floating contacts; some
// infeasible): success rate, time per call for successes and for failures,
// iterations, and how many successes the independent check accepts.
// Usage: bench_posture --help.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>

#include <CLI/CLI.hpp>

#include "cli_checks.h"

#include "planner/check/validity.h"
#include "planner/posture/heap_tuning.h"
#include "planner/posture/posture_generator.h"

using namespace acyclic;

namespace {

struct Problem {
  std::string label;
  PostureRequest request;
  std::vector<ContactSpec> stance;  // for the check: floating contact added as geometric only
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

std::vector<Problem> makeProblems(const Scenario& sc, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const std::vector<std::string> floating_spots = {"l_wrist", "r_wrist", "l_palm", "r_palm",
                                                   "l_forearm", "r_forearm", "l_knee", "r_knee"};
  std::vector<Problem> out;
  for (int i = 0; i < n; ++i) {
    Problem p;
    PostureRequest& r = p.request;
    // A random subset of the start stance: each foot or thigh kept (supporting,
    // or geometric only), at least one supporting.
    for (const auto& c : sc.start_stance) {
      const double dice = u(rng);
      if (dice < 0.15) continue;  // dropped
      ContactSpec cs = c;
      cs.supporting = dice > 0.3;
      r.contacts.push_back(cs);
    }
    bool any = false;
    for (const auto& c : r.contacts) any = any || c.supporting;
    if (!any) r.contacts = sc.start_stance;
    // Start guess: the seated posture, perturbed.
    r.initial_guess = sc.start;
    for (int j = 0; j < r.initial_guess.joints.size(); ++j) r.initial_guess.joints[j] += 0.1 * g(rng);
    r.initial_guess.base_position += 0.02 * Eigen::Vector3d(g(rng), g(rng), g(rng));
    r.cost = std::make_shared<ReferencePostureCost>(sc.start);
    p.stance = r.contacts;
    p.label = std::to_string(r.contacts.size()) + " fixed";
    // Two problems in three also search a floating contact in a random part of a surface.
    if (u(rng) < 0.67) {
      FloatingContact f;
      f.spot = sc.robot->spotIndex(floating_spots[rng() % floating_spots.size()]);
      f.surface = sc.allowed_surfaces[rng() % sc.allowed_surfaces.size()];
      const Surface& s = sc.scene->surfaces()[f.surface];
      // a random rectangle inside the surface polygon's bounding box, clipped to 1.2 m around the robot
      Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
      for (const auto& v : s.polygon.vertices()) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      const Eigen::Vector2d robot = (s.frame.inverse() * sc.start.base_position).head<2>();
      lo = lo.cwiseMax(robot - Eigen::Vector2d(1.2, 1.2));
      hi = hi.cwiseMin(robot + Eigen::Vector2d(1.2, 1.2));
      const double w = 0.1 + 0.3 * u(rng);
      const Eigen::Vector2d c(lo.x() + (hi.x() - lo.x()) * u(rng), lo.y() + (hi.y() - lo.y()) * u(rng));
      const Eigen::Vector2d a = (c - Eigen::Vector2d(w, w)).cwiseMax(lo), b = (c + Eigen::Vector2d(w, w)).cwiseMin(hi);
      if ((b - a).minCoeff() > 0.02) {
        f.volume.polygon = ConvexPolygon({{a.x(), a.y()}, {b.x(), a.y()}, {b.x(), b.y()}, {a.x(), b.y()}});
        r.floating = f;
        p.label += " + " + sc.robot->spots()[f.spot].name + "@" + s.name;
      }
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  int n = 100;
  unsigned seed = 1;
  PostureGeneratorOptions opt;
  CLI::App app{"The posture generator on a fixed, seeded set of problems from the chair scene (random contact\n"
               "subsets, start guesses, floating contacts; some infeasible): success rate, time per call for\n"
               "successes and for failures (median, 90th percentile), iterations, and how many successes the\n"
               "independent check accepts."};
  app.add_option("--problems", n, "number of problems")->check(acyclic::bench::positive())->capture_default_str();
  app.add_option("--seed", seed, "seed of the problem set")->capture_default_str();
  app.add_option("--max-seconds", opt.max_seconds, "CPU time limit per call, s")->capture_default_str();
  app.add_option("--max-iterations", opt.max_iterations, "iteration limit per call")->capture_default_str();
  app.add_option("--cutoff", opt.problem.collision_cutoff, "collision pairs farther than this at the start are left out, m")
      ->capture_default_str();
  app.add_option("--hessian", opt.hessian, "lbfgs, analytic or diagonal")->capture_default_str();
  app.add_option("--linear-solver", opt.linear_solver, "ldl or mumps")->capture_default_str();
  app.add_option("--lbfgs-rows", opt.lbfgs_in_kkt, "L-BFGS's low-rank part as rows of the KKT system (else Sherman-Morrison)")
      ->capture_default_str();
  app.add_option("--stop-at-restoration", opt.stop_at_restoration,
                 "give up when Ipopt enters its restoration phase (the planner's setting)")
      ->capture_default_str();
  app.add_option("--mu-oracle", opt.mu_oracle, "Ipopt's barrier-parameter oracle: quality-function, probing or loqo")
      ->capture_default_str();
  std::string engine = "convex";
  app.add_option("--distance-engine", engine, "pair distances: convex (GJK on the primitives' cores) or fcl")
      ->check(CLI::IsMember({"convex", "fcl"}))
      ->capture_default_str();
  app.add_option("--ipopt", opt.ipopt_options, "further Ipopt option name=value (repeatable)");
  CLI11_PARSE(app, argc, argv);
  opt.distance_engine = engine == "fcl" ? DistanceEngine::Fcl : DistanceEngine::Convex;
  const Scenario sc = Scenario::load(ACYCLIC_SOURCE_DIR "/models/scenarios/chair_table.yaml");
  std::unique_ptr<PostureGenerator> made;
  try {
    made = std::make_unique<PostureGenerator>(sc.robot, sc.scene, opt);
  } catch (const std::invalid_argument& e) {  // a bad option: said, not aborted on
    std::fprintf(stderr, "bench_posture: %s\n", e.what());
    return 2;
  }
  PostureGenerator& pg = *made;
  ValidityChecker checker(sc.robot, sc.scene);
  const auto problems = makeProblems(sc, n, seed);

  std::vector<double> t_ok, t_fail, it_ok, it_fail;
  int checked_ok = 0, by_status[5] = {0, 0, 0, 0, 0};
  for (const auto& p : problems) {
    const PostureResult r = pg.solve(p.request);
    ++by_status[static_cast<int>(r.status)];
    if (r.success()) {
      t_ok.push_back(r.seconds * 1e3);
      it_ok.push_back(r.iterations);
      std::vector<ContactSpec> stance = p.stance;
      if (p.request.floating) {
        ContactSpec c;
        c.spot = p.request.floating->spot;
        c.surface = p.request.floating->surface;
        c.supporting = false;
        c.placement = r.floating;
        stance.push_back(c);
      }
      const ValidityReport rep = checker.checkPosture(r.configuration, stance);
      if (rep.valid()) {
        ++checked_ok;
      } else {
        for (const auto& part : rep.parts)
          if (!part.ok()) std::printf("  check refuses a success (%s): %s\n", p.label.c_str(), part.violations[0].c_str());
      }
    } else {
      t_fail.push_back(r.seconds * 1e3);
      it_fail.push_back(r.iterations);
    }
  }
  std::printf("posture generator, %d seeded problems from the chair scene (seed %u)\n", n, seed);
  std::printf("  success %zu (%.0f%%); failures: infeasible %d, iteration limit %d, time limit %d, bad input %d\n",
              t_ok.size(), 100.0 * t_ok.size() / n, by_status[1], by_status[2], by_status[3], by_status[4]);
  std::printf("  successes: median %.1f ms, p90 %.1f ms, median %.0f iterations\n", percentile(t_ok, 0.5),
              percentile(t_ok, 0.9), percentile(it_ok, 0.5));
  std::printf("  failures:  median %.1f ms, p90 %.1f ms, median %.0f iterations\n", percentile(t_fail, 0.5),
              percentile(t_fail, 0.9), percentile(it_fail, 0.5));
  std::printf("  independent check (limits, contacts, collisions, quasi-static LP): %d of %zu successes valid\n",
              checked_ok, t_ok.size());
  return checked_ok == static_cast<int>(t_ok.size()) ? 0 : 1;
}
