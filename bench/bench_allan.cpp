// Allan-variance kernels on the 2-h 400 Hz GL-2D record (2.88 M samples, exact counts):
// one overlapping AVAR per cluster size, whole grids (octave, dense) on one and on all threads,
// MVAR, noise identification and EDF, and the int32 view of the counts they read.
#include <benchmark/benchmark.h>

#include "allan/allan_kernels.hpp"
#include "bench_inputs.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/confidence.hpp"

namespace {

using namespace rwcalc;

// One OAVAR sum at cluster size m = range(0): cost is ~N whatever m.
void BM_OavarOneTau(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  const std::int64_t m = state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(allan_variance(x, m, Estimator::Overlapping));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.points() - 2 * static_cast<std::size_t>(m)));
}
BENCHMARK(BM_OavarOneTau)->Arg(1)->Arg(64)->Arg(4096)->Arg(262144)->Unit(benchmark::kMillisecond);

// The int32 view of the counts (offsets C_k − C_0 and their range; AVX2 where available) on
// range(0) threads. Each iteration allocates the view afresh, as analyze does: the heap reuses the
// previous iteration's pages, so this is the pass itself without the cost of fresh pages.
void BM_PrepareCounts(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  const auto threads = static_cast<unsigned>(state.range(0));
  for (auto _ : state) {
    const auto p = detail::prepare_counts(x.counts, false, threads);
    benchmark::DoNotOptimize(p.rel32.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.points()));
}
BENCHMARK(BM_PrepareCounts)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MvarOneTau(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  const std::int64_t m = state.range(0);
  for (auto _ : state) benchmark::DoNotOptimize(allan_variance(x, m, Estimator::Modified));
}
BENCHMARK(BM_MvarOneTau)->Arg(1)->Arg(4096)->Unit(benchmark::kMillisecond);

// A whole grid: AVAR, noise id, EDF and bounds for every τ. range(0): threads; range(1): 0 octave, 1 dense.
void BM_ComputeAllanGrid(benchmark::State& state) {
  const auto& x = bench::gl2d_series();
  AllanOptions o;
  o.threads = static_cast<unsigned>(state.range(0));
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
