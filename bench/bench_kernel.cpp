// Micro-benchmarks of the kernel's step loop (World::step), reported as
// particle-steps per second. Scenes: see bench_scene.hpp.
//
//   ./bench_kernel                                # all cases
//   ./bench_kernel --benchmark_filter=Hex/20      # one case
//   taskset -c 0 ./bench_kernel --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true      (one line)
//
// Every case builds its packing, pre-loads it (steps before timing, so that
// the contact network and tangential histories exist and the first
// neighbour-list rebuilds are behind it), then times World::step in chunks
// (wall-clock time, as the side-by-side comparison). Rates: particle_steps/s
// (kIsRate) = particles × timed steps / seconds.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <memory>

#include "bench_scene.hpp"

namespace {

using demcal_bench::Scene;

int64_t preload_steps(int n) { return std::clamp<int64_t>(20'000'000 / std::max(n, 1), 200, 2000); }
int64_t chunk_steps(int n) { return std::max<int64_t>(32, 4'000'000 / std::max(n, 1)); }

// The timed steps restart from a fresh pre-loaded packing (outside the
// timing) every kMaxSteps steps, so the top wall never goes beyond ~1 %
// strain and every case measures the same lightly compressed state.
constexpr int64_t kMaxSteps = 100'000;

void run_case(benchmark::State& state, const Scene& scene, int threads = 1) {
  std::unique_ptr<demcal::World> world;
  int64_t since_reset = 0, rebuilds = 0, steps = 0;
  auto reset = [&] {
    if (world) rebuilds += world->rebuilds();
    world = demcal_bench::make_compression_world(scene);
    world->set_threads(threads);
    const bool ok = world->step(preload_steps(world->size()));
    rebuilds -= world->rebuilds();
    since_reset = 0;
    return ok;
  };
  if (!reset()) {
    state.SkipWithError("diverged during pre-load");
    return;
  }
  const int n = world->size();
  const int64_t chunk = chunk_steps(n);
  for (auto _ : state) {
    if (since_reset + chunk > kMaxSteps) {
      state.PauseTiming();
      const bool ok = reset();
      state.ResumeTiming();
      if (!ok) {
        state.SkipWithError("diverged during pre-load");
        return;
      }
    }
    if (!world->step(chunk)) {
      state.SkipWithError("diverged");
      return;
    }
    steps += chunk;
    since_reset += chunk;
  }
  rebuilds += world->rebuilds();
  const auto m = world->measure();
  state.counters["particles"] = n;
  state.counters["threads"] = world->threads();
  state.counters["particle_steps/s"] = benchmark::Counter(
      static_cast<double>(n) * static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["steps/s"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["contacts"] = m.particle_contacts;
  state.counters["wall_contacts"] = m.wall_contacts;
  state.counters["p_kPa"] = m.mean_pressure * 1e-3;
  state.counters["rebuilds/1k_steps"] =
      steps > 0 ? 1000.0 * static_cast<double>(rebuilds) / static_cast<double>(steps) : 0.0;
}

// Arg = disks per side (side × side hexagonal packing).
void BM_StepHex(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  run_case(state, demcal_bench::hex_scene(side, side));
}
BENCHMARK(BM_StepHex)
    ->ArgName("side")
    ->Arg(10)   // 100
    ->Arg(20)   // 400
    ->Arg(32)   // 1 024
    ->Arg(50)   // 2 500
    ->Arg(71)   // 5 041
    ->Arg(100)  // 10 000
    ->Arg(141)  // 19 881
    ->Arg(224)  // 50 176
    ->Arg(316)  // 99 856
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

// The large hexagonal cases on 2 threads (KernelOptions::threads): compare
// with BM_StepHex of the same size. Real (wall-clock) time: the machine must
// have two idle cores for the figure to mean anything.
void BM_StepHexThreads(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  run_case(state, demcal_bench::hex_scene(side, side), static_cast<int>(state.range(1)));
}
BENCHMARK(BM_StepHexThreads)
    ->ArgNames({"side", "threads"})
    ->Args({100, 2})  // 10 000
    ->Args({224, 2})  // 50 176
    ->Args({316, 2})  // 99 856
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

// Random polydisperse ~400 disks, compacted frictionless to ~100 kPa, then
// compressed by the top wall with μ = 0.3 (bench_scene.hpp).
void BM_StepRandom(benchmark::State& state) {
  static const Scene scene = [] {
    Scene s = demcal_bench::random_scene(400);
    s.material.particle.friction = 0.3;
    return s;
  }();
  run_case(state, scene);
}
BENCHMARK(BM_StepRandom)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::AddCustomContext("demcal_simd", demcal::kernel_simd());
  benchmark::AddCustomContext("demcal_gather", demcal::kernel_gather());
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
