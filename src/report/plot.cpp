// The figures: gnuplot scripts generated from the analysis, batch and diagnosis results as the
// report shows them (shown_results.hpp); the public calls read the JSON into those first.
#include "rwcalc/plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/quantity_text.hpp"
#include "rwcalc/units.hpp"
#include "shown_figures.hpp"

namespace rwcalc {

using nlohmann::json;
namespace lbl = units::label;

namespace {

/// A fitted coefficient as the figure draws it. When not resolved, `value` is the 95 % upper
/// bound; `model` is what the fitted model curve uses: `model_value` (0 for a term left out), or from
/// results saved without it the estimate.
struct Drawn {
  std::optional<double> value, high95;
  double model = 0;
  bool resolved = false;
};

Drawn drawn(const shown::CoefficientValues& c) {
  Drawn r{c.value, c.high95};
  r.resolved = c.resolved.value_or(r.value.has_value());
  if (c.in_model && !*c.in_model)
    r.model = 0;
  else if (c.model_value)
    r.model = *c.model_value;
  else if (c.estimate)
    r.model = *c.estimate;
  else
    r.model = r.resolved ? r.value.value_or(0.0) : 0.0;
  return r;
}

struct AllanRow {
  double tau = 0, dev = 0, low = 0, high = 0;
};

/// The usable Allan points (τ > 0, σ > 0) by τ; bounds default to σ (a zero lower bound cannot
/// be drawn on a log axis).
std::vector<AllanRow> allan_rows(const shown::Allan& allan) {
  std::vector<AllanRow> rows;
  for (const auto& p : allan.points) {
    const auto tau = p.tau_s, dev = p.dev;
    if (!tau || !dev || *tau <= 0 || *dev <= 0) continue;
    AllanRow r{*tau, *dev, p.dev_low.value_or(*dev), p.dev_high.value_or(*dev)};
    if (r.low <= 0) r.low = r.dev;
    rows.push_back(r);
  }
  std::sort(rows.begin(), rows.end(), [](const AllanRow& a, const AllanRow& b) { return a.tau < b.tau; });
  return rows;
}

/// A number for display: 4 significant digits, a power of ten written out (never e-notation).
std::string show(double v) { return number_text(v, 4); }

/// A title, label or key entry as a gnuplot string, in the chosen language's number style.
std::string label_text(std::string_view text) { return gnuplot_string(localize_numbers(std::string(text))); }

/// The data range of a log-log figure, widened to whole decades so the 10^n ticks frame it.
struct Bounds {
  double xlo = std::numeric_limits<double>::infinity(), xhi = 0;
  double ylo = std::numeric_limits<double>::infinity(), yhi = 0;
  void x(double v) { xlo = std::min(xlo, v), xhi = std::max(xhi, v); }
  void y(double lo, double hi) { ylo = std::min(ylo, lo), yhi = std::max(yhi, hi); }
  static std::pair<double, double> decades(double lo, double hi) {
    const double a = std::pow(10.0, std::floor(std::log10(lo)));
    const double b = std::pow(10.0, std::ceil(std::log10(hi)));
    return {a, b <= a ? a * 10 : b};
  }
};

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

/// UTF-8 code points of the longest key title among the plot elements (" t '…'").
std::size_t longest_title(const std::vector<std::string>& elements) {
  std::size_t longest = 0;
  for (const auto& e : elements) {
    const auto p = e.rfind(" t '");
    if (p == std::string::npos) continue;
    const auto n = std::count_if(e.begin() + static_cast<std::ptrdiff_t>(p + 4), e.end(),
                                 [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; });
    longest = std::max(longest, static_cast<std::size_t>(n));
  }
  return longest;
}

/// The look of every log-log figure. The key goes below the plot area, in two columns (one when
/// the labels are long), so it never hides data.
std::string loglog_preamble(const std::string& title, const std::string& ylabel, const Bounds& b,
                            const std::vector<std::string>& elements) {
  const auto [x0, x1] = Bounds::decades(b.xlo, b.xhi);
  const auto [y0, y1] = Bounds::decades(b.ylo, b.yhi);
  const std::size_t columns = longest_title(elements) > 52 ? 1 : 2;
  const std::size_t rows = std::max<std::size_t>(1, (elements.size() + columns - 1) / columns);
  return fmt::format(
      "set encoding utf8\nset title {} noenhanced\nset logscale xy 10\n"
      "set format x '10^{{%L}}'\nset format y '10^{{%L}}'\n"
      "set xtics nomirror\nset ytics nomirror\nset mxtics 10\nset mytics 10\n"
      "set grid xtics ytics mxtics mytics lw 0.6 lc rgb '#d9d9d9', lw 0.4 lc rgb '#eeeeee'\n"
      "set border 3 lw 1\nset xlabel {} noenhanced offset 0,0.7\nset ylabel {} noenhanced\n"
      "set xrange [{:.6g}:{:.6g}]\nset yrange [{:.6g}:{:.6g}]\n"
      "set key outside below center vertical maxrows {} Left reverse noenhanced samplen 2.5 "
      "spacing 1.05 width 2 height 1 nobox\nset samples 250\n",
      label_text(title), label_text(tr("τ (s)")), label_text(ylabel), x0, x1, y0, y1, rows);
}

Figure loglog_figure(const char* name, const PlotOptions& options, const std::string& title, const std::string& ylabel,
                     const Bounds& b, const std::string& body, const PlotCommand& plot) {
  Figure f;
  f.name = name;
  f.height_px = options.height_px;
  f.script = loglog_preamble(title, ylabel, b, plot.elements) + body + plot.text();
  f.series = static_cast<int>(plot.elements.size());
  return f;
}

bool is_gyro(const shown::Allan& allan) { return allan.unit.empty() || allan.unit == "deg/h"; }

std::string allan_ylabel(const shown::Allan& allan) {
  const auto& unit = allan.unit;
  if (is_gyro(allan)) return trf("Allan deviation σ(τ) ({})", tr(lbl::rate));
  if (unit == "1") return tr("Allan deviation σ(τ)");
  return trf("Allan deviation σ(τ) ({})", unit);
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

struct TermLine {
  shown::Term term;
  const char *var, *fn, *label, *unit, *colour;  // gnuplot variable and function
};
constexpr std::array<TermLine, 5> kTermLines{{
    {shown::Term::Q, "Q", "sQ", N_("quantization Q"), lbl::angle, "#7b3294"},
    {shown::Term::N, "N", "sN", N_("angle random walk N"), lbl::arw, "#1f77b4"},
    {shown::Term::B, "B", "sB", N_("bias instability B"), lbl::rate, "#2ca02c"},
    {shown::Term::K, "K", "sK", N_("rate random walk K"), lbl::rrw, "#ff7f0e"},
    {shown::Term::R, "R", "sR", N_("rate ramp R"), lbl::ramp, "#8c564b"},
}};

void append_allan_block(std::string& s, const std::string& name, const std::vector<AllanRow>& rows) {
  s += fmt::format("${} << EOD\n# tau_s dev dev_low dev_high\n", name);
  for (const auto& r : rows) s += fmt::format("{:.10g} {:.10g} {:.10g} {:.10g}\n", r.tau, r.dev, r.low, r.high);
  s += "EOD\n";
}

/// The fitted model and each term's line; an unresolved term is only bounded: its bound, dashed.
void add_model(const shown::Fit& fit, std::string& vars, PlotCommand& plot) {
  vars += "# Coefficients of the fitted model (0 for a term the fit left out):\n";
  std::string model = "model(t) = sqrt(0";
  std::vector<std::string> term_lines;
  for (const auto& t : kTermLines) {
    const auto c = drawn(fit[t.term]);
    vars += fmt::format("{} = {:.8g}   # {}\n", t.var, c.model, t.unit);
    model += fmt::format(" + {}(t, {})**2", t.fn, t.var);
    const double v = c.value.value_or(0.0);
    if (c.resolved && v > 0) {
      term_lines.push_back(fmt::format("{}(x, {}) w l lw 1.4 lc rgb '{}' t {}", t.fn, t.var, t.colour,
                                       label_text(fmt::format("{} = {} {}", tr(t.label), show(v), tr(t.unit)))));
    } else if (const double bound = c.high95.value_or(v); !c.resolved && bound > 0) {
      vars += fmt::format("{}_up95 = {:.8g}   # {}, 95 % upper bound\n", t.var, bound, t.unit);
      term_lines.push_back(
          fmt::format("{}(x, {}_up95) w l lw 1.2 dt 3 lc rgb '{}' t {}", t.fn, t.var, t.colour,
                      label_text(fmt::format("{} < {} {} (95 %)", tr(t.label), show(bound), tr(t.unit)))));
    }
  }
  vars += model + ")\n";
  const auto chi2 = fit.chi2_per_dof;
  plot.add(fmt::format("model(x) w l lw 2.2 lc rgb '#000000' t {}",
                       label_text(chi2 ? trf("fitted model (χ²/dof = {:.3g})", *chi2) : tr("fitted model"))));
  for (auto& l : term_lines) plot.add(std::move(l));
}

/// The term functions and the class-limit floor lines 0.6643·B_limit, which the y range includes.
void add_class_floors(const shown::Analysis& analysis, std::string& vars, PlotCommand& plot, Bounds& bounds) {
  static constexpr std::array<const char*, 3> kDash{"2", "4", "5"};  // dots (3) mark upper bounds
  const auto t = analysis.verdict.tolerance_pct;
  const std::string tolerance = t && *t > 0 ? trf(" (+{:g} % tolerance)", *t) : std::string();
  std::size_t i = 0;
  for (const auto& [cls, b] : shown::class_limits(analysis.verdict, 'B')) {
    vars += fmt::format("B_class{} = {:.6g}   # {}, class {} limit for B\n", cls, b, lbl::rate, cls);
    plot.add(fmt::format("sB(x, B_class{0}) w l lw 1.3 dt {1} lc rgb '#d62728' t {2}", cls, kDash[i++ % kDash.size()],
                         label_text(trf("class {0} limit B = {1} {2}{3} (floor {4} {2})", cls, show(b), tr(lbl::rate),
                                        tolerance, show(kFloorPerB * b)))));
    bounds.y(kFloorPerB * b, 0);
  }
}

/// What names a run in a title or a key, as typed: the file name of its source.
std::string run_name(const shown::Analysis& a) {
  const std::string& src = a.source;
  return src.empty() ? src : as_typed(std::filesystem::path(src).filename().string());
}

/// What names an IMU axis in a key, as typed: its column as named (a column name is no path:
/// "accel/x" keeps its '/'), else its run's name.
std::string axis_name(const shown::Analysis& a) {
  if (!a.column.empty()) return as_typed(a.column);
  return run_name(a);
}

std::string default_analysis_title(const shown::Analysis& a) {
  std::string t = tr("Allan deviation");
  // A gyro in its usual units is a run of the batch, named by its file; any other channel by its column.
  const bool usual = a.rate_unit.empty() || a.rate_unit == "deg/h";
  if (const auto src = usual ? run_name(a) : axis_name(a); !src.empty()) t += trf(" of {}", src);
  if (const auto temp = shown::temperature_label(a.temperature_c); !temp.empty()) t += trf(" at {}", temp);
  return t;
}

std::string run_label(const shown::Analysis& run, std::size_t index) {
  const auto t = shown::temperature_label(run.temperature_c);
  const auto src = run_name(run);
  if (!t.empty()) return src.empty() ? t : fmt::format("{} ({})", t, src);
  return src.empty() ? trf("run {}", index + 1) : src;
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
    write_file_atomic(options.script, full_script(figures, format.value_or(PlotFormat::Svg), options.width_px, target),
                      options.force);
  }
  if (format) write_file_atomic(options.output, render_figures(figures, *format, options.width_px), options.force);
}

constexpr std::array<int, 8> kPointTypes{7, 5, 9, 11, 13, 15, 4, 6};

}  // namespace

std::string temperature_colour(const json& temperature_c, std::size_t index) {
  return shown::temperature_colour(shown::read_temperature(temperature_c), index);
}

std::string shown::temperature_colour(std::optional<double> temp, std::size_t index) {
  if (temp) {
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
    const double t = std::clamp(*temp, kScale.front().t, kScale.back().t);
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

Figure analysis_figure(const json& analysis, const PlotOptions& options) {
  return shown::analysis_figure(shown::read_analysis(analysis), options);
}

Figure shown::analysis_figure(const Analysis& analysis, const PlotOptions& options) {
  const auto& allan = analysis.allan;
  const auto rows = allan_rows(allan);
  if (rows.empty())
    throw AnalysisError(
        "the analysis has no Allan deviation points (allan.points with tau_s and dev): "
        "nothing to plot");
  Bounds bounds;
  for (const auto& r : rows) bounds.x(r.tau), bounds.y(r.low, r.high);
  std::string body;
  append_allan_block(body, "allan", rows);
  PlotCommand plot;
  const auto conf = allan.confidence;
  plot.add(fmt::format("$allan u 1:2:3:4 w yerrorbars pt 7 ps 0.55 lw 1.2 lc rgb '#222222' t {}",
                       label_text(conf ? trf("measured σ(τ), {:g} % bounds", *conf * 100) : tr("measured σ(τ)"))));
  if (is_gyro(allan)) {
    body += kTermFunctions;
    if (analysis.fit.present) add_model(analysis.fit, body, plot);
    add_class_floors(analysis, body, plot, bounds);
  }
  return loglog_figure("allan", options,
                       options.title.empty() ? default_analysis_title(analysis) : as_typed(options.title),
                       allan_ylabel(allan), bounds, body, plot);
}

Figure batch_allan_figure(const json& runs, const PlotOptions& options) {
  return shown::batch_allan_figure(shown::read_runs(runs), options);
}

Figure shown::batch_allan_figure(const std::vector<Analysis>& runs, const PlotOptions& options) {
  const auto order = by_temperature(runs);
  std::string blocks;
  PlotCommand plot;
  Bounds bounds;
  bool gyro = true;
  std::string ylabel = trf("Allan deviation σ(τ) ({})", tr(lbl::rate));
  for (std::size_t i = 0; i < order.size(); ++i) {
    const auto& run = runs[order[i]];
    const auto rows = allan_rows(run.allan);
    if (rows.empty()) continue;
    gyro = gyro && is_gyro(run.allan);
    ylabel = allan_ylabel(run.allan);
    const auto name = fmt::format("run{}", i + 1);
    append_allan_block(blocks, name, rows);
    for (const auto& r : rows) bounds.x(r.tau), bounds.y(r.low, r.high);
    plot.add(fmt::format("${} u 1:2:3:4 w yerrorlines pt {} ps 0.6 lw 1.4 lc rgb '{}' t {}", name,
                         kPointTypes[i % kPointTypes.size()], temperature_colour(run.temperature_c, i),
                         label_text(run_label(run, i))));
  }
  if (plot.elements.empty())
    throw AnalysisError(tr("no run of the batch has Allan deviation points (runs[].allan.points): nothing to plot"));
  if (gyro) {
    blocks += kTermFunctions;
    add_class_floors(runs[order.front()], blocks, plot, bounds);
  }
  return loglog_figure("batch-allan", options,
                       options.title.empty() ? tr("Allan deviation at each test temperature") : as_typed(options.title),
                       ylabel, bounds, blocks, plot);
}

Figure batch_direct_figure(const json& runs, const PlotOptions& options) {
  return shown::batch_direct_figure(shown::read_runs(runs), options);
}

Figure shown::batch_direct_figure(const std::vector<Analysis>& runs, const PlotOptions& options) {
  const auto order = by_temperature(runs);
  Figure f;
  f.name = "batch-direct";
  f.height_px = options.height_px;
  std::string blocks, vars;
  PlotCommand plot;
  double tmax = 0, vmax = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const auto& run = runs[order[i]];
    const auto& direct = run.n_direct;
    if (direct.curve.empty()) continue;  // the curve's points with both values
    const auto name = fmt::format("direct{}", i + 1);
    blocks += fmt::format("${} << EOD\n# t_s var_arcsec2\n", name);
    double run_tmax = 0;
    for (const auto& [t, v] : direct.curve) {
      blocks += fmt::format("{:.10g} {:.10g}\n", t, v);
      vmax = std::max(vmax, v);
      run_tmax = std::max(run_tmax, t);
    }
    blocks += "EOD\n";
    tmax = std::max(tmax, run_tmax);
    const auto colour = temperature_colour(run.temperature_c, i);
    const auto n_val = direct.value;
    const bool n_resolved = direct.resolved.value_or(true);
    auto slope = direct.slope;
    // Without a stated slope it follows from N: the angle variance of ARW is a + (60·N)²·t.
    if (!slope && n_val && n_resolved) slope = std::pow(60 * *n_val, 2);
    const auto intercept = direct.intercept;
    // One key entry per run: the points carry the label, the line shares their colour.
    std::string label = run_label(run, i);
    if (n_val) label += fmt::format(": N {} {} {}", n_resolved ? "=" : "<", show(*n_val), tr(lbl::arw));
    plot.add(fmt::format("${} u 1:2 w p pt {} ps 0.8 lc rgb '{}' t {}", name, kPointTypes[i % kPointTypes.size()],
                         colour, label_text(label)));
    if (slope) {
      vars += fmt::format("slope{0} = {1:.8g}   # {3}/s\nintercept{0} = {2:.8g}   # {3}\n", i + 1, *slope,
                          intercept.value_or(0.0), lbl::angle2);
      plot.add(fmt::format("[0:{2:.6g}] intercept{0} + slope{0} * x w l lw 1.6 lc rgb '{1}' notitle", i + 1, colour,
                           run_tmax));
    }
  }
  if (plot.elements.empty()) return f;
  const std::string title =
      options.title.empty()
          ? tr("Direct method: variance of the angle over t (Earth rate removed), with regression lines")
          : as_typed(options.title) + tr(" — direct method");
  // The variance grows with t, so the upper-left corner is empty: the key goes there.
  f.script = fmt::format(
      "set encoding utf8\nset title {} noenhanced\n"
      "set xtics nomirror\nset ytics nomirror\nset mxtics\nset mytics\n"
      "set grid xtics ytics lw 0.6 lc rgb '#d9d9d9'\nset border 3 lw 1\n"
      "set xlabel {} noenhanced\nset ylabel {} noenhanced\n{}"
      "set xrange [0:{:.6g}]\nset yrange [0:{:.6g}]\n"
      "set key inside left top vertical Left reverse noenhanced samplen 2.5 spacing 1.1 opaque "
      "box lc rgb '#bbbbbb'\n",
      label_text(title), label_text(tr("interval length t (s)")),
      label_text(trf("angle variance D(t) ({})", tr(lbl::angle2))),
      language() == Language::Russian ? "set decimalsign ','\n" : "", tmax * 1.02, vmax * 1.25);
  f.script += blocks + vars + plot.text();
  f.series = static_cast<int>(plot.elements.size());
  return f;
}

namespace {

struct BandRow {
  double tau = 0, dev = 0, low = 0, high = 0;
  double median = 0;  ///< the ensemble's median σ (0 when not given)
};

std::vector<BandRow> band_rows(const std::optional<std::vector<shown::BandPoint>>& band) {
  std::vector<BandRow> rows;
  if (!band) return rows;
  for (const auto& p : *band) {
    const auto tau = p.tau_s, lo = p.band_low, hi = p.band_high;
    if (!tau || !lo || !hi || *tau <= 0 || *lo <= 0 || *hi <= 0) continue;
    rows.push_back({*tau, p.dev.value_or(0.0), *lo, *hi, p.median.value_or(0.0)});
  }
  std::sort(rows.begin(), rows.end(), [](const BandRow& a, const BandRow& b) { return a.tau < b.tau; });
  return rows;
}

/// °/h, or the unit the diagnosis names for its band (an accelerometer's: "units": {"band": "ug"}).
std::string diagnosis_ylabel(const shown::Diagnosis& diagnosis) {
  if (!diagnosis.band_unit) return trf("Allan deviation σ(τ) ({})", tr(lbl::rate));
  return trf("Allan deviation σ(τ) ({})", unit_text(*diagnosis.band_unit));
}

std::string band_label(const char* what, std::optional<double> level, const std::vector<BandRow>& rows) {
  int inside = 0, measured = 0;
  for (const auto& r : rows) {
    if (r.dev <= 0) continue;
    ++measured;
    inside += (r.dev >= r.low && r.dev <= r.high) ? 1 : 0;
  }
  const std::string percent = level ? fmt::format("{:g} % ", *level * 100) : std::string();
  std::string s =
      std::string_view(what) == "base" ? trf("base model: {}band", percent) : trf("extended model: {}band", percent);
  if (measured > 0) s += trf(", {} of {} τ inside", inside, measured);
  return s;
}

std::string diagnosis_title(const shown::Diagnosis& diagnosis) {
  std::vector<std::string> effects;
  for (const auto& f : diagnosis.findings)
    if (!f.effect.empty()) effects.push_back(f.effect);
  return tr("Measurement against the noise model's band") +
         (effects.empty() ? std::string(tr(" (no finding)")) : trf(" (findings: {})", fmt::join(effects, ", ")));
}

}  // namespace

Figure diagnosis_figure(const json& diagnosis, const PlotOptions& options) {
  return shown::diagnosis_figure(shown::read_diagnosis(diagnosis), options);
}

Figure shown::diagnosis_figure(const Diagnosis& diagnosis, const PlotOptions& options) {
  const auto base = band_rows(diagnosis.band);
  const auto ext = band_rows(diagnosis.band_extended);
  if (base.empty())
    throw AnalysisError(
        "the diagnosis has no band (band or base_model.band, with tau_s, band_low, "
        "band_high): nothing to plot");
  std::string blocks;
  PlotCommand plot;
  Bounds bounds;
  auto add_band = [&](const char* name, const std::vector<BandRow>& rows) {
    blocks += fmt::format("${} << EOD\n# tau_s dev band_low band_high median\n", name);
    for (const auto& r : rows) {
      blocks += fmt::format("{:.10g} {:.10g} {:.10g} {:.10g} {:.10g}\n", r.tau, r.dev, r.low, r.high, r.median);
      bounds.x(r.tau);
      bounds.y(std::min(r.low, r.dev > 0 ? r.dev : r.low), std::max(r.high, r.dev));
    }
    blocks += "EOD\n";
  };
  add_band("base", base);
  plot.add(fmt::format("$base u 1:3:4 w filledcurves fs transparent solid 0.30 noborder lc rgb '#1f77b4' t {}",
                       label_text(band_label("base", diagnosis.band_level, base))));
  if (std::all_of(base.begin(), base.end(), [](const BandRow& r) { return r.median > 0; }))
    plot.add("$base u 1:5 w l lw 1.2 dt 2 lc rgb '#1f77b4' t " + label_text(tr("base model: median")));
  if (!ext.empty()) {
    add_band("extended", ext);
    plot.add(fmt::format(
        "$extended u 1:3:4 w filledcurves fs transparent pattern 5 border lc rgb '#e6550d' lc rgb '#e6550d' t {}",
        label_text(band_label("extended", diagnosis.band_level_extended, ext))));
  }
  // The τ where the measurement leaves the base band are marked so that they stand out.
  std::string outside;
  for (const auto& r : base)
    if (r.dev > 0 && (r.dev < r.low || r.dev > r.high)) outside += fmt::format("{:.10g} {:.10g}\n", r.tau, r.dev);
  plot.add("$base u 1:($2 > 0 ? $2 : NaN) w lp pt 7 ps 0.6 lw 1.4 lc rgb '#000000' t " +
           label_text(tr("measured σ(τ)")));
  if (!outside.empty()) {
    blocks += "$outside << EOD\n# tau_s dev (outside the base band)\n" + outside + "EOD\n";
    plot.add("$outside u 1:2 w p pt 6 ps 1.6 lw 1.6 lc rgb '#d62728' t " +
             label_text(tr("measured, outside the base band")));
  }
  return loglog_figure("diagnosis", options,
                       options.title.empty() ? diagnosis_title(diagnosis) : as_typed(options.title),
                       diagnosis_ylabel(diagnosis), bounds, blocks, plot);
}

PlotResult plot_analysis(const json& analysis, const PlotOptions& options) {
  require_valid(options);
  PlotResult r;
  write_outputs({shown::analysis_figure(shown::read_analysis(analysis), options)}, options, r);
  return r;
}

PlotResult plot_batch(const json& batch, const PlotOptions& options) {
  require_valid(options);
  const auto runs = shown::read_runs(shown::batch_runs(batch));
  if (runs.empty()) throw AnalysisError(tr("the batch has no runs (\"runs\": [analysis objects]): nothing to plot"));
  PlotResult r;
  std::vector<Figure> figures{shown::batch_allan_figure(runs, options)};
  if (auto direct = shown::batch_direct_figure(runs, options); direct.series > 0)
    figures.push_back(std::move(direct));
  else
    r.notes.emplace_back(
        tr("no run carries the direct-method curve (methods.N_direct.curve): "
           "the angle-variance panel (Fig. 2) is left out"));
  write_outputs(figures, options, r);
  return r;
}

PlotResult plot_diagnosis(const json& diagnosis, const PlotOptions& options) {
  require_valid(options);
  PlotResult r;
  const auto d = shown::read_diagnosis(diagnosis);
  if (!d.band_extended || d.band_extended->empty())
    r.notes.emplace_back(
        tr("the diagnosis has no extended model band (band_extended or extended_model.band): only the base model "
           "is drawn"));
  write_outputs({shown::diagnosis_figure(d, options)}, options, r);
  return r;
}

namespace {

/// The fitted model of an IMU axis as a gnuplot function `fn(t)` of τ (s) giving σ in the axis'
/// shown unit: the IEEE 952 sum over the SI coefficients (fit.X.si; a term left out is 0) times
/// allan.unit_per_si (the axis' unit per SI unit). Empty without SI coefficients or the factor.
std::string imu_model_function(const shown::Analysis& channel, const std::string& fn) {
  const auto factor = channel.allan.unit_per_si;
  const auto& fit = channel.fit;
  if (!factor || !fit.present) return {};
  std::array<double, 5> c{};
  for (std::size_t k = 0; k < fit.terms.size(); ++k) {
    if (!fit.terms[k].si) return {};
    c[k] = drawn(*fit.terms[k].si).model;
  }
  return fmt::format(
      "{0}(t) = {1:.10g} * sqrt(3 * {2:.10g}**2 / t**2 + {3:.10g}**2 / t + 2 * log(2) / pi * {4:.10g}**2"
      " + {5:.10g}**2 * t / 3 + {6:.10g}**2 * t**2 / 2)\n",
      fn, *factor, c[0], c[1], c[2], c[3], c[4]);
}

}  // namespace

Figure imu_axes_figure(const json& channels, const PlotOptions& options) {
  return shown::imu_axes_figure(shown::read_runs(channels), options);
}

Figure shown::imu_axes_figure(const std::vector<Analysis>& channels, const PlotOptions& options) {
  std::string body = "# Each axis' fitted model: sigma in the axis' unit from its SI coefficients (Q, N, B, K, R)\n";
  PlotCommand plot;
  Bounds bounds;
  std::string ylabel;
  std::size_t i = 0;
  for (const auto& c : channels) {
    const auto rows = allan_rows(c.allan);
    if (rows.empty()) continue;
    ylabel = allan_ylabel(c.allan);
    const std::string colour = temperature_colour(std::nullopt, i);
    const auto name = fmt::format("axis{}", i + 1);
    append_allan_block(body, name, rows);
    for (const auto& r : rows) bounds.x(r.tau), bounds.y(r.low, r.high);
    plot.add(fmt::format("${} u 1:2:3:4 w yerrorbars pt {} ps 0.6 lw 1.2 lc rgb '{}' t {}", name,
                         kPointTypes[i % kPointTypes.size()], colour, label_text(axis_name(c))));
    if (const auto fn = std::string("model_") + name, model = imu_model_function(c, fn); !model.empty()) {
      body += model;
      const auto chi2 = c.fit.chi2_per_dof;
      plot.add(fmt::format("{}(x) w l lw 1.6 lc rgb '{}' t {}", fn, colour,
                           label_text(chi2 ? trf("{}: fitted model (χ²/dof = {:.3g})", axis_name(c), *chi2)
                                           : trf("{}: fitted model", axis_name(c)))));
    }
    ++i;
  }
  if (plot.elements.empty())
    throw AnalysisError(tr("no axis of the IMU has Allan deviation points (channels[].allan.points): nothing to plot"));
  return loglog_figure("imu", options, as_typed(options.title), ylabel, bounds, body, plot);
}

}  // namespace rwcalc
