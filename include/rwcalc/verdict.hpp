#pragma once
/// @file verdict.hpp
/// Navigation accuracy class of a gyro from its bias instability B and angle random walk N, with
/// the probability, from each estimate's uncertainty, that the true value meets each class.
///
/// Built-in table: GOST RV 52339-2005 as reported by Bolotnov & Fomin (2021):
///   class 1: position error 0.90 km/h, B ≤ 0.005 °/h, N ≤ 0.0010 °/√h
///   class 2: position error 1.85 km/h, B ≤ 0.008 °/h, N ≤ 0.0015 °/√h
///   class 3: position error 3.70 km/h, B ≤ 0.015 °/h, N ≤ 0.0030 °/√h
/// A run's class by a parameter is the best class whose limit the estimate meets; the overall class
/// is the worse of the two; beyond the last class there is no class (null in JSON).
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace rwcalc {

/// One row of a class table.
struct ClassLimit {
  int cls = 0;                     ///< class number (1 is the best)
  double position_error_km_h = 0;  ///< navigation position error the class stands for, km/h
  double B_deg_per_h = 0;          ///< limit on the bias instability, °/h
  double N_deg_per_sqrt_h = 0;     ///< limit on the angle random walk, °/√h
};

struct ClassTable {
  std::string name;                ///< e.g. "GOST RV 52339-2005"
  std::vector<ClassLimit> classes; ///< ascending class numbers, limits non-decreasing

  /// The built-in GOST RV 52339 table.
  static ClassTable gost();
  /// From JSON text: {"name": "...", "classes": [{"class": 1, "position_error_km_h": 0.9,
  /// "B_deg_per_h": 0.005, "N_deg_per_sqrt_h": 0.001}, …]}: integer class numbers ascending,
  /// positive finite limits non-decreasing. Throws InputError naming `source`, the line and the
  /// key path of the first value that is wrong.
  static ClassTable parse(std::string_view text, const std::string& source);
  /// Read a JSON file (see from_json). Throws InputError.
  static ClassTable load(const std::string& path);
};

/// Which estimate of B the verdict uses.
enum class BEstimate {
  Fit,       ///< the AV fit (default)
  SigmaMin,  ///< σ_min/0.6643 (classic readout)
  Avg100,    ///< spread of 100-s mean rates
};
std::string_view to_string(BEstimate b);
BEstimate parse_b_estimate(std::string_view s);  ///< "fit", "sigma-min", "avg100"; UsageError otherwise

struct VerdictOptions {
  ClassTable table = ClassTable::gost();
  BEstimate b_estimate = BEstimate::Fit;
  /// The seed paper's heading-gyro rule: a B up to this many percent above a class limit is
  /// accepted for that class (0: strict). Applies to B only.
  double tolerance_pct = 0;
  /// A stated class whose probability is below this is reported with its runner-up.
  double decisive = 0.9;
};

/// What the verdict needs of an estimate: its reported value and its confidence distribution.
struct EstimateInput {
  double value = 0;     ///< reported value (the upper bound when not resolved)
  double low = 0;       ///< lower 95 % bound
  double high = 0;      ///< upper 95 % bound
  bool resolved = true;
  /// P(true value ≤ x). Must be non-decreasing; 0 at x ≤ 0.
  std::function<double(double)> cdf;
};
/// Log-normal sampling distribution with the given standard error (used for σ_min and 100-s B).
EstimateInput lognormal_estimate(double value, double sigma);

/// The verdict for one parameter.
struct ParameterVerdict {
  std::string parameter;        ///< "B" or "N"
  std::string unit;             ///< "deg/h" or "deg/sqrt(h)"
  double value = 0;
  bool resolved = true;
  std::optional<int> cls;       ///< class by the reported value (empty: beyond the last class)
  std::optional<int> cls_strict;///< class without the tolerance (equal to cls when none)
  std::vector<double> limit;    ///< effective limit per class (tolerance applied)
  std::vector<double> margin_pct;  ///< (limit − value)/limit·100 per class (positive: met)
  std::vector<double> p_meets;  ///< P(true ≤ limit) per class
  std::vector<double> p_is;     ///< P(true class = k) per class, then P(beyond the last) at the end
  double p_class = 0;           ///< probability of the stated class (or of "beyond")
};

struct Verdict {
  ParameterVerdict B, N;
  std::optional<int> cls;        ///< overall: the worse of the two
  std::optional<int> cls_strict; ///< overall without tolerance
  std::vector<double> p_meets;   ///< P(overall true class ≤ k) per class (joint, Gaussian copula)
  std::vector<double> p_is;      ///< P(overall true class = k), then P(beyond)
  double p_class = 0;            ///< probability of the stated overall class
  double rho_BN = 0;             ///< correlation of the log-estimates used in the copula
  bool decisive = true;          ///< p_class ≥ options.decisive
  double decisive_threshold = 0.9;
  bool tolerance_changed = false;///< the tolerance changed the B or the overall class
  std::string b_estimate;        ///< which B estimate was used
  double tolerance_pct = 0;
  std::string table_name;
  std::vector<int> class_numbers;
  /// Human statement: "class 1 (P=0.97)", "class 2 or 3 (P=0.55/0.45)", "outside class 3 (P=0.8)".
  [[nodiscard]] std::string statement() const;
  /// Same for one parameter.
  [[nodiscard]] std::string statement(const ParameterVerdict& p) const;
};

/// Decide. `rho_BN` is the correlation between the log-estimates of B and N.
Verdict decide(const EstimateInput& B, const EstimateInput& N, double rho_BN, const VerdictOptions& options);

/// P(X ≤ a, Y ≤ b) for standard bivariate normal with correlation rho (a, b may be ±∞).
double bivariate_normal_cdf(double a, double b, double rho);

/// "class 1 (P=0.97)", "class 2 or 3 (P=0.55/0.45)", "outside class 3 (P=0.80)": the stated
/// class with its probability, and its more probable neighbour when below `decisive`. p_is holds
/// P(class = k) for each class of `classes` and then P(beyond the last).
std::string describe_class(const std::vector<double>& p_is, const std::optional<int>& cls,
                           const std::vector<int>& classes, double decisive = 0.9);

/// Describe a class ("1", "2", … or "none").
std::string class_label(const std::optional<int>& c);

/// JSON of the verdict (class_B, class_N, class, p_class and the details).
nlohmann::json to_json(const Verdict& v);

}  // namespace rwcalc
