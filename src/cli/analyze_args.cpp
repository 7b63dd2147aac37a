#include "analyze_args.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <limits>

#include "numeric_options.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::cli {

namespace {

/// "A:B" with either side optional → {a, b}; defaults for empty sides.
std::pair<double, double> parse_range(const std::string& spec, const char* what, double lo_default, double hi_default) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos) throw UsageError(trf("{} must be TMIN:TMAX in seconds, got '{}'", what, spec));
  auto num = [&](std::string s, double def) {
    if (s.empty()) return def;
    double v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v) || v < 0)
      throw UsageError(trf("{}: '{}' is not a non-negative number of seconds", what, s));
    return v;
  };
  // Their order is the options' rule (FitOptions, MethodOptions::validate).
  return {num(spec.substr(0, colon), lo_default), num(spec.substr(colon + 1), hi_default)};
}

}  // namespace

void add_outlier_options(CLI::App& app, std::string& action, double& threshold) {
  app.add_option("--outliers", action,
                 tr("Isolated outliers are always detected and reported (sample, time, line); then: keep "
                    "(default: analyse the data as read), remove (drop them; later samples move one period "
                    "earlier), or replace (by the median of the nearest good neighbours; keeps every sample)"))
      ->option_text("keep|remove|replace")
      ->capture_default_str()
      ->group(tr("Outliers"));
  app.add_option("--outlier-threshold", threshold,
                 tr("Detection threshold, robust sigma of the residual from the neighbour median"))
      ->check(real_in(kMinOutlierThreshold, 1e6, "robust sigma"))
      ->capture_default_str()
      ->group(tr("Outliers"));
}

CLI::Option* add_temperature_option(CLI::App& app, std::optional<double>& temperature, const std::string& help) {
  return app.add_option("--temperature", temperature, help)
      ->check(real_in(kMinTemperatureC, kMaxTemperatureC, "deg C"));
}

void AnalyzeArgs::add_to(CLI::App& app) {
  app.add_option("--fit-range", fit_range,
                 tr("Tau range of the fit, TMIN:TMAX in s (either may be empty; default: all octave points, or "
                    "tau >= 10 tau_f when the shortest tau shows an output filter of time constant tau_f)"))
      ->group(tr("Fit"));
  app.add_option("--min-edf", min_edf, tr("Leave out AV points with fewer equivalent degrees of freedom"))
      ->check(real_in(0.0, 1e12, "", Ends::OpenLow))
      ->capture_default_str()
      ->group(tr("Fit"));
  app.add_option("--terms", terms, tr("Terms to fit, a subset of QNBKR"))->capture_default_str()->group(tr("Fit"));
  app.add_flag("--all-terms", keep_all_terms,
               tr("Keep every fitted term in the model (default: K, R, Q not supported by the data are "
                  "left out and reported as upper bounds)"))
      ->group(tr("Fit"));
  app.add_option("--readout", readout,
                 tr("Read-out model of pulse counts: auto (the better of the two), counter (a plain counter's "
                    "sawtooth plus white angle noise Q) or white (Q alone: a dithered counter)"))
      ->option_text("auto|counter|white")
      ->capture_default_str()
      ->group(tr("Fit"));
  app.add_option("--tau", tau,
                 tr("Tau grid of the reported Allan deviation: octave, decade, dense[:P] (P per decade, default 20, "
                    "up to N/10), all, or a list of seconds; the fit always uses the octave points"))
      ->capture_default_str()
      ->group(tr("Fit"));
  latitude_option = app.add_option("--latitude", latitude_deg,
                                   tr("Latitude for the vertical Earth rate, degrees (given: the Earth rate is "
                                      "subtracted whatever the input)"))
                        ->check(real_in(-90.0, 90.0, "deg"))
                        ->capture_default_str()
                        ->group(tr("Earth rate"));
  app.add_option("--earth-rate", earth_rate,
                 tr("Expected sensed Earth rate, deg/h (overrides --latitude; given: it is subtracted whatever the "
                    "input)"))
      ->check(real_in(-kMaxRateDegPerH, kMaxRateDegPerH, "deg/h"))
      ->group(tr("Earth rate"));
  app.add_flag("--vertical", vertical,
               tr("The gyro's axis is vertical: subtract the vertical Earth rate and give the class verdict for any "
                  "input (default: only for pulse or counter input, a ring-laser gyro's)"))
      ->group(tr("Earth rate"));
  app.add_option("--b-estimate", b_estimate, tr("B estimate the verdict uses: fit, sigma-min or avg100"))
      ->option_text("fit|sigma-min|avg100")
      ->capture_default_str()
      ->group(tr("Verdict"));
  app.add_option("--tolerance", tolerance_pct,
                 tr("Accept a B up to PCT % above a class limit (the paper's heading-gyro rule, e.g. 50)"))
      ->check(real_in(0.0, 1000.0, "%"))
      ->capture_default_str()
      ->group(tr("Verdict"));
  app.add_option("--limits", limits_file,
                 tr("Class table as JSON (default: GOST RV 52339); given, the verdict is made for any input"))
      ->group(tr("Verdict"));
  app.add_option("--block", block_s, tr("Block length of the averaging cross-check, s"))
      ->check(real_in(0.0, 1e9, "s", Ends::OpenLow))
      ->capture_default_str()
      ->group(tr("Cross-checks"));
  app.add_option("--direct-range", direct_range, tr("Interval lengths of the direct N method, TMIN:TMAX in s"))
      ->capture_default_str()
      ->group(tr("Cross-checks"));
  add_outlier_options(app, outliers, outlier_threshold);
}

AnalysisOptions AnalyzeArgs::options() const {
  AnalysisOptions o;
  if (!fit_range.empty()) {
    const auto [a, b] = parse_range(fit_range, "--fit-range", 0.0, std::numeric_limits<double>::infinity());
    o.fit.tau_min_s = a;
    o.fit.tau_max_s = b;
    o.fit_range_given = true;
  }
  o.allan.grid = TauGrid::parse(tau);
  o.fit.min_edf = min_edf;
  o.fit.enabled = {false, false, false, false, false};
  if (terms.empty()) throw UsageError(tr("--terms: give at least one of Q, N, B, K, R"));
  for (char c : terms) {
    const std::string names = "QNBKR";
    const auto p = names.find(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (p == std::string::npos) throw UsageError(trf("--terms: unknown term '{}' (use Q, N, B, K, R)", c));
    o.fit.enabled[p] = true;
  }
  o.fit.select_terms = !keep_all_terms;
  if (readout == "auto")
    o.fit.readout = Readout::Auto;
  else if (readout == "counter")
    o.fit.readout = Readout::Counter;
  else if (readout == "white")
    o.fit.readout = Readout::White;
  else
    throw UsageError(trf("--readout: unknown read-out '{}' (use auto, counter or white)", readout));
  o.latitude_deg = latitude_deg;
  o.earth_rate_deg_per_h = earth_rate;
  // Asked for: the Earth rate by --vertical, --earth-rate or --latitude; the verdict by --vertical or
  // --limits. Otherwise analyze decides by the input (on for pulse or counter input).
  if (vertical || earth_rate || (latitude_option && latitude_option->count() > 0)) o.earth_rate = true;
  if (vertical || !limits_file.empty()) o.verdict_wanted = true;
  o.verdict.b_estimate = parse_b_estimate(b_estimate);
  o.verdict.tolerance_pct = tolerance_pct;
  if (!limits_file.empty()) o.verdict.table = ClassTable::load(limits_file);
  o.methods.block_s = block_s;
  const auto [dl, dh] = parse_range(direct_range, "--direct-range", 1.0, 100.0);
  o.methods.direct_t_min_s = dl;
  o.methods.direct_t_max_s = dh;
  o.outlier_action = parse_outlier_action(outliers);
  o.outlier_threshold = outlier_threshold;
  require_valid(o);  // the library's rules, before any file is read
  return o;
}

}  // namespace rwcalc::cli
