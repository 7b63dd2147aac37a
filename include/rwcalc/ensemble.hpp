#pragma once
#ifndef RWCALC_USES_SIM
#error "rwcalc/ensemble.hpp belongs to the sim layer, which this layer may not use (docs/architecture.md)"
#endif
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
  Progress* progress = nullptr;  ///< advanced once per finished realisation (may be null)
};

/// Seed of realisation `run` of an ensemble whose base seed is `seed` (independent streams).
[[nodiscard]] std::uint64_t ensemble_seed(std::uint64_t seed, std::size_t run) noexcept;

/// Realisation r uses ensemble_seed(settings.seed, r); `consume(r, series)` runs concurrently for
/// different r. The first exception stops the remaining runs and is rethrown.
void simulate_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                       const std::function<void(std::size_t run, const PhaseSeries& series)>& consume,
                       const EnsembleOptions& options = {});

}  // namespace rwcalc
