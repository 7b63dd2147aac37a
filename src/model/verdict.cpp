// Class verdicts with probabilities from the estimates' confidence distributions.
#include "rwcalc/verdict.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/normal_quantile.hpp"

namespace rwcalc {

namespace {

double norm_cdf(double x) {
  if (x == std::numeric_limits<double>::infinity()) return 1.0;
  if (x == -std::numeric_limits<double>::infinity()) return 0.0;
  return boost::math::cdf(boost::math::normal_distribution<double>(), x);
}

/// Φ⁻¹ with the tails mapped to ±∞.
double norm_quantile(double p) {
  if (!(p > 0)) return -std::numeric_limits<double>::infinity();
  if (!(p < 1)) return std::numeric_limits<double>::infinity();
  return boost::math::quantile(boost::math::normal_distribution<double>(), p);
}

/// Index of an outcome among (classes…, beyond).
std::size_t outcome_index(const std::optional<int>& cls, const ClassTable& t) {
  if (!cls) return t.classes.size();
  for (std::size_t k = 0; k < t.classes.size(); ++k)
    if (t.classes[k].cls == *cls) return k;
  return t.classes.size();
}

/// The confidence distribution given that the coefficient is positive. A fitted term whose estimate
/// sits at or near 0 has a point mass there (half the distribution when the estimate is 0); a gyro
/// always has some ARW and flicker, so that mass is a statement about the data's resolution, not a
/// chance of a noiseless gyro, and left in place it made "class 1 (P=0.94)" verdicts on unresolved
/// B right 83 % of the time (docs/calibration.md). Resolved estimates have no mass at 0
/// and are unchanged.
std::function<double(double)> positive_part(const EstimateInput& e) {
  const double at_zero = e.cdf(std::numeric_limits<double>::min());
  if (!(at_zero > 0) || !(at_zero < 1)) return e.cdf;
  return [cdf = e.cdf, at_zero](double x) { return std::clamp((cdf(x) - at_zero) / (1.0 - at_zero), 0.0, 1.0); };
}

ParameterVerdict decide_one(const std::string& name, const std::string& unit, const EstimateInput& e,
                            const ClassTable& t, double tol_pct, bool is_b) {
  ParameterVerdict p;
  p.parameter = name;
  p.unit = unit;
  p.value = e.value;
  p.resolved = e.resolved;
  std::vector<double> strict;
  for (const auto& c : t.classes) {
    const double lim = is_b ? c.B_deg_per_h : c.N_deg_per_sqrt_h;
    strict.push_back(lim);
    p.limit.push_back(is_b ? lim * (1.0 + tol_pct / 100.0) : lim);
  }
  const auto cdf = positive_part(e);
  // The stated class is the one holding the median of the confidence distribution (for a resolved
  // estimate, about the fit's √ĉ; for an upper bound, usually the best class consistent with it).
  auto median_class = [&](const std::vector<double>& limits) -> std::optional<int> {
    for (std::size_t k = 0; k < limits.size(); ++k)
      if (cdf(limits[k]) >= 0.5) return t.classes[k].cls;
    return std::nullopt;
  };
  p.cls = median_class(p.limit);
  p.cls_strict = median_class(strict);
  double prev = 0;
  for (double lim : p.limit) {
    const double f = std::clamp(cdf(lim), prev, 1.0);  // keep it monotone
    p.p_meets.push_back(f);
    p.p_is.push_back(f - prev);
    p.margin_pct.push_back((lim - e.value) / lim * 100.0);
    prev = f;
  }
  p.p_is.push_back(1.0 - prev);
  p.p_class = p.p_is[outcome_index(p.cls, t)];
  return p;
}

nlohmann::json opt_class(const std::optional<int>& c) { return c ? nlohmann::json(*c) : nlohmann::json(nullptr); }

nlohmann::json param_json(const ParameterVerdict& p) {
  return {{"value", p.value},
          {"unit", p.unit},
          {"resolved", p.resolved},
          {"class", opt_class(p.cls)},
          {"class_strict", opt_class(p.cls_strict)},
          {"limits", p.limit},
          {"margin_pct", p.margin_pct},
          {"p_meets", p.p_meets},
          {"p_is", p.p_is},
          {"p_class", p.p_class}};
}

}  // namespace

ClassTable ClassTable::gost() {
  return {N_("GOST RV 52339-2005 (as reported by Bolotnov & Fomin 2021)"),
          {{1, 0.90, 0.005, 0.0010}, {2, 1.85, 0.008, 0.0015}, {3, 3.70, 0.015, 0.0030}}};
}

namespace {

ClassLimit class_limit(const json_input::Value& c) {
  c.object();
  ClassLimit l;
  l.cls = static_cast<int>(c.at("class").integer(0, 1000000));
  if (const auto p = c.find("position_error_km_h")) l.position_error_km_h = p->non_negative();
  l.B_deg_per_h = c.at("B_deg_per_h").positive();
  l.N_deg_per_sqrt_h = c.at("N_deg_per_sqrt_h").positive();
  return l;
}

}  // namespace

ClassTable ClassTable::parse(std::string_view text, const std::string& source) {
  const json_input::Document doc(text, source);
  const auto root = doc.root();
  root.object();
  ClassTable t;
  t.name = source;
  if (const auto name = root.find("name")) t.name = name->string();
  const auto list = root.at("classes");
  const auto classes = list.elements();
  if (classes.empty()) list.fail("must list at least one class");
  for (const auto& c : classes) {
    const ClassLimit l = class_limit(c);
    if (!t.classes.empty()) {
      const auto& p = t.classes.back();
      if (l.cls <= p.cls || l.B_deg_per_h < p.B_deg_per_h || l.N_deg_per_sqrt_h < p.N_deg_per_sqrt_h)
        c.fail(
            fmt::format("(class {}): classes must be listed best first, with ascending numbers and "
                        "non-decreasing limits",
                        l.cls));
    }
    t.classes.push_back(l);
  }
  return t;
}

ClassTable ClassTable::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, tr("cannot open the class-limits file"));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), path);
}

std::string_view to_string(BEstimate b) {
  switch (b) {
    case BEstimate::Fit: return "fit";
    case BEstimate::SigmaMin: return "sigma-min";
    case BEstimate::Avg100: return "avg100";
  }
  return "fit";
}

BEstimate parse_b_estimate(std::string_view s) {
  if (s == "fit") return BEstimate::Fit;
  if (s == "sigma-min") return BEstimate::SigmaMin;
  if (s == "avg100") return BEstimate::Avg100;
  throw UsageError(trf("unknown B estimate '{}' (use fit, sigma-min or avg100)", s));
}

EstimateInput lognormal_estimate(double value, double sigma) {
  EstimateInput e;
  e.value = value;
  e.resolved = true;
  const double s = value > 0 ? sigma / value : 0.0;
  const LogNormalInterval i = lognormal_interval95(value, sigma);
  e.low = i.low;
  e.high = i.high;
  e.cdf = [value, s](double x) {
    if (!(x > 0)) return 0.0;
    if (!(s > 0)) return x >= value ? 1.0 : 0.0;
    return norm_cdf(std::log(x / value) / s);
  };
  return e;
}

double bivariate_normal_cdf(double a, double b, double rho) {
  if (a == -std::numeric_limits<double>::infinity() || b == -std::numeric_limits<double>::infinity()) return 0.0;
  if (a == std::numeric_limits<double>::infinity()) return norm_cdf(b);
  if (b == std::numeric_limits<double>::infinity()) return norm_cdf(a);
  rho = std::clamp(rho, -0.999999, 0.999999);
  if (std::abs(rho) < 1e-12) return norm_cdf(a) * norm_cdf(b);
  // ∫_{-∞}^{a} φ(x) Φ((b − ρx)/√(1−ρ²)) dx by composite Simpson over [max(−9, a−…), a].
  if (a <= -9.0) return 0.0;  // Φ(−9) ≈ 1e-19
  const double lo = -9.0;
  const int n = 800;  // even
  const double h = (a - lo) / n;
  const double sr = std::sqrt(1.0 - rho * rho);
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    const double x = lo + i * h;
    const double f = std::exp(-0.5 * x * x) * norm_cdf((b - rho * x) / sr);
    sum += f * (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0));
  }
  return std::clamp(sum * h / 3.0 / std::sqrt(2.0 * std::numbers::pi), 0.0, 1.0);
}

std::string class_label(const std::optional<int>& c) { return c ? fmt::format("{}", *c) : std::string(tr("none")); }

Verdict decide(const EstimateInput& B, const EstimateInput& N, double rho_BN, const VerdictOptions& options) {
  require_valid(options);
  const ClassTable& t = options.table;
  Verdict v;
  v.table_name = t.name;
  for (const auto& c : t.classes) v.class_numbers.push_back(c.cls);
  v.b_estimate = std::string(to_string(options.b_estimate));
  v.tolerance_pct = options.tolerance_pct;
  v.rho_BN = std::isfinite(rho_BN) ? std::clamp(rho_BN, -1.0, 1.0) : 0.0;
  v.B = decide_one("B", "deg/h", B, t, options.tolerance_pct, true);
  v.N = decide_one("N", "deg/sqrt(h)", N, t, 0.0, false);

  auto worse = [](const std::optional<int>& a, const std::optional<int>& b) -> std::optional<int> {
    if (!a || !b) return std::nullopt;
    return std::max(*a, *b);
  };
  v.cls = worse(v.B.cls, v.N.cls);
  v.cls_strict = worse(v.B.cls_strict, v.N.cls_strict);
  v.tolerance_changed = v.B.cls != v.B.cls_strict || v.cls != v.cls_strict;

  double prev = 0;
  for (std::size_t k = 0; k < t.classes.size(); ++k) {
    const double g = bivariate_normal_cdf(norm_quantile(v.B.p_meets[k]), norm_quantile(v.N.p_meets[k]), v.rho_BN);
    const double f = std::clamp(g, prev, 1.0);
    v.p_meets.push_back(f);
    v.p_is.push_back(f - prev);
    prev = f;
  }
  v.p_is.push_back(1.0 - prev);
  v.p_class = v.p_is[outcome_index(v.cls, t)];
  v.decisive_threshold = options.decisive;
  v.decisive = v.p_class >= options.decisive;
  return v;
}

std::string describe_class(const std::vector<double>& p_is, const std::optional<int>& cls,
                           const std::vector<int>& classes, double decisive) {
  if (p_is.size() != classes.size() + 1) throw UsageError(tr("class probabilities do not match the class table"));
  const std::size_t n = classes.size();
  const std::size_t s =
      cls ? static_cast<std::size_t>(std::find(classes.begin(), classes.end(), *cls) - classes.begin()) : n;
  auto label = [&](std::size_t k) { return k < n ? fmt::format("{}", classes[k]) : std::string(tr("outside")); };
  if (p_is[s] >= decisive || n == 0) {
    if (s == n) return trf("outside class {} (P={:.2f})", classes.empty() ? 0 : classes.back(), p_is[s]);
    return trf("class {} (P={:.2f})", label(s), p_is[s]);
  }
  // Runner-up: the more probable neighbour.
  std::size_t r = s;
  if (s > 0) r = s - 1;
  if (s + 1 <= n && (r == s || p_is[s + 1] > p_is[r])) r = s + 1;
  const std::size_t a = std::min(s, r);
  const std::size_t b = std::max(s, r);
  if (b == n) return trf("class {} or outside class {} (P={:.2f}/{:.2f})", label(a), classes.back(), p_is[a], p_is[b]);
  return trf("class {} or {} (P={:.2f}/{:.2f})", label(a), label(b), p_is[a], p_is[b]);
}

void Verdict::withhold(std::string reason, std::string command) {
  withheld = true;
  withheld_reason = std::move(reason);
  next_command = std::move(command);
}

std::string Verdict::statement() const {
  if (withheld) return std::string(tr(kNoVerdict));
  return describe_class(p_is, cls, class_numbers, decisive_threshold);
}

std::string Verdict::statement(const ParameterVerdict& p) const {
  if (withheld) return std::string(tr("no verdict"));
  return describe_class(p.p_is, p.cls, class_numbers, decisive_threshold);
}

namespace {

/// A withheld verdict: what was judged against (table, limits, the estimates) but no class and no
/// probability; "withheld", the reason and the command to run next.
nlohmann::json withheld_json(const Verdict& v) {
  auto param = [](const ParameterVerdict& p) {
    return nlohmann::json{{"value", p.value},   {"unit", p.unit},          {"resolved", p.resolved},
                          {"class", nullptr},   {"class_strict", nullptr}, {"limits", p.limit},
                          {"p_meets", nullptr}, {"p_is", nullptr},         {"p_class", nullptr}};
  };
  const std::string st = v.statement(), by = v.statement(v.B);
  return {{"withheld", true},
          {"reason", v.withheld_reason},
          {"command", v.next_command},
          {"class_B", nullptr},
          {"class_N", nullptr},
          {"class", nullptr},
          {"class_strict", nullptr},
          {"p_class", nullptr},
          {"p_class_B", nullptr},
          {"p_class_N", nullptr},
          {"statement", st},
          {"statement_B", by},
          {"statement_N", by},
          {"decisive", false},
          {"b_estimate", v.b_estimate},
          {"tolerance_pct", v.tolerance_pct},
          {"tolerance_changed", false},
          {"table", v.table_name},
          {"classes", v.class_numbers},
          {"p_meets", nullptr},
          {"p_is", nullptr},
          {"rho_BN", v.rho_BN},
          {"B", param(v.B)},
          {"N", param(v.N)}};
}

}  // namespace

nlohmann::json to_json(const Verdict& v) {
  if (v.withheld) return withheld_json(v);
  return {{"class_B", opt_class(v.B.cls)},
          {"class_N", opt_class(v.N.cls)},
          {"class", opt_class(v.cls)},
          {"p_class", v.p_class},
          {"p_class_B", v.B.p_class},
          {"p_class_N", v.N.p_class},
          {"class_strict", opt_class(v.cls_strict)},
          {"statement", v.statement()},
          {"statement_B", v.statement(v.B)},
          {"statement_N", v.statement(v.N)},
          {"decisive", v.decisive},
          {"b_estimate", v.b_estimate},
          {"tolerance_pct", v.tolerance_pct},
          {"tolerance_changed", v.tolerance_changed},
          {"table", v.table_name},
          {"classes", v.class_numbers},
          {"p_meets", v.p_meets},
          {"p_is", v.p_is},
          {"rho_BN", v.rho_BN},
          {"B", param_json(v.B)},
          {"N", param_json(v.N)}};
}

}  // namespace rwcalc
