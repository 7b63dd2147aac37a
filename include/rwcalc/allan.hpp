#pragma once
#ifndef RWCALC_USES_ALLAN
#error "rwcalc/allan.hpp belongs to the allan layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file allan.hpp
/// Allan-type variances of a PhaseSeries: fully overlapping AVAR (the workhorse), non-overlapping
/// AVAR, modified AVAR and the Hadamard variance (overlapping and not), on a chosen τ grid, with noise identification,
/// equivalent degrees of freedom and χ² confidence bounds as Stable32 computes them (NIST SP 1065; Greenhall & Riley
/// 2003).
///
/// For exact pulse data the second differences are formed in modular int64 arithmetic and their
/// squares summed exactly, the pulse weight applied at the end: any counter offset gives the same
/// bits. Units: τ in seconds; σ in deviation units (PhaseSeries::deviation_unit()).
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "rwcalc/series.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

/// The Hadamard variance takes third differences of the phase: a linear rate drift leaves it, and
/// it converges for rate noise down to α = −4 (SP 1065 §5.2.8).
enum class Estimator { Overlapping, NonOverlapping, Modified, OverlappingHadamard, NonOverlappingHadamard };

/// τ grid: octave (m = 1, 2, 4, …; default), decade (Stable32's 1, 2, 4 per decade), dense[:P] (P
/// log-spaced cluster sizes per decade; default 20), all (every m), or a list of τ in seconds.
struct TauGrid {
  enum class Kind { Octave, Decade, Dense, All, Explicit } kind = Kind::Octave;
  int per_decade = 20;         ///< for Dense
  std::vector<double> taus_s;  ///< for Explicit, s
  std::int64_t max_m = 0;      ///< optional cap on m (0: the estimator's own limit)
  /// Also every octave cluster size (up to the estimator's limit, whatever max_m): analyze fits
  /// the octave points of a finer grid, so its coefficients do not depend on the grid.
  bool with_octave = false;
  /// Parse "octave", "decade", "dense", "dense:P", "all", or "1,2,5" (seconds). Throws UsageError.
  static TauGrid parse(std::string_view spec);
};

/// True for the two Hadamard estimators.
constexpr bool is_hadamard(Estimator e) {
  return e == Estimator::OverlappingHadamard || e == Estimator::NonOverlappingHadamard;
}

/// Largest cluster size the estimator accepts for `points` phase points (at least one term: AVAR
/// N − 2m ≥ 1, MVAR N − 3m + 1 ≥ 1, HVAR N − 3m ≥ 1); 0 when the record is too short for m = 1.
std::int64_t max_cluster_size(Estimator est, std::size_t points);

/// Number of terms of the estimator's sum at cluster size m for `points` phase points
/// (N − 2m overlapping, ⌊(N−1)/m⌋ − 1 non-overlapping, N − 3m + 1 modified; Hadamard N − 3m
/// overlapping, ⌊(N−1)/m⌋ − 2 non-overlapping; 0 if none).
std::int64_t term_count(Estimator est, std::int64_t m, std::size_t points);

/// The cluster sizes m of a grid for `points` phase points every tau0_s, increasing and distinct.
/// Throws UsageError for an explicit τ that is not a whole number of samples or out of range.
std::vector<std::int64_t> cluster_sizes(const TauGrid& grid, Estimator est, std::size_t points, double tau0_s);

/// The series the noise identification looks at, as Stable32's phase and frequency files (rate and
/// pulse-increment input is frequency data).
enum class NoiseIdDomain { Phase, Frequency };

struct AllanOptions {
  Estimator estimator = Estimator::Overlapping;
  TauGrid grid;
  double confidence = 0.683;  ///< two-sided confidence of the bounds (Stable32's default)
  bool noise_id = true;       ///< identify α per τ (else use `alpha` for all)
  int alpha = 0;              ///< noise exponent used when noise_id is false (−2 … +2)
  NoiseIdDomain noise_id_domain = NoiseIdDomain::Phase;
  /// Where the progress line of the per-τ noise identification and bounds goes (progress.hpp; long
  /// on the `all` grid); nullptr: none.
  std::FILE* progress = nullptr;

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

struct AllanPoint {
  std::int64_t m = 0;   ///< averaging factor (cluster size)
  double tau_s = 0;     ///< τ = m·τ0, s
  std::int64_t n = 0;   ///< number of terms in the sum
  int alpha = 0;        ///< identified noise exponent of S_y(f) ∝ f^α (+2 … −2)
  double edf = 0;       ///< equivalent degrees of freedom (Greenhall–Riley)
  double var = 0;       ///< σ²(τ), deviation units squared
  double dev = 0;       ///< σ(τ)
  double dev_low = 0;   ///< lower confidence bound of σ
  double dev_high = 0;  ///< upper confidence bound of σ
};

struct AllanResult {
  Estimator estimator = Estimator::Overlapping;
  std::string unit;  ///< unit of the deviations: "deg/h" or "1"
  double tau0_s = 0;
  std::size_t points_in = 0;  ///< phase points of the record
  double confidence = 0.683;
  /// 0, or the smallest m whose variance came from the FFT path of the `all` grid (floating-point).
  std::int64_t fft_from_m = 0;
  std::vector<AllanPoint> points;
};

/// The chosen variance on the grid, with α, EDF and bounds; the result does not depend on the
/// thread count. Throws AnalysisError for a record too short for one τ, UsageError for bad options.
AllanResult compute_allan(const PhaseSeries& x, const AllanOptions& options = {});

/// σ² at one cluster size (no noise id/EDF), setting `terms` (0 and σ² = 0 when m leaves none).
double allan_variance(const PhaseSeries& x, std::int64_t m, Estimator est, std::int64_t* terms = nullptr);

/// JSON form: {"unit", "estimator", "confidence", "tau0_s", "points": [{"af", "tau_s", "n", …}]}.
nlohmann::json to_json(const AllanResult& r);

std::string_view to_string(Estimator e);  ///< "oadev", "adev", "mdev", "ohdev" or "hdev" (Stable32's names)
/// The estimator's deviation and variance by name in the current language (i18n.hpp):
/// "overlapping Allan deviation" («перекрывающаяся девиация Аллана»), "Hadamard variance", …
[[nodiscard]] std::string deviation_name(Estimator e);
[[nodiscard]] std::string variance_name(Estimator e);
/// "oadev"|"overlapping", "adev"|"nonoverlapping", "mdev"|"modified", "ohdev", "hdev".
Estimator parse_estimator(std::string_view s);

}  // namespace rwcalc
