// Signed distances of every robot-environment and self-collision pair of the
// chair scenario, with and without gradients (Simbody Jacobians), by either
// engine: FCL's GJK (the independent check's) and convex::separation (the
// posture generator's).
#include <benchmark/benchmark.h>

#include <random>

#include "planner/collision/collision_model.h"
#include "planner/common/geometry.h"
#include "planner/scene/scenario.h"

using namespace acyclic;

namespace {

const Scenario& chair() {
  static Scenario sc = Scenario::load(ACYCLIC_SOURCE_DIR "/models/scenarios/chair_table.yaml");
  return sc;
}

// Seeded perturbations of the sitting start, lifted 2 cm off the seat.
std::vector<Configuration> configurations() {
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0, 0.05);
  std::vector<Configuration> qs;
  for (int i = 0; i < 64; ++i) {
    Configuration q = chair().start;
    q.base_position.z() += 0.02;
    for (int j = 0; j < q.joints.size(); ++j) q.joints[j] += n(rng);
    qs.push_back(q);
  }
  return qs;
}

void run(benchmark::State& st, const DistanceOptions& opt, DistanceEngine engine = DistanceEngine::Fcl) {
  CollisionModel cm(chair().robot, chair().scene, engine);
  Kinematics k(chair().robot);
  const auto qs = configurations();
  std::size_t i = 0, pairs = 0;
  for (auto _ : st) {
    k.setConfiguration(qs[i++ % qs.size()]);
    auto d = cm.distances(k, opt);
    pairs += d.size();
    benchmark::DoNotOptimize(d);
  }
  st.counters["pairs"] = benchmark::Counter(double(pairs) / st.iterations());
}

void BM_AllPairs(benchmark::State& st) { run(st, {}); }
BENCHMARK(BM_AllPairs)->Unit(benchmark::kMicrosecond);

void BM_AllPairsWithGradients(benchmark::State& st) {
  DistanceOptions opt;
  opt.gradients = true;
  run(st, opt);
}
BENCHMARK(BM_AllPairsWithGradients)->Unit(benchmark::kMicrosecond);

void BM_PairsWithin10cmWithGradients(benchmark::State& st) {
  // What a posture generator evaluates: pairs that could become active.
  DistanceOptions opt;
  opt.gradients = true;
  opt.cutoff = 0.10;
  run(st, opt);
}
BENCHMARK(BM_PairsWithin10cmWithGradients)->Unit(benchmark::kMicrosecond);

void BM_AllPairsConvex(benchmark::State& st) { run(st, {}, DistanceEngine::Convex); }
BENCHMARK(BM_AllPairsConvex)->Unit(benchmark::kMicrosecond);

void BM_AllPairsWithGradientsConvex(benchmark::State& st) {
  DistanceOptions opt;
  opt.gradients = true;
  run(st, opt, DistanceEngine::Convex);
}
BENCHMARK(BM_AllPairsWithGradientsConvex)->Unit(benchmark::kMicrosecond);

void BM_PairsWithin10cmWithGradientsConvex(benchmark::State& st) {
  DistanceOptions opt;
  opt.gradients = true;
  opt.cutoff = 0.10;
  run(st, opt, DistanceEngine::Convex);
}
BENCHMARK(BM_PairsWithin10cmWithGradientsConvex)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
