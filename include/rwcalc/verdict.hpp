#pragma once
#ifndef RWCALC_USES_MODEL
#error "rwcalc/verdict.hpp belongs to the model layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file verdict.hpp
/// Accuracy class of a gyro from B and N (the best class whose limits the estimates meet; null
/// beyond the last), with the probability that the true values meet each class.
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/validate.hpp"

#include "rwcalc/i18n.hpp"

namespace rwcalc {

struct ClassLimit {
  int cls = 0;                     ///< class number (1 is the best)
  double position_error_km_h = 0;  ///< navigation position error the class stands for
  double B_deg_per_h = 0;          ///< limit on B
  double N_deg_per_sqrt_h = 0;     ///< limit on N
};

struct ClassTable {
  std::string name;
  std::vector<ClassLimit> classes;  ///< ascending class numbers, limits non-decreasing

  /// GOST RV 52339-2005 as reported by Bolotnov & Fomin (2021): B ≤ 0.005/0.008/0.015 °/h,
  /// N ≤ 0.0010/0.0015/0.0030 °/√h for classes 1/2/3.
  static ClassTable gost();
  /// From JSON: {"name": …, "classes": [{"class": 1, "position_error_km_h": 0.9, "B_deg_per_h":
  /// 0.005, "N_deg_per_sqrt_h": 0.001}, …]}. Throws InputError (source, line, key path).
  static ClassTable parse(std::string_view text, const std::string& source);
  static ClassTable load(const std::string& path);
};

/// Which estimate of B the verdict uses: the AV fit, σ_min/0.6643, or the spread of 100-s means.
enum class BEstimate { Fit, SigmaMin, Avg100 };
std::string_view to_string(BEstimate b);
BEstimate parse_b_estimate(std::string_view s);  ///< "fit", "sigma-min", "avg100"; else UsageError

struct VerdictOptions {
  ClassTable table = ClassTable::gost();
  BEstimate b_estimate = BEstimate::Fit;
  /// The seed paper's heading-gyro rule: a B up to this many percent above a class limit is
  /// accepted for that class (0: strict).
  double tolerance_pct = 0;
  double decisive = 0.9;  ///< a stated class less probable than this is given with its runner-up

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// An estimate's reported value (the upper bound when not resolved) and its distribution.
struct EstimateInput {
  double value = 0;
  double low = 0;  ///< 95 % bounds
  double high = 0;
  bool resolved = true;
  std::function<double(double)> cdf;  ///< P(true ≤ x); non-decreasing, 0 at x ≤ 0
};
/// Log-normal distribution with the given standard error (σ_min and 100-s B).
EstimateInput lognormal_estimate(double value, double sigma);

struct ParameterVerdict {
  std::string parameter;  ///< "B" or "N"
  std::string unit;       ///< "deg/h" or "deg/sqrt(h)"
  double value = 0;
  bool resolved = true;
  std::optional<int> cls;          ///< empty: beyond the last class
  std::optional<int> cls_strict;   ///< without the tolerance
  std::vector<double> limit;       ///< per class, tolerance applied
  std::vector<double> margin_pct;  ///< (limit − value)/limit·100 per class
  std::vector<double> p_meets;     ///< P(true ≤ limit) per class
  std::vector<double> p_is;        ///< P(true class = k) per class, then P(beyond)
  double p_class = 0;              ///< probability of the stated class
};

/// The statement of a withheld verdict (Verdict::withhold), untranslated.
inline constexpr const char* kNoVerdict = N_("no verdict: the noise model does not describe this record");

struct Verdict {
  ParameterVerdict B, N;
  std::optional<int> cls;  ///< the worse of the two
  std::optional<int> cls_strict;
  std::vector<double> p_meets;  ///< joint (Gaussian copula) per class
  std::vector<double> p_is;     ///< then P(beyond)
  double p_class = 0;
  double rho_BN = 0;  ///< correlation of the log-estimates in the copula
  bool decisive = true;
  double decisive_threshold = 0.9;
  bool tolerance_changed = false;
  std::string b_estimate;
  double tolerance_pct = 0;
  std::string table_name;
  std::vector<int> class_numbers;
  /// No verdict: the fit the estimates come from is rejected, so no class and no probability is
  /// stated; `withheld_reason` says why and `next_command` what to run next.
  bool withheld = false;
  std::string withheld_reason, next_command;
  /// Withholds the verdict (the class and the probabilities stay computed but are not stated).
  void withhold(std::string reason, std::string command);
  [[nodiscard]] std::string statement() const;  ///< see describe_class; "no verdict: …" when withheld
  [[nodiscard]] std::string statement(const ParameterVerdict& p) const;
};

/// `rho_BN` is the correlation between the log-estimates of B and N.
Verdict decide(const EstimateInput& B, const EstimateInput& N, double rho_BN, const VerdictOptions& options);

/// P(X ≤ a, Y ≤ b) for a standard bivariate normal with correlation rho (a, b may be ±∞).
double bivariate_normal_cdf(double a, double b, double rho);

/// "class 1 (P=0.97)", "class 2 or 3 (P=0.55/0.45)", "outside class 3 (P=0.80)": the stated class
/// and, below `decisive`, its more probable neighbour. p_is: P(class = k) per class, then beyond.
std::string describe_class(const std::vector<double>& p_is, const std::optional<int>& cls,
                           const std::vector<int>& classes, double decisive = 0.9);

/// "1", "2", … or "none".
std::string class_label(const std::optional<int>& c);

nlohmann::json to_json(const Verdict& v);

}  // namespace rwcalc
