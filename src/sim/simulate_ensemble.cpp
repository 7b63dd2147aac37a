// Multi-threaded ensembles of simulated records (simulate.hpp): one Simulator per worker.
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "rwcalc/progress.hpp"
#include "rwcalc/random.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/thread.hpp"

namespace rwcalc {

std::uint64_t ensemble_seed(std::uint64_t seed, std::size_t run) noexcept {
  // A stream number far from the per-term streams of one record.
  return derive_seed(seed, 0x656e73656d626c65ULL + run);
}

void simulate_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                       const std::function<void(std::size_t, const PhaseSeries&)>& consume,
                       const EnsembleOptions& options) {
  if (runs == 0) return;
  validate(model, settings);  // throw on the calling thread, before any worker starts
  unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, runs));
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mu;
  auto work = [&] {
    try {
      Simulator sim(model, settings, options.path);
      PhaseSeries series;
      for (std::size_t r = next++; r < runs; r = next++) {
        sim.run(ensemble_seed(settings.seed, r), series);
        consume(r, series);
        if (options.progress) options.progress->advance();
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mu);
      if (!error) error = std::current_exception();
      next = runs;  // the other workers stop after their current run
    }
  };
  std::vector<Thread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace rwcalc
