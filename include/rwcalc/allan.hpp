#pragma once
/// @file allan.hpp
/// Allan-type variances of a PhaseSeries: fully overlapping AVAR (the workhorse), non-overlapping
/// AVAR and modified AVAR, on a chosen τ grid, with noise identification, equivalent degrees of
/// freedom and χ² confidence bounds as Stable32 computes them (NIST SP 1065; Greenhall & Riley 2003).
///
/// For exact pulse data the second differences C(k+2m) − 2C(k+m) + C(k) are formed in int64
/// (modular) arithmetic and their squares summed exactly; the pulse weight enters only at the end,
/// so a record gives bit-identical results whatever constant offset its counter carries.
///
/// Units: τ in seconds; σ in deviation units (°/h for gyro data, input units per second for
/// clock data; see PhaseSeries::deviation_unit()).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "rwcalc/series.hpp"

namespace rwcalc {

enum class Estimator { Overlapping, NonOverlapping, Modified };

/// τ grid: octave (m = 1, 2, 4, …; default), decade (Stable32's 1, 2, 4 per decade: m = 1, 2, 4,
/// 10, 20, 40, …), dense[:P] (P log-spaced distinct cluster sizes per decade; default P = 20),
/// all (every m), or an explicit list of τ in seconds (each a whole number of samples).
struct TauGrid {
  enum class Kind { Octave, Decade, Dense, All, Explicit } kind = Kind::Octave;
  int per_decade = 20;             ///< for Dense
  std::vector<double> taus_s;      ///< for Explicit, s
  std::int64_t max_m = 0;          ///< optional cap on m (0: the estimator's own limit)
  /// Also every octave cluster size (1, 2, 4, … up to the estimator's limit, whatever max_m):
  /// analyze reports a finer grid but fits the octave points, so its coefficients do not depend
  /// on the grid.
  bool with_octave = false;
  /// Parse "octave", "decade", "dense", "dense:P", "all", or "1,2,5" (seconds). Throws UsageError.
  static TauGrid parse(std::string_view spec);
};

/// Largest cluster size the estimator accepts for `points` phase points (at least one term):
/// overlapping and non-overlapping AVAR need N − 2m ≥ 1 (the paper's k < N/2), MVAR N − 3m + 1 ≥ 1.
/// Returns 0 when the record is too short for m = 1.
std::int64_t max_cluster_size(Estimator est, std::size_t points);

/// Number of terms of the estimator's sum at cluster size m for `points` phase points
/// (N − 2m overlapping, ⌊(N−1)/m⌋ − 1 non-overlapping, N − 3m + 1 modified; 0 if none).
std::int64_t term_count(Estimator est, std::int64_t m, std::size_t points);

/// The cluster sizes m of a grid for a record of `points` phase points sampled every tau0_s,
/// increasing and distinct. Throws UsageError for an explicit τ that is not a whole number of
/// samples or out of range.
std::vector<std::int64_t> cluster_sizes(const TauGrid& grid, Estimator est, std::size_t points,
                                        double tau0_s);

/// Which series the lag-1 autocorrelation noise identification looks at, as Stable32 does for
/// phase files and for frequency files. Rate and pulse-increment input is frequency data.
enum class NoiseIdDomain { Phase, Frequency };

class Crew;

struct AllanOptions {
  Estimator estimator = Estimator::Overlapping;
  TauGrid grid;
  double confidence = 0.683;  ///< two-sided confidence of the bounds (Stable32's default)
  bool noise_id = true;       ///< identify α per τ (else use `alpha` for all)
  int alpha = 0;              ///< noise exponent used when noise_id is false (−2 … +2)
  NoiseIdDomain noise_id_domain = NoiseIdDomain::Phase;
  unsigned threads = 0;       ///< 0: all hardware threads
  /// Threads lent by the caller (crew.hpp): the passes over the data that can be shared out are
  /// then cut into stretches that this thread and the crew's lenders take as they are free, and
  /// `threads` sets only the rest. The same results.
  Crew* crew = nullptr;
};

struct AllanPoint {
  std::int64_t m = 0;        ///< averaging factor (cluster size)
  double tau_s = 0;          ///< τ = m·τ0, s
  std::int64_t n = 0;        ///< number of terms in the sum
  int alpha = 0;             ///< identified noise exponent of S_y(f) ∝ f^α (+2 … −2)
  double edf = 0;            ///< equivalent degrees of freedom (Greenhall–Riley)
  double var = 0;            ///< σ²(τ), deviation units squared
  double dev = 0;            ///< σ(τ)
  double dev_low = 0;        ///< lower confidence bound of σ
  double dev_high = 0;       ///< upper confidence bound of σ
};

struct AllanResult {
  Estimator estimator = Estimator::Overlapping;
  std::string unit;          ///< unit of the deviations: "deg/h" or "1"
  double tau0_s = 0;
  std::size_t points_in = 0; ///< phase points of the record
  double confidence = 0.683;
  /// 0, or the smallest m whose variance came from the FFT path of the `all` grid (floating-point,
  /// relative departure from the exact sum ~1e-12 on gyro records; see docs/performance.md).
  std::int64_t fft_from_m = 0;
  std::vector<AllanPoint> points;
};

/// Compute the chosen variance on the grid, with α, EDF and bounds. Work is spread over
/// `options.threads` threads across τ; the result does not depend on the thread count.
/// Throws AnalysisError when the record is too short for even one τ, UsageError for a bad grid or
/// confidence.
AllanResult compute_allan(const PhaseSeries& x, const AllanOptions& options = {});

/// The raw variance at one cluster size (no noise id/EDF); returns σ² in deviation units squared
/// and sets `terms` (0 and σ² = 0 when m leaves no term).
double allan_variance(const PhaseSeries& x, std::int64_t m, Estimator est, std::int64_t* terms = nullptr);

/// JSON form of a result: {"unit", "estimator", "confidence", "tau0_s", "points": [{"af",
/// "tau_s", "n", "alpha", "edf", "dev", "dev_low", "dev_high"}]}.
nlohmann::json to_json(const AllanResult& r);

/// What the report header says about the record.
struct AllanReportInfo {
  std::string source;        ///< file name as given
  std::size_t samples = 0;   ///< samples read
  double rate_hz = 0;        ///< sample rate, Hz
  std::string rate_source;   ///< where the rate came from ("option", "metadata", …); may be empty
};

/// Human-readable table: a header block (source, estimator, confidence, unit convention, samples,
/// rate) and columns AF, τ (s), terms, α, EDF, σ_min, σ, σ_max with the deviation unit.
std::string format_allan_table(const AllanResult& r, const AllanReportInfo& info);
/// CSV with a header row naming each column and its unit.
std::string format_allan_csv(const AllanResult& r);
/// Unit label of the deviations for people: "°/h" for gyro data, "input units/s" otherwise.
std::string unit_label(const AllanResult& r);

/// "oadev", "adev" or "mdev".
std::string_view to_string(Estimator e);
/// Human name: "overlapping Allan", "non-overlapping Allan", "modified Allan".
std::string_view long_name(Estimator e);
Estimator parse_estimator(std::string_view s);  ///< "oadev"|"overlapping", "adev"|"nonoverlapping", "mdev"|"modified"

}  // namespace rwcalc
