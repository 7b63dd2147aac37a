// The figures: gnuplot scripts generated from the analysis, batch and diagnosis JSON objects.
#include "rwcalc/plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>

#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"

namespace rwcalc {

using nlohmann::json;

namespace {

// ---- reading the JSON defensively: a missing or null key is "absent", never 0 or NaN -------

std::optional<double> number_at(const json& j, std::string_view key) {
  if (!j.is_object()) return std::nullopt;
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return std::nullopt;
  const double v = it->get<double>();
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

const json& child(const json& j, std::string_view key) {
  static const json null_json;
  if (!j.is_object()) return null_json;
  const auto it = j.find(key);
  return it == j.end() ? null_json : *it;
}

std::string string_at(const json& j, std::string_view key) {
  const auto& c = child(j, key);
  return c.is_string() ? c.get<std::string>() : std::string();
}

/// A fitted coefficient: {value, sigma, low95, high95, resolved[, estimate, in_model]}. When not
/// resolved, `value` is the 95 % upper bound; `estimate` is the model's own value (may be 0).
struct Coefficient {
  std::optional<double> value;
  std::optional<double> high95;
  double model = 0;  ///< what the fitted model curve uses
  bool resolved = false;
};

Coefficient coefficient(const json& fit, std::string_view key) {
  const auto& c = child(fit, key);
  Coefficient r;
  r.value = number_at(c, "value");
  r.high95 = number_at(c, "high95");
  const auto& res = child(c, "resolved");
  r.resolved = res.is_boolean() ? res.get<bool>() : r.value.has_value();
  const auto& in_model = child(c, "in_model");
  if (in_model.is_boolean() && !in_model.get<bool>())
    r.model = 0;  // left out of the model by the term selection
  else if (const auto est = number_at(c, "estimate"))
    r.model = *est;
  else
    r.model = r.resolved ? r.value.value_or(0.0) : 0.0;
  return r;
}

struct AllanRow {
  double tau = 0, dev = 0, low = 0, high = 0;
};

/// The usable Allan points (τ > 0, σ > 0); bounds default to σ itself when absent.
std::vector<AllanRow> allan_rows(const json& allan) {
  std::vector<AllanRow> rows;
  const auto& pts = child(allan, "points");
  if (!pts.is_array()) return rows;
  for (const auto& p : pts) {
    const auto tau = number_at(p, "tau_s");
    const auto dev = number_at(p, "dev");
    if (!tau || !dev || *tau <= 0 || *dev <= 0) continue;
    AllanRow r{*tau, *dev, number_at(p, "dev_low").value_or(*dev), number_at(p, "dev_high").value_or(*dev)};
    if (r.low <= 0) r.low = r.dev;  // a zero lower bound cannot be drawn on a log axis
    rows.push_back(r);
  }
  std::sort(rows.begin(), rows.end(), [](const AllanRow& a, const AllanRow& b) { return a.tau < b.tau; });
  return rows;
}

// ---- script text ---------------------------------------------------------------------------

/// A number for display: 4 significant digits, no exponent when avoidable.
std::string show(double v) { return fmt::format("{:.4g}", v); }

std::string temperature_label(const json& t) {
  if (!t.is_number()) return {};
  const double v = t.get<double>();
  if (!std::isfinite(v)) return {};
  return fmt::format("{}{:g} °C", v > 0 ? "+" : v < 0 ? "−" : "", std::fabs(v));
}

/// 10^floor(log10 lo) … 10^ceil(log10 hi): whole decades, so the 10^n ticks frame the data.
std::pair<double, double> decade_range(double lo, double hi) {
  double a = std::pow(10.0, std::floor(std::log10(lo)));
  double b = std::pow(10.0, std::ceil(std::log10(hi)));
  if (b <= a) b = a * 10;
  return {a, b};
}

/// The key below the plot area, filled top to bottom in two columns (one when the labels are
/// long), so it never hides data and leaves the plot its full width.
std::string key_below(std::size_t series, std::size_t longest_label) {
  const std::size_t columns = longest_label > 52 ? 1 : 2;
  const std::size_t rows = std::max<std::size_t>(1, (series + columns - 1) / columns);
  return fmt::format("set key outside below center vertical maxrows {} Left reverse noenhanced samplen 2.5 "
                     "spacing 1.05 width 2 height 1 nobox\n",
                     rows);
}

/// Characters (UTF-8 code points) of the longest key title among plot elements (" t '…'").
std::size_t longest_title(const std::vector<std::string>& elements) {
  std::size_t longest = 0;
  for (const auto& e : elements) {
    const auto p = e.rfind(" t '");
    if (p == std::string::npos) continue;
    std::size_t n = 0;
    for (std::size_t i = p + 4; i < e.size(); ++i)
      if ((static_cast<unsigned char>(e[i]) & 0xC0) != 0x80) ++n;
    longest = std::max(longest, n);
  }
  return longest;
}

/// The look shared by all log-log Allan figures.
std::string loglog_preamble(const std::string& title, const std::string& ylabel, double xmin, double xmax,
                            double ymin, double ymax, const std::vector<std::string>& elements) {
  std::string s;
  s += "set encoding utf8\n";
  s += fmt::format("set title {} noenhanced\n", gnuplot_string(title));
  s += "set logscale xy 10\n";
  s += "set format x '10^{%L}'\nset format y '10^{%L}'\n";
  s += "set xtics nomirror\nset ytics nomirror\nset mxtics 10\nset mytics 10\n";
  s += "set grid xtics ytics mxtics mytics lw 0.6 lc rgb '#d9d9d9', lw 0.4 lc rgb '#eeeeee'\n";
  s += "set border 3 lw 1\n";
  s += "set xlabel 'τ (s)' noenhanced offset 0,0.7\n";  // clear of the key below
  s += fmt::format("set ylabel {} noenhanced\n", gnuplot_string(ylabel));
  s += fmt::format("set xrange [{:.6g}:{:.6g}]\nset yrange [{:.6g}:{:.6g}]\n", xmin, xmax, ymin, ymax);
  s += key_below(elements.size(), longest_title(elements));
  s += "set samples 250\n";
  return s;
}

std::string allan_ylabel(const json& allan) {
  const auto unit = string_at(allan, "unit");
  if (unit.empty() || unit == "deg/h") return "Allan deviation σ(τ) (°/h)";
  if (unit == "1") return "Allan deviation σ(τ)";
  return fmt::format("Allan deviation σ(τ) ({})", unit);
}

bool is_gyro(const json& allan) {
  const auto unit = string_at(allan, "unit");
  return unit.empty() || unit == "deg/h";
}

/// The class limits for B (°/h) by class: `verdict.classes` with `verdict.B.limits` (the limits
/// the verdict applied, tolerance included), else the GOST RV 52339 table as the seed paper
/// reports it.
std::vector<std::pair<int, double>> b_limits(const json& analysis) {
  std::vector<std::pair<int, double>> r;
  const auto& verdict = child(analysis, "verdict");
  const auto& classes = child(verdict, "classes");
  const auto& limits = child(child(verdict, "B"), "limits");
  if (classes.is_array() && limits.is_array() && classes.size() == limits.size()) {
    for (std::size_t i = 0; i < classes.size(); ++i)
      if (classes[i].is_number() && limits[i].is_number() && limits[i].get<double>() > 0)
        r.emplace_back(classes[i].get<int>(), limits[i].get<double>());
  }
  if (r.empty()) r = {{1, 0.005}, {2, 0.008}, {3, 0.015}};
  return r;
}

/// " (+50 % tolerance)" when the verdict widened the B limits by the paper's heading-gyro rule.
std::string tolerance_note(const json& analysis) {
  const auto t = number_at(child(analysis, "verdict"), "tolerance_pct");
  return t && *t > 0 ? fmt::format(" (+{:g} % tolerance)", *t) : std::string();
}

/// √(2 ln2/π): the flicker floor of σ per unit B.
constexpr double kFloorPerB = 0.66428;

/// The five IEEE terms as gnuplot functions of τ (s) returning σ in °/h.
constexpr const char* kTermFunctions =
    "# Terms of the rate noise model, σ in °/h for τ in s (IEEE 952 units):\n"
    "#   Q ″ (σ² = 3Q²/τ²), N °/√h (σ = 60N/√τ), B °/h (σ = 0.6643·B),\n"
    "#   K °/h/√h (σ = K·√(τ/3)/60), R °/h² (σ = R·τ/(√2·3600))\n"
    "sQ(t, c) = sqrt(3) * c / t\n"
    "sN(t, c) = 60 * c / sqrt(t)\n"
    "sB(t, c) = sqrt(2 * log(2) / pi) * c + 0 * t\n"
    "sK(t, c) = c * sqrt(t / 3) / 60\n"
    "sR(t, c) = c * t / (sqrt(2) * 3600)\n";

struct Term {
  const char* key;     // fit key
  const char* var;     // gnuplot variable
  const char* fn;      // gnuplot function
  const char* label;   // legend name
  const char* unit;    // unit of the coefficient
  const char* colour;
};
constexpr std::array<Term, 5> kTerms{{
    {"Q_arcsec", "Q", "sQ", "quantization Q", "″", "#7b3294"},
    {"N_deg_per_sqrt_h", "N", "sN", "angle random walk N", "°/√h", "#1f77b4"},
    {"B_deg_per_h", "B", "sB", "bias instability B", "°/h", "#2ca02c"},
    {"K_deg_per_h_per_sqrt_h", "K", "sK", "rate random walk K", "°/h/√h", "#ff7f0e"},
    {"R_deg_per_h2", "R", "sR", "rate ramp R", "°/h²", "#8c564b"},
}};

void append_allan_block(std::string& s, const std::string& name, const std::vector<AllanRow>& rows) {
  s += fmt::format("${} << EOD\n# tau_s dev dev_low dev_high\n", name);
  for (const auto& r : rows) s += fmt::format("{:.10g} {:.10g} {:.10g} {:.10g}\n", r.tau, r.dev, r.low, r.high);
  s += "EOD\n";
}

/// A plot command assembled element by element, so the number of series is known exactly.
struct PlotCommand {
  std::vector<std::string> elements;
  void add(std::string e) { elements.push_back(std::move(e)); }
  [[nodiscard]] std::string text() const {
    std::string s = "plot ";
    for (std::size_t i = 0; i < elements.size(); ++i) s += (i ? ", \\\n     " : "") + elements[i];
    return s + "\n";
  }
};

/// Class-limit floor lines (0.6643·B_limit) as plot elements; `vars` receives their definitions.
void add_class_floors(const json& analysis, std::string& vars, PlotCommand& plot) {
  static constexpr std::array<const char*, 3> kDash{"2", "4", "5"};  // dots (3) mark upper bounds
  std::size_t i = 0;
  for (const auto& [cls, b] : b_limits(analysis)) {
    vars += fmt::format("B_class{} = {:.6g}   # °/h, class {} limit for B\n", cls, b, cls);
    plot.add(fmt::format("sB(x, B_class{0}) w l lw 1.3 dt {1} lc rgb '#d62728' t {2}", cls,
                         kDash[i % kDash.size()],
                         gnuplot_string(fmt::format("class {} limit B = {} °/h{} (floor {} °/h)", cls, show(b),
                                       tolerance_note(analysis), show(kFloorPerB * b)))));
    ++i;
  }
}

std::string default_analysis_title(const json& a) {
  std::string src = string_at(a, "source");
  if (src.empty()) src = string_at(a, "file");
  std::string t = "Allan deviation";
  if (!src.empty()) t += " of " + std::filesystem::path(src).filename().string();
  const auto temp = temperature_label(child(a, "temperature_c"));
  if (!temp.empty()) t += " at " + temp;
  return t;
}

std::string run_label(const json& run, std::size_t index) {
  auto t = temperature_label(child(run, "temperature_c"));
  std::string src = string_at(run, "source");
  if (src.empty()) src = string_at(run, "file");
  if (!src.empty()) src = std::filesystem::path(src).filename().string();
  if (!t.empty()) return src.empty() ? t : fmt::format("{} ({})", t, src);
  return src.empty() ? fmt::format("run {}", index + 1) : src;
}

void write_outputs(const std::vector<Figure>& figures, const PlotOptions& options, PlotResult& result) {
  for (const auto& f : figures) result.series += f.series;
  if (options.output.empty() && options.script.empty()) return;
  std::optional<PlotFormat> format;
  if (!options.output.empty()) format = plot_format_for(options.output);
  // Fail before the work (and before the script is written) when the figure could not be written.
  check_output_targets({{"--plot", options.output}, {"--plot-script", options.script}}, options.force);
  if (!options.script.empty()) {
    std::string target = options.output;
    if (target.empty()) target = std::filesystem::path(options.script).replace_extension(".svg").string();
    write_file_atomic(options.script,
                      full_script(figures, format.value_or(PlotFormat::Svg), options.width_px, target),
                      options.force);
  }
  if (format) write_file_atomic(options.output, render_figures(figures, *format, options.width_px), options.force);
}

}  // namespace

std::string temperature_colour(const json& temperature_c, std::size_t index) {
  if (temperature_c.is_number() && std::isfinite(temperature_c.get<double>())) {
    // Cold-to-hot anchors at the paper's test temperatures; linear in RGB between them.
    struct Anchor {
      double t;
      int r, g, b;
    };
    static constexpr std::array<Anchor, 5> kScale{{{-50, 0x1f, 0x3f, 0xa0},
                                                   {-20, 0x2b, 0x9b, 0xd6},
                                                   {0, 0x1a, 0x98, 0x50},
                                                   {25, 0xf0, 0x8c, 0x1a},
                                                   {50, 0xc8, 0x10, 0x2e}}};
    const double t = std::clamp(temperature_c.get<double>(), kScale.front().t, kScale.back().t);
    std::size_t k = 0;
    while (k + 2 < kScale.size() && t > kScale[k + 1].t) ++k;
    const auto& a = kScale[k];
    const auto& b = kScale[k + 1];
    const double w = (t - a.t) / (b.t - a.t);
    auto mix = [w](int x, int y) { return static_cast<int>(std::lround(x + w * (y - x))); };
    return fmt::format("#{:02x}{:02x}{:02x}", mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b));
  }
  static constexpr std::array<const char*, 8> kCategorical{"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                                           "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};
  return kCategorical[index % kCategorical.size()];
}

// ---- analyze: one run ----------------------------------------------------------------------

Figure analysis_figure(const json& analysis, const PlotOptions& options) {
  const auto& allan = child(analysis, "allan");
  const auto rows = allan_rows(allan);
  if (rows.empty())
    throw AnalysisError("the analysis has no Allan deviation points (allan.points with tau_s and dev): "
                        "nothing to plot");
  const bool gyro = is_gyro(allan);
  const auto& fit = child(analysis, "fit");

  double ymin = std::numeric_limits<double>::infinity(), ymax = 0;
  for (const auto& r : rows) {
    ymin = std::min(ymin, r.low);
    ymax = std::max(ymax, r.high);
  }
  std::string vars;
  PlotCommand plot;
  const auto conf = number_at(allan, "confidence");
  plot.add(fmt::format("$allan u 1:2:3:4 w yerrorbars pt 7 ps 0.55 lw 1.2 lc rgb '#222222' t {}",
                       gnuplot_string(conf ? fmt::format("measured σ(τ), {:g} % bounds", *conf * 100) : "measured σ(τ)")));

  if (gyro && fit.is_object()) {
    vars += kTermFunctions;
    vars += "# Coefficients of the fitted model (0 for a term the fit left out):\n";
    std::string model = "model(t) = sqrt(0";
    std::vector<std::string> term_lines;
    for (std::size_t i = 0; i < kTerms.size(); ++i) {
      const auto& t = kTerms[i];
      const auto c = coefficient(fit, t.key);
      vars += fmt::format("{} = {:.8g}   # {}\n", t.var, c.model, t.unit);
      model += fmt::format(" + {}(t, {})**2", t.fn, t.var);
      const double v = c.value.value_or(0.0);
      if (c.resolved && v > 0) {
        term_lines.push_back(fmt::format("{}(x, {}) w l lw 1.4 lc rgb '{}' t {}", t.fn, t.var, t.colour,
                                         gnuplot_string(fmt::format("{} = {} {}", t.label, show(v), t.unit))));
      } else if (const double bound = c.high95.value_or(v); !c.resolved && bound > 0) {
        // An unresolved term is only bounded: draw the bound, dashed.
        vars += fmt::format("{}_up95 = {:.8g}   # {}, 95 % upper bound\n", t.var, bound, t.unit);
        term_lines.push_back(fmt::format("{}(x, {}_up95) w l lw 1.2 dt 3 lc rgb '{}' t {}", t.fn, t.var,
                                         t.colour,
                                         gnuplot_string(fmt::format("{} < {} {} (95 %)", t.label, show(bound), t.unit))));
      }
    }
    vars += model + ")\n";
    plot.add(fmt::format("model(x) w l lw 2.2 lc rgb '#000000' t {}",
                         gnuplot_string(fit.contains("chi2_per_dof") && number_at(fit, "chi2_per_dof")
                               ? fmt::format("fitted model (χ²/dof = {:.3g})", *number_at(fit, "chi2_per_dof"))
                               : std::string("fitted model"))));
    for (auto& l : term_lines) plot.add(std::move(l));
    std::string floors;
    add_class_floors(analysis, floors, plot);
    vars += floors;
    for (const auto& [cls, b] : b_limits(analysis)) ymin = std::min(ymin, kFloorPerB * b);
  } else if (gyro) {
    // No fit: still show where the class limits lie.
    vars += kTermFunctions;
    add_class_floors(analysis, vars, plot);
    for (const auto& [cls, b] : b_limits(analysis)) ymin = std::min(ymin, kFloorPerB * b);
  }
  const auto [xmin, xmax] = decade_range(rows.front().tau, rows.back().tau);
  const auto [ylo, yhi] = decade_range(ymin, ymax);

  Figure f;
  f.name = "allan";
  f.height_px = options.height_px;
  f.script = loglog_preamble(options.title.empty() ? default_analysis_title(analysis) : options.title,
                             allan_ylabel(allan), xmin, xmax, ylo, yhi, plot.elements);
  append_allan_block(f.script, "allan", rows);
  f.script += vars;
  f.script += plot.text();
  f.series = static_cast<int>(plot.elements.size());
  return f;
}

// ---- batch: the runs overlaid, and the direct method ---------------------------------------

namespace {

/// Runs sorted by temperature (runs without one last, in input order).
std::vector<const json*> sorted_runs(const json& runs) {
  std::vector<const json*> r;
  if (runs.is_array())
    for (const auto& run : runs) r.push_back(&run);
  std::stable_sort(r.begin(), r.end(), [](const json* a, const json* b) {
    const auto ta = number_at(*a, "temperature_c"), tb = number_at(*b, "temperature_c");
    if (ta && tb) return *ta < *tb;
    return ta.has_value() && !tb.has_value();
  });
  return r;
}

constexpr std::array<int, 8> kPointTypes{7, 5, 9, 11, 13, 15, 4, 6};

}  // namespace

Figure batch_allan_figure(const json& runs, const PlotOptions& options) {
  const auto order = sorted_runs(runs);
  std::string blocks;
  PlotCommand plot;
  double xlo = std::numeric_limits<double>::infinity(), xhi = 0;
  double ylo = std::numeric_limits<double>::infinity(), yhi = 0;
  bool gyro = true;
  std::string ylabel = "Allan deviation σ(τ) (°/h)";
  for (std::size_t i = 0; i < order.size(); ++i) {
    const auto& run = *order[i];
    const auto rows = allan_rows(child(run, "allan"));
    if (rows.empty()) continue;
    gyro = gyro && is_gyro(child(run, "allan"));
    ylabel = allan_ylabel(child(run, "allan"));
    const auto name = fmt::format("run{}", i + 1);
    append_allan_block(blocks, name, rows);
    for (const auto& r : rows) {
      xlo = std::min(xlo, r.tau);
      xhi = std::max(xhi, r.tau);
      ylo = std::min(ylo, r.low);
      yhi = std::max(yhi, r.high);
    }
    const auto colour = temperature_colour(child(run, "temperature_c"), i);
    plot.add(fmt::format("${} u 1:2:3:4 w yerrorlines pt {} ps 0.6 lw 1.4 lc rgb '{}' t {}", name,
                         kPointTypes[i % kPointTypes.size()], colour, gnuplot_string(run_label(run, i))));
  }
  if (plot.elements.empty())
    throw AnalysisError("no run of the batch has Allan deviation points (runs[].allan.points): nothing to plot");
  std::string vars;
  if (gyro) {
    vars += kTermFunctions;
    const json& first = *order.front();
    add_class_floors(first, vars, plot);
    for (const auto& [cls, b] : b_limits(first)) ylo = std::min(ylo, kFloorPerB * b);
  }
  const auto [x0, x1] = decade_range(xlo, xhi);
  const auto [y0, y1] = decade_range(ylo, yhi);
  Figure f;
  f.name = "batch-allan";
  f.height_px = options.height_px;
  f.script = loglog_preamble(options.title.empty() ? "Allan deviation at each test temperature" : options.title,
                             ylabel, x0, x1, y0, y1, plot.elements);
  f.script += blocks + vars + plot.text();
  f.series = static_cast<int>(plot.elements.size());
  return f;
}

Figure batch_direct_figure(const json& runs, const PlotOptions& options) {
  const auto order = sorted_runs(runs);
  Figure f;
  f.name = "batch-direct";
  f.height_px = options.height_px;
  std::string blocks, vars;
  PlotCommand plot;
  double tmax = 0, vmax = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const auto& run = *order[i];
    const auto& direct = child(child(run, "methods"), "N_direct_deg_per_sqrt_h");
    const auto& curve = child(direct, "curve");
    if (!curve.is_array() || curve.empty()) continue;
    const auto name = fmt::format("direct{}", i + 1);
    std::string block = fmt::format("${} << EOD\n# t_s var_arcsec2\n", name);
    int n = 0;
    double run_tmax = 0;
    for (const auto& p : curve) {
      const auto t = number_at(p, "t_s");
      const auto v = number_at(p, "var_arcsec2");
      if (!t || !v) continue;
      block += fmt::format("{:.10g} {:.10g}\n", *t, *v);
      vmax = std::max(vmax, *v);
      run_tmax = std::max(run_tmax, *t);
      ++n;
    }
    block += "EOD\n";
    if (n == 0) continue;
    blocks += block;
    tmax = std::max(tmax, run_tmax);
    const auto colour = temperature_colour(child(run, "temperature_c"), i);
    const auto n_val = number_at(direct, "value");
    const auto& resolved = child(direct, "resolved");
    const bool n_resolved = !resolved.is_boolean() || resolved.get<bool>();
    auto slope = number_at(direct, "slope_arcsec2_per_s");
    if (!slope) slope = number_at(direct, "slope");
    // Without a stated slope, the regression's slope follows from N: D(t) = a + (60·N)²·t.
    if (!slope && n_val && n_resolved) slope = std::pow(60 * *n_val, 2);
    auto intercept = number_at(direct, "intercept_arcsec2");
    if (!intercept) intercept = number_at(direct, "intercept");
    // One key entry per run: the points carry the label, the line shares their colour.
    std::string label = run_label(run, i);
    if (n_val) label += fmt::format(": N {} {} °/√h", n_resolved ? "=" : "<", show(*n_val));
    plot.add(fmt::format("${} u 1:2 w p pt {} ps 0.8 lc rgb '{}' t {}", name, kPointTypes[i % kPointTypes.size()],
                         colour, gnuplot_string(label)));
    if (slope) {
      // The angle variance of ARW grows as (60N)²·t in ″² (N in °/√h, t in s).
      vars += fmt::format("slope{0} = {1:.8g}   # ″²/s\nintercept{0} = {2:.8g}   # ″²\n", i + 1, *slope,
                          intercept.value_or(0.0));
      plot.add(fmt::format("[0:{2:.6g}] intercept{0} + slope{0} * x w l lw 1.6 lc rgb '{1}' notitle", i + 1,
                           colour, run_tmax));
    }
  }
  if (plot.elements.empty()) return f;
  f.script += "set encoding utf8\n";
  f.script += fmt::format("set title {} noenhanced\n",
                          gnuplot_string(options.title.empty() ? "Direct method: variance of the angle over t (Earth rate removed), with regression lines"
                                                  : options.title + " — direct method"));
  f.script += "set xtics nomirror\nset ytics nomirror\nset mxtics\nset mytics\n";
  f.script += "set grid xtics ytics lw 0.6 lc rgb '#d9d9d9'\nset border 3 lw 1\n";
  f.script += "set xlabel 'interval length t (s)' noenhanced\n";
  f.script += "set ylabel 'angle variance D(t) (″²)' noenhanced\n";
  f.script += fmt::format("set xrange [0:{:.6g}]\nset yrange [0:{:.6g}]\n", tmax * 1.02, vmax * 1.25);
  // The variance grows with t, so the upper-left corner is empty: the key goes there.
  f.script += "set key inside left top vertical Left reverse noenhanced samplen 2.5 spacing 1.1 opaque "
              "box lc rgb '#bbbbbb'\n";
  f.script += blocks + vars + plot.text();
  f.series = static_cast<int>(plot.elements.size());
  return f;
}

// ---- diagnose: measurement against the simulated bands --------------------------------------

namespace {

struct BandRow {
  double tau = 0, dev = 0, low = 0, high = 0;
  double median = 0;  ///< the ensemble's median σ (0 when not given)
};

/// The band of the base or the extended model: `base_model.band` / `extended_model.band`, or the
/// top-level `band` / `band_extended` that `rwcalc diagnose --json` writes.
const json& band_of(const json& diagnosis, bool extended) {
  const auto& nested = child(child(diagnosis, extended ? "extended_model" : "base_model"), "band");
  return nested.is_array() ? nested : child(diagnosis, extended ? "band_extended" : "band");
}

std::vector<BandRow> band_rows(const json& band) {
  std::vector<BandRow> rows;
  if (!band.is_array()) return rows;
  for (const auto& p : band) {
    const auto tau = number_at(p, "tau_s");
    const auto lo = number_at(p, "band_low");
    const auto hi = number_at(p, "band_high");
    if (!tau || !lo || !hi || *tau <= 0 || *lo <= 0 || *hi <= 0) continue;
    rows.push_back({*tau, number_at(p, "dev").value_or(0.0), *lo, *hi, number_at(p, "median").value_or(0.0)});
  }
  std::sort(rows.begin(), rows.end(), [](const BandRow& a, const BandRow& b) { return a.tau < b.tau; });
  return rows;
}

std::string band_label(const char* what, const json& model, const std::vector<BandRow>& rows) {
  int inside = 0, measured = 0;
  for (const auto& r : rows) {
    if (r.dev <= 0) continue;
    ++measured;
    inside += (r.dev >= r.low && r.dev <= r.high) ? 1 : 0;
  }
  const auto level = number_at(model, "band_level");
  std::string s = fmt::format("{} model: simulated {}band", what,
                              level ? fmt::format("{:g} % ", *level * 100) : std::string());
  if (measured > 0) s += fmt::format(", {} of {} τ inside", inside, measured);
  return s;
}

}  // namespace

Figure diagnosis_figure(const json& diagnosis, const PlotOptions& options) {
  const auto base = band_rows(band_of(diagnosis, false));
  const auto ext = band_rows(band_of(diagnosis, true));
  if (base.empty())
    throw AnalysisError("the diagnosis has no simulated band (band or base_model.band, with tau_s, band_low, "
                        "band_high): nothing to plot");
  std::string blocks;
  PlotCommand plot;
  double xlo = std::numeric_limits<double>::infinity(), xhi = 0;
  double ylo = std::numeric_limits<double>::infinity(), yhi = 0;
  auto add_band = [&](const char* name, const std::vector<BandRow>& rows) {
    blocks += fmt::format("${} << EOD\n# tau_s dev band_low band_high median\n", name);
    for (const auto& r : rows) {
      blocks += fmt::format("{:.10g} {:.10g} {:.10g} {:.10g} {:.10g}\n", r.tau, r.dev, r.low, r.high, r.median);
      xlo = std::min(xlo, r.tau);
      xhi = std::max(xhi, r.tau);
      ylo = std::min({ylo, r.low, r.dev > 0 ? r.dev : r.low});
      yhi = std::max({yhi, r.high, r.dev});
    }
    blocks += "EOD\n";
  };
  add_band("base", base);
  plot.add(fmt::format("$base u 1:3:4 w filledcurves fs transparent solid 0.30 noborder lc rgb '#1f77b4' t {}",
                       gnuplot_string(band_label("base", child(diagnosis, "base_model"), base))));
  if (std::all_of(base.begin(), base.end(), [](const BandRow& r) { return r.median > 0; }))
    plot.add("$base u 1:5 w l lw 1.2 dt 2 lc rgb '#1f77b4' t 'base model: simulated median'");
  if (!ext.empty()) {
    add_band("extended", ext);
    plot.add(fmt::format(
        "$extended u 1:3:4 w filledcurves fs transparent pattern 5 border lc rgb '#e6550d' lc rgb '#e6550d' t {}",
        gnuplot_string(band_label("extended", child(diagnosis, "extended_model"), ext))));
  }
  // The measurement, and the τ where it leaves the base band marked so they stand out.
  std::string outside = "$outside << EOD\n# tau_s dev (outside the base band)\n";
  int n_outside = 0;
  for (const auto& r : base) {
    if (r.dev > 0 && (r.dev < r.low || r.dev > r.high)) {
      outside += fmt::format("{:.10g} {:.10g}\n", r.tau, r.dev);
      ++n_outside;
    }
  }
  outside += "EOD\n";
  plot.add("$base u 1:($2 > 0 ? $2 : NaN) w lp pt 7 ps 0.6 lw 1.4 lc rgb '#000000' t 'measured σ(τ)'");
  if (n_outside > 0) {
    blocks += outside;
    plot.add("$outside u 1:2 w p pt 6 ps 1.6 lw 1.6 lc rgb '#d62728' t 'measured, outside the base band'");
  }
  std::string title = options.title;
  if (title.empty()) {
    title = "Measurement against simulations of the noise model";
    std::vector<std::string> effects;
    const auto& findings = child(diagnosis, "findings");
    if (findings.is_array())
      for (const auto& fnd : findings)
        if (auto e = string_at(fnd, "effect"); !e.empty()) effects.push_back(e);
    title += effects.empty() ? " (no finding)" : fmt::format(" (findings: {})", fmt::join(effects, ", "));
  }
  const auto [x0, x1] = decade_range(xlo, xhi);
  const auto [y0, y1] = decade_range(ylo, yhi);
  Figure f;
  f.name = "diagnosis";
  f.height_px = options.height_px;
  f.script = loglog_preamble(title, "Allan deviation σ(τ) (°/h)", x0, x1, y0, y1, plot.elements);
  f.script += blocks + plot.text();
  f.series = static_cast<int>(plot.elements.size());
  return f;
}

// ---- the public entry points -----------------------------------------------------------------

PlotResult plot_analysis(const json& analysis, const PlotOptions& options) {
  PlotResult r;
  write_outputs({analysis_figure(analysis, options)}, options, r);
  return r;
}

PlotResult plot_batch(const json& batch, const PlotOptions& options) {
  const auto& runs = batch.is_array() ? batch : child(batch, "runs");
  if (!runs.is_array() || runs.empty())
    throw AnalysisError("the batch has no runs (\"runs\": [analysis objects]): nothing to plot");
  PlotResult r;
  std::vector<Figure> figures{batch_allan_figure(runs, options)};
  auto direct = batch_direct_figure(runs, options);
  if (direct.series > 0)
    figures.push_back(std::move(direct));
  else
    r.notes.emplace_back(
        "no run carries the direct-method curve (methods.N_direct_deg_per_sqrt_h.curve): "
        "the angle-variance panel (Fig. 2) is left out");
  write_outputs(figures, options, r);
  return r;
}

PlotResult plot_diagnosis(const json& diagnosis, const PlotOptions& options) {
  PlotResult r;
  if (!band_of(diagnosis, true).is_array() || band_of(diagnosis, true).empty())
    r.notes.emplace_back(
        "the diagnosis has no extended model band (band_extended or extended_model.band): only the base model is "
        "drawn");
  write_outputs({diagnosis_figure(diagnosis, options)}, options, r);
  return r;
}

}  // namespace rwcalc
