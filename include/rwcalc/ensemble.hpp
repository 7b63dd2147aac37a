#pragma once
/// @file ensemble.hpp
/// Many realisations of one simulated record, run side by side (parallel.hpp).
#include <cstddef>
#include <cstdint>
#include <functional>

#include "rwcalc/simulate.hpp"

namespace rwcalc {

class Progress;

/// How simulate_ensemble runs.
struct EnsembleOptions {
  SimulationPath path = SimulationPath::Ensemble;
  Progress* progress = nullptr;   ///< advanced once per finished realisation (may be null)
};

/// Seed of realisation `run` of an ensemble whose base seed is `seed` (independent streams).
[[nodiscard]] std::uint64_t ensemble_seed(std::uint64_t seed, std::size_t run) noexcept;

/// Simulate `runs` realisations of one model, settings.seed being the base seed: realisation r
/// uses ensemble_seed(settings.seed, r), so the result does not depend on the thread count.
/// `consume(r, series)` is called concurrently for different r; the series is reused once it
/// returns. The first exception (from the simulator or `consume`) stops the remaining runs and
/// is rethrown.
void simulate_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                       const std::function<void(std::size_t run, const PhaseSeries& series)>& consume,
                       const EnsembleOptions& options = {});

}  // namespace rwcalc
