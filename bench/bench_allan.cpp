// Allan-variance kernels on the 2-h 400 Hz GL-2D record (2.88 M samples, exact counts):
// one overlapping AVAR per cluster size, the sweep of the dense grid's sums, whole grids (octave,
// dense) on one and on two threads, MVAR, noise identification and EDF.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "allan/allan_kernels.hpp"
#include "bench_inputs.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/confidence.hpp"

namespace {

using namespace rwcalc;

// Threads of the parallel loops (parallel.hpp reads RWCALC_THREADS at every loop).
void use_threads(std::int64_t n) { setenv("RWCALC_THREADS", std::to_string(n).c_str(), 1); }

// One OAVAR sum at cluster size m = range(0): cost is ~N whatever m.
void BM_OavarOneTau(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  const std::int64_t m = state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(allan_variance(x, m, Estimator::Overlapping));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.points() - 2 * static_cast<std::size_t>(m)));
}
BENCHMARK(BM_OavarOneTau)->Arg(1)->Arg(64)->Arg(4096)->Arg(262144)->Unit(benchmark::kMillisecond);

// The overlapping sums of every τ of the dense grid in one blocked sweep on range(0) threads.
void BM_OavarSweep(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  use_threads(state.range(0));
  const std::vector<std::int64_t> ms =
      cluster_sizes(TauGrid::parse("dense"), Estimator::Overlapping, x.points(), x.tau0_s);
  for (auto _ : state)
    benchmark::DoNotOptimize(detail::second_diff_sumsq_sweep(x.counts.data(), x.points(), ms).data());
  state.counters["taus"] = static_cast<double>(ms.size());
}
BENCHMARK(BM_OavarSweep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MvarOneTau(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  const std::int64_t m = state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(allan_variance(x, m, Estimator::Modified));
}
BENCHMARK(BM_MvarOneTau)->Arg(1)->Arg(4096)->Unit(benchmark::kMillisecond);

// A whole grid: AVAR, noise id, EDF and bounds for every τ. range(0): threads; range(1): 0 octave, 1 dense.
void BM_ComputeAllanGrid(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  use_threads(state.range(0));
  AllanOptions o;
  o.grid = TauGrid::parse(state.range(1) ? "dense" : "octave");
  o.noise_id_domain = NoiseIdDomain::Frequency;
  std::size_t taus = 0;
  for (auto _ : state) {
    const auto r = compute_allan(x, o);
    taus = r.points.size();
    benchmark::DoNotOptimize(r.points.data());
  }
  state.counters["taus"] = static_cast<double>(taus);
}
BENCHMARK(BM_ComputeAllanGrid)->ArgsProduct({{1, 2}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();

// Noise identification alone at a small, a middle and a large cluster size.
void BM_IdentifyNoise(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  const std::int64_t m = state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(identify_noise(x, m, Estimator::Overlapping, NoiseIdDomain::Frequency));
}
BENCHMARK(BM_IdentifyNoise)->Arg(1)->Arg(256)->Arg(65536)->Unit(benchmark::kMillisecond);

// Greenhall–Riley EDF for one τ (exact BasicSum up to J = 100).
void BM_EdfGreenhall(benchmark::State& state) {
  const std::int64_t m = state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(edf_for(Estimator::Overlapping, -1, m, 2'880'001));
}
BENCHMARK(BM_EdfGreenhall)->Arg(1)->Arg(1024)->Arg(262144)->Unit(benchmark::kMicrosecond);

}  // namespace
