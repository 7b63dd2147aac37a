// Ensembles of simulated records (ensemble.hpp): the records run side by side, each Simulator
// reused for the next record once its record is consumed.
#include "rwcalc/ensemble.hpp"

#include <memory>
#include <mutex>
#include <vector>

#include "rwcalc/parallel.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/random.hpp"

namespace rwcalc {

std::uint64_t ensemble_seed(std::uint64_t seed, std::size_t run) noexcept {
  // A stream number far from the per-term streams of one record.
  return derive_seed(seed, 0x656e73656d626c65ULL + run);
}

void simulate_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                       const std::function<void(std::size_t, const PhaseSeries&)>& consume,
                       const EnsembleOptions& options) {
  if (runs == 0) return;
  validate(model, settings);  // throw on the calling thread, before any record starts
  // A Simulator (its FFT plan and flicker filter) and a record's storage are made once per
  // thread, not per record: a record borrows a free pair and gives it back when consumed. A
  // record depends only on its seed, so which pair it borrows changes nothing.
  struct Slot {
    Simulator sim;
    PhaseSeries series;
  };
  std::mutex mutex;
  std::vector<std::unique_ptr<Slot>> free;
  parallel_for(runs, [&](std::size_t r) {
    std::unique_ptr<Slot> slot;
    {
      const std::lock_guard lock(mutex);
      if (!free.empty()) {
        slot = std::move(free.back());
        free.pop_back();
      }
    }
    if (!slot) slot = std::make_unique<Slot>(Slot{Simulator(model, settings, options.path), {}});
    slot->sim.run(ensemble_seed(settings.seed, r), slot->series);
    consume(r, slot->series);
    if (options.progress) options.progress->advance();
    const std::lock_guard lock(mutex);
    free.push_back(std::move(slot));
  });
}

}  // namespace rwcalc
