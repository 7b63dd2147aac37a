#pragma once
// What the report and the figures show of an analysis, a batch's overall verdict, a diagnosis and
// an IMU result, as typed values. shown_results.cpp reads them from the JSON (docs/result.schema.json)
// and is the one place the report layer names its keys. The JSON may be saved or hand-made: a value
// absent, null or non-finite is "not available" (an empty optional or string), never 0.
#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rwcalc::shown {

/// A class as the report shows it: a number, "outside" the table (null or absent in the JSON), or
/// not available (anything else there).
struct ClassValue {
  enum class Kind { NotAvailable, Outside, Number };
  Kind kind = Kind::Outside;
  int number = 0;
};

/// A fitted coefficient or a cross-check's estimate (value ± sigma, its 95 % interval).
struct CoefficientValues {
  std::optional<double> value, sigma, low95, high95;
  std::optional<bool> resolved;       ///< empty when the JSON does not say
  std::optional<bool> in_model;       ///< false: the fit left the term out
  std::optional<double> model_value;  ///< what the model curve uses
  std::optional<double> estimate;     ///< results saved without model_value
  std::string unit;
};

struct Coefficient : CoefficientValues {
  std::optional<CoefficientValues> si;  ///< an IMU axis' coefficient in SI units
};

/// The five terms of the model, in its order.
enum class Term : std::size_t { Q, N, B, K, R };

struct Fit {
  bool present = false;              ///< the analysis has a fit object
  std::array<Coefficient, 5> terms;  ///< by Term
  std::optional<double> chi2_per_dof, p_value, tau_min_s, tau_max_s, interval_scale;
  std::optional<std::string> range_reason;  ///< set when the fit names its range
  bool intervals_scaled = false;
  [[nodiscard]] const Coefficient& operator[](Term t) const { return terms[static_cast<std::size_t>(t)]; }
};

/// The direct method's N with its angle-variance curve (points with both values only).
struct DirectN : Coefficient {
  std::vector<std::pair<double, double>> curve;  ///< (t in s, variance)
  std::optional<double> slope, intercept;
};

/// One class limit of a parameter as the verdict applied it.
struct ClassLimit {
  int cls = 0;
  double limit = 0;
};

struct Verdict {
  bool present = false;  ///< the JSON has a verdict object
  ClassValue cls, class_B, class_N;
  bool withheld = false;
  bool tolerance_changed = false;
  std::string statement, statement_B, statement_N;  ///< a run's statements
  std::string by_B_statement, by_N_statement;       ///< a batch's overall "B"/"N" statements
  std::string reason, command, table, b_estimate;
  std::optional<double> p_class, tolerance_pct;
  std::optional<std::vector<double>> p_is;     ///< probabilities of each class and of "outside"
  std::optional<std::vector<int>> classes;     ///< the class numbers the probabilities are of
  std::vector<ClassLimit> limits_B, limits_N;  ///< empty when the verdict does not give them
};

struct AllanPoint {
  std::optional<double> tau_s, dev, dev_low, dev_high;
};

struct Allan {
  std::string unit;  ///< ASCII name; empty: °/h
  std::optional<double> confidence, unit_per_si;
  std::vector<AllanPoint> points;
};

struct OutlierPosition {
  std::optional<double> line, time_s, value;
};

struct Outliers {
  bool present = false;  ///< the results have an outlier summary
  std::string action;
  std::optional<double> count, removed, replaced, threshold_robust_z;
  std::vector<OutlierPosition> positions;
};

struct Gap {
  std::optional<double> line, missing_s;
};

struct Segments {
  std::optional<double> count;
  std::vector<Gap> gaps;
  std::vector<std::optional<double>> durations_s;
};

struct Warning {
  std::string code, message, command;
};

/// The identification of a recording in its metadata, in the order the data table lists it.
enum class Id : std::size_t { Serial, Operator, TestDate, Conditions };

/// One analysed run (`analyze --json`, a batch's run, an IMU channel).
struct Analysis {
  std::string source, column, sensor;
  std::string rate_unit;  ///< units.rate; empty: °/h
  std::optional<double> temperature_c, samples, rate_hz, duration_s, mean_rate, earth_rate, bias;
  std::array<std::string, 4> identification;  ///< by Id; empty when not given
  std::string sha256;
  std::optional<double> file_bytes;
  Segments segments;
  Outliers outliers;
  std::vector<Warning> warnings;
  Fit fit;
  DirectN n_direct;
  Coefficient b_100s;
  Verdict verdict;
  Allan allan;
  /// The results' conventions that the schema does not define (the report typesets those), shown
  /// as given: (key, value).
  std::vector<std::pair<std::string, nlohmann::json>> other_conventions;
  [[nodiscard]] const std::string& operator[](Id id) const { return identification[static_cast<std::size_t>(id)]; }
};

struct FindingParameter {
  std::string name, unit;
  std::optional<double> value, standard_uncertainty;
};

struct Finding {
  std::string effect;
  std::vector<FindingParameter> parameters;
};

struct Gain {
  std::optional<double> misfit_base, misfit_extended, coverage_base, coverage_extended;
  std::optional<double> likelihood_in_sample, likelihood_holdout;
};

struct BandPoint {
  std::optional<double> tau_s, dev, band_low, band_high, median;
};

struct Diagnosis {
  Outliers outliers;
  std::vector<Finding> findings;
  std::optional<Gain> gain;
  std::optional<std::vector<BandPoint>> band, band_extended;  ///< set when the JSON has the band
  std::optional<double> band_level, band_level_extended;
  std::optional<std::string> band_unit;  ///< the band's unit when not °/h
};

/// The worst axis of a sensor kind in the noise file.
struct NoiseWorst {
  std::optional<double> noise_density, random_walk;
  std::string noise_density_axis, random_walk_axis;
};

struct Imu {
  std::string source;
  std::optional<double> rate_hz, duration_s;
  std::optional<std::string> samples;  ///< the count as the JSON writes it
  std::vector<Analysis> channels;
  std::optional<NoiseWorst> gyro_worst, accelerometer_worst;
};

/// The readers: every key the report layer needs is named here.
[[nodiscard]] Analysis read_analysis(const nlohmann::json& j);
[[nodiscard]] std::vector<Analysis> read_analyses(const std::vector<nlohmann::json>& runs);
/// A batch's overall verdict; nothing when `j` is no object.
[[nodiscard]] std::optional<Verdict> read_overall(const nlohmann::json& j);
/// One diagnosis per item; nothing where the item is no object.
[[nodiscard]] std::vector<std::optional<Diagnosis>> read_diagnoses(const std::vector<nlohmann::json>& diagnoses);
/// The runs of a JSON array; empty for anything else.
[[nodiscard]] std::vector<Analysis> read_runs(const nlohmann::json& runs);
/// A batch's runs: the object's "runs", or the array itself.
[[nodiscard]] const nlohmann::json& batch_runs(const nlohmann::json& batch);
[[nodiscard]] Verdict read_verdict(const nlohmann::json& j);
[[nodiscard]] Diagnosis read_diagnosis(const nlohmann::json& j);
[[nodiscard]] Imu read_imu(const nlohmann::json& j);
/// A temperature: a finite number, else not available.
[[nodiscard]] std::optional<double> read_temperature(const nlohmann::json& j);

/// "+25 °C", "−50 °C", "0 °C"; empty when not available.
[[nodiscard]] std::string temperature_label(std::optional<double> t);

/// Class limits of "B" or "N" as the verdict applied them (tolerance included), else the GOST
/// RV 52339 table.
[[nodiscard]] std::vector<ClassLimit> class_limits(const Verdict& v, char parameter);

/// Indices of the runs by temperature; runs without one last, in input order.
[[nodiscard]] std::vector<std::size_t> by_temperature(const std::vector<Analysis>& runs);

}  // namespace rwcalc::shown
