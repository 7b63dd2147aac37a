// Noise-model fit on the octave Allan variance of the 2-h 400 Hz GL-2D record: the whole fit
// (Gamma-deviance IRLS, model EDFs, the covariance of the AV points, term selection, sandwich
// and profile intervals) and the point covariance alone, on one and on two threads.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "bench_inputs.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/fit.hpp"

namespace {

using namespace rwcalc;

// Threads of the parallel loops (parallel.hpp reads RWCALC_THREADS at every loop).
void use_threads(std::int64_t n) { setenv("RWCALC_THREADS", std::to_string(n).c_str(), 1); }

const std::vector<FitPoint>& octave_points() {
  static const std::vector<FitPoint> pts = [] {
    return fit_points(compute_allan(bench::gl2d_series(), AllanOptions{}));
  }();
  return pts;
}

void BM_FitNoise(benchmark::State& state) {
  const auto& pts = octave_points();
  use_threads(state.range(0));
  const FitOptions o;
  for (auto _ : state) {
    const FitResult r = fit_noise(pts, o);
    benchmark::DoNotOptimize(r.c.data());
  }
  state.counters["points"] = static_cast<double>(pts.size());
}
BENCHMARK(BM_FitNoise)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The covariance of the AV points under the fitted model (every pair of τ): most of the fit's time.
void BM_AvCovariance(benchmark::State& state) {
  const auto& pts = octave_points();
  static const FitResult fit = fit_noise(pts, FitOptions{});
  use_threads(state.range(0));
  for (auto _ : state) {
    const Eigen::MatrixXd s = av_covariance(pts, fit.c);
    benchmark::DoNotOptimize(s.data());
  }
}
BENCHMARK(BM_AvCovariance)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
