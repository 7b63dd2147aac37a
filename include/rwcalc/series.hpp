#pragma once
/// @file series.hpp
/// The phase series every estimator works on: the cumulative angle (gyro, ″) or phase (clock),
/// sampled every τ0; pulse data keep exact integer counts, the pulse weight applied last.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace rwcalc {

enum class PhaseKind {
  Gyro,   ///< phase in arcseconds; deviations in °/h
  Clock,  ///< phase in the input's unit (s for time error); deviations in input units per second
  /// velocity in 1/3600 m/s (units::velocity_units_per_mps); deviations in m/s/h
  Accelerometer,
};

struct PhaseSeries {
  double tau0_s = 0.0025;  ///< sample period, s
  PhaseKind kind = PhaseKind::Gyro;
  /// Exact cumulative pulse counts C_0..C_M (C_0 = 0). Used when not empty. Differences are
  /// computed with wrap-around (modular) int64 arithmetic, so any offset gives identical results.
  std::vector<std::int64_t> counts;
  double arcsec_per_count = 0.92;  ///< pulse weight q, ″ per count
  /// Floating phase x_0..x_M in phase units, used when `counts` is empty.
  std::vector<double> values;
  /// Phase = values[i] + rate_offset·i·τ0: a large mean rate kept out of the 53 bits of `values`.
  double rate_offset = 0.0;

  [[nodiscard]] bool exact() const noexcept { return !counts.empty(); }
  /// Number of phase points (samples + 1 for increment or rate data).
  [[nodiscard]] std::size_t points() const noexcept { return exact() ? counts.size() : values.size(); }
  /// Exact count C_i (exact() only).
  [[nodiscard]] std::int64_t count(std::size_t i) const noexcept { return counts[i]; }
  /// Phase at index i in phase units.
  [[nodiscard]] double at(std::size_t i) const noexcept {
    return exact() ? static_cast<double>(count(i)) * arcsec_per_count
                   : values[i] + offset_phase(static_cast<double>(i));
  }
  /// The rate offset's part of the floating phase over `lag` samples, rate_offset·lag·τ0: the same
  /// for every pair of samples that far apart, so a loop over many pairs adds it as a constant.
  [[nodiscard]] double offset_phase(double lag) const noexcept { return rate_offset * lag * tau0_s; }
  /// Phase difference x_j − x_i in phase units, exact for counts.
  [[nodiscard]] double diff(std::size_t j, std::size_t i) const noexcept {
    if (!counts.empty()) {
      const auto d =
          static_cast<std::int64_t>(static_cast<std::uint64_t>(counts[j]) - static_cast<std::uint64_t>(counts[i]));
      return static_cast<double>(d) * arcsec_per_count;
    }
    return values[j] - values[i] + offset_phase(static_cast<double>(j) - static_cast<double>(i));
  }
  /// Record length T = (points − 1)·τ0, s.
  [[nodiscard]] double duration_s() const noexcept {
    return points() > 1 ? static_cast<double>(points() - 1) * tau0_s : 0.0;
  }
  /// Unit of the Allan deviation: "deg/h" for gyro data, "m/s/h" for accelerometer data, "1" (input
  /// units per second) for clock data.
  [[nodiscard]] std::string deviation_unit() const {
    return kind == PhaseKind::Gyro ? "deg/h" : kind == PhaseKind::Accelerometer ? "m/s/h" : "1";
  }
  /// Rate sample i (0-based, i < points−1) in deviation units: (x_{i+1} − x_i)/τ0.
  [[nodiscard]] double rate(std::size_t i) const noexcept { return diff(i + 1, i) / tau0_s; }
};

/// First index of run r (0 … runs − 1) of `runs` runs of `width` consecutive samples spread evenly
/// over `points` samples, the first at the start and the last ending at the end: a sample of a long
/// record, bounded in size, that covers the whole of it.
constexpr std::size_t spread_run_start(std::size_t r, std::size_t runs, std::size_t points, std::size_t width) {
  return runs <= 1 ? 0 : r * (points - width) / (runs - 1);
}

}  // namespace rwcalc
