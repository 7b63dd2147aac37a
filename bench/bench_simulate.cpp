// Simulation kernels: one 2-h 400 Hz GL-2D record (2.88 M samples), exact and ensemble paths,
// and the terms separately (what dominates a record).
#include <benchmark/benchmark.h>

#include <atomic>

#include "bench_inputs.hpp"
#include "rwcalc/ensemble.hpp"

namespace {

using namespace rwcalc;

NoiseModel gl2d_model_local() { return bench::gl2d_model(); }

SimulationSettings two_hours() { return bench::gl2d_settings(); }

void run_model(benchmark::State& state, const NoiseModel& m) {
  Simulator sim(m, two_hours());
  PhaseSeries out;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    sim.run(seed++, out);
    benchmark::DoNotOptimize(out.counts.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(two_hours().samples()));
}

void BM_SimulateGl2dExact(benchmark::State& state) { run_model(state, gl2d_model_local()); }
BENCHMARK(BM_SimulateGl2dExact)->Unit(benchmark::kMillisecond);

void BM_SimulateNoFlicker(benchmark::State& state) {
  auto m = gl2d_model_local();
  m.bias_instability_deg_per_h = 0;
  run_model(state, m);
}
BENCHMARK(BM_SimulateNoFlicker)->Unit(benchmark::kMillisecond);

void BM_SimulateQuantizeOnly(benchmark::State& state) {
  NoiseModel m;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  m.readout = ReadoutMode::White;
  run_model(state, m);
}
BENCHMARK(BM_SimulateQuantizeOnly)->Unit(benchmark::kMillisecond);

void BM_SimulateCountingReadout(benchmark::State& state) {
  NoiseModel m;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  run_model(state, m);
}
BENCHMARK(BM_SimulateCountingReadout)->Unit(benchmark::kMillisecond);

}  // namespace

namespace {

void BM_SimulateGl2dEnsemblePath(benchmark::State& state) {
  Simulator sim(gl2d_model_local(), two_hours(), SimulationPath::Ensemble);
  PhaseSeries out;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    sim.run(seed++, out);
    benchmark::DoNotOptimize(out.counts.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(two_hours().samples()));
}
BENCHMARK(BM_SimulateGl2dEnsemblePath)->Unit(benchmark::kMillisecond);

// 50 records of 2 h on all hardware threads (the diagnosis ensemble, without its statistics).
void BM_Ensemble50Gl2d(benchmark::State& state) {
  for (auto _ : state) {
    std::atomic<std::int64_t> sink{0};
    simulate_ensemble(gl2d_model_local(), two_hours(), 50,
                      [&](std::size_t, const PhaseSeries& p) { sink += p.counts.back(); });
    benchmark::DoNotOptimize(sink.load());
  }
}
BENCHMARK(BM_Ensemble50Gl2d)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
