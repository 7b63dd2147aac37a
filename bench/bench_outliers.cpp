// The outlier scan of `analyze` on the 2-h record: the robust scale and the screen, reading the
// rates block by block from the exact counts (no copy), in two passes or in one (scan_outliers,
// what analyze runs), against the scan of a rate vector made first (what analyze did before).
#include <benchmark/benchmark.h>

#include "rwcalc/outliers.hpp"
// after the library headers (pulse_writer.hpp's Metadata would shadow RateSource::Metadata)
#include "bench_inputs.hpp"

namespace {

using namespace rwcalc;

std::vector<double> rates_of(const PhaseSeries& p) {
  std::vector<double> r(p.points() - 1);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = p.rate(i);
  return r;
}

// Argument: threads of the screen.
void BM_OutlierScanCounts2h(benchmark::State& state) {
  const PhaseSeries& p = bench::gl2d_series();
  const auto threads = static_cast<unsigned>(state.range(0));
  for (auto _ : state) {
    const OutlierScale s = outlier_scale(p);
    auto out = find_outliers(p, kDefaultOutlierThreshold, s, threads);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(p.points() - 1));
}
BENCHMARK(BM_OutlierScanCounts2h)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// What analyze runs: scale and screen in one pass (scan_outliers). Argument: threads.
void BM_OutlierOnePassCounts2h(benchmark::State& state) {
  const PhaseSeries& p = bench::gl2d_series();
  const auto threads = static_cast<unsigned>(state.range(0));
  for (auto _ : state) {
    OutlierScale s;
    auto out = scan_outliers(p, kDefaultOutlierThreshold, s, threads);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(p.points() - 1));
}
BENCHMARK(BM_OutlierOnePassCounts2h)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_OutlierScaleCounts2h(benchmark::State& state) {
  const PhaseSeries& p = bench::gl2d_series();
  for (auto _ : state) benchmark::DoNotOptimize(outlier_scale(p));
}
BENCHMARK(BM_OutlierScaleCounts2h)->Unit(benchmark::kMillisecond);

void BM_OutlierScanRateCopy2h(benchmark::State& state) {
  const PhaseSeries& p = bench::gl2d_series();
  for (auto _ : state) {
    const auto r = rates_of(p);
    auto out = find_outliers(r, kDefaultOutlierThreshold, outlier_scale(r));
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_OutlierScanRateCopy2h)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
