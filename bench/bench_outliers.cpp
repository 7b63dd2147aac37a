// The outlier scan of `analyze` on the 2-h record: the robust scale and the screen, reading the
// rates stretch by stretch from the exact counts (no copy), against the scan of a rate vector
// made first. RWCALC_THREADS caps the threads.
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

// What analyze runs: the scale, then the screen.
void BM_OutlierScanCounts2h(benchmark::State& state) {
  const PhaseSeries& p = bench::gl2d_series();
  for (auto _ : state) {
    const OutlierScale s = outlier_scale(p);
    auto out = find_outliers(p, kDefaultOutlierThreshold, s);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(p.points() - 1));
}
BENCHMARK(BM_OutlierScanCounts2h)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_OutlierScaleCounts2h(benchmark::State& state) {
  const PhaseSeries& p = bench::gl2d_series();
  for (auto _ : state) benchmark::DoNotOptimize(outlier_scale(p));
}
BENCHMARK(BM_OutlierScaleCounts2h)->Unit(benchmark::kMillisecond)->UseRealTime();

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
