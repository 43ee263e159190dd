// Kinematics of the HRP-2 model (Simbody): the per-evaluation costs the
// posture generator pays.
#include <benchmark/benchmark.h>

#include <random>

#include "planner/common/geometry.h"
#include "planner/model/kinematics.h"

using namespace acyclic;

namespace {

std::shared_ptr<const RobotModel> model() {
  static auto m = RobotModel::load(ACYCLIC_SOURCE_DIR "/models/hrp2/hrp2.yaml");
  return m;
}

// A fixed, seeded set of configurations, cycled through so no cache helps.
std::vector<Configuration> configurations() {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Configuration> qs;
  for (int i = 0; i < 64; ++i) {
    Configuration q = model()->posture("half_sitting");
    q.base_orientation = Eigen::Quaterniond(expSO3(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.3));
    for (const auto& j : model()->joints()) q.joints[j.index] = j.lower + (j.upper - j.lower) * u(rng);
    qs.push_back(q);
  }
  return qs;
}

void BM_SetConfiguration(benchmark::State& st) {
  Kinematics k(model());
  const auto qs = configurations();
  std::size_t i = 0;
  for (auto _ : st) k.setConfiguration(qs[i++ % qs.size()]);
}
BENCHMARK(BM_SetConfiguration)->Unit(benchmark::kMicrosecond);

// Link poses only, composed without Simbody (the limb planner's clearance checks).
void BM_SetPoses(benchmark::State& st) {
  Kinematics k(model());
  const auto qs = configurations();
  std::size_t i = 0;
  for (auto _ : st) k.setPoses(qs[i++ % qs.size()]);
}
BENCHMARK(BM_SetPoses)->Unit(benchmark::kMicrosecond);

void BM_AllSpotFrameJacobians(benchmark::State& st) {
  // Position + every contact spot's 6 x 36 frame Jacobian (12 spots).
  Kinematics k(model());
  const auto qs = configurations();
  std::size_t i = 0;
  for (auto _ : st) {
    k.setConfiguration(qs[i++ % qs.size()]);
    for (const auto& s : model()->spots()) benchmark::DoNotOptimize(k.frameJacobian(s.link, s.frame.translation()));
  }
}
BENCHMARK(BM_AllSpotFrameJacobians)->Unit(benchmark::kMicrosecond);

void BM_PointJacobian(benchmark::State& st) {
  Kinematics k(model());
  k.setConfiguration(configurations()[0]);
  const int link = model()->linkIndex("LARM_LINK5");
  for (auto _ : st) benchmark::DoNotOptimize(k.pointJacobian(link, Eigen::Vector3d(0, 0, -0.1)));
}
BENCHMARK(BM_PointJacobian)->Unit(benchmark::kMicrosecond);

void BM_CenterOfMassAndJacobian(benchmark::State& st) {
  Kinematics k(model());
  k.setConfiguration(configurations()[0]);
  for (auto _ : st) {
    benchmark::DoNotOptimize(k.centerOfMass());
    benchmark::DoNotOptimize(k.centerOfMassJacobian());
  }
}
BENCHMARK(BM_CenterOfMassAndJacobian)->Unit(benchmark::kMicrosecond);

void BM_GravityTorques(benchmark::State& st) {
  Kinematics k(model());
  k.setConfiguration(configurations()[0]);
  for (auto _ : st) benchmark::DoNotOptimize(k.gravityTorques());
}
BENCHMARK(BM_GravityTorques)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
