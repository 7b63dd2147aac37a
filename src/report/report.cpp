// The HTML test report: tables from the analysis JSON, figures by gnuplot, all in one file.
#include "rwcalc/report.hpp"
#include "rwcalc/version.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <optional>

#include "report/json_view.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/printable.hpp"

namespace rwcalc {

using nlohmann::json;

std::string base64_encode(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

namespace {

using view::at;
using view::num;
using view::str;
namespace lbl = units::label;

/// Text for HTML, in element content and in quoted attribute values alike: the markup
/// characters as entities, and (by printable()) control characters and bytes that are not UTF-8
/// spelled out. Every string from outside goes through here.
std::string esc(std::string_view text) {
  std::string r;
  for (char c : printable(text)) {
    switch (c) {
      case '&': r += "&amp;"; break;
      case '<': r += "&lt;"; break;
      case '>': r += "&gt;"; break;
      case '"': r += "&quot;"; break;
      case '\'': r += "&#39;"; break;
      default: r += c;
    }
  }
  return r;
}

std::string g(double v, int digits = 3) { return fmt::format("{:.{}g}", v, digits); }

constexpr const char* kNotAvailable = "<span class=\"na\">—</span>";

/// A coefficient cell: "value ± σ" with the 95 % interval below, or "< bound" when unresolved.
std::string coef_cell(const json& c) {
  const auto v = num(c, "value");
  if (!v) return kNotAvailable;
  const auto& resolved = at(c, "resolved");
  if (resolved.is_boolean() && !resolved.get<bool>())
    return fmt::format("&lt; {} <span class=\"ci\">95 % upper bound</span>", g(*v));
  std::string s = g(*v);
  if (const auto sigma = num(c, "sigma"); sigma && *sigma > 0) s += fmt::format(" ± {}", g(*sigma, 2));
  const auto lo = num(c, "low95"), hi = num(c, "high95");
  if (lo && hi) s += fmt::format(" <span class=\"ci\">[{}, {}]</span>", g(*lo), g(*hi));
  return s;
}

std::string temperature_text(const json& run) {
  const auto t = view::temperature_label(at(run, "temperature_c"));
  return t.empty() ? "not given" : t;
}

std::string class_text(const json& c) {
  if (c.is_number_integer()) return fmt::format("{}", c.get<int>());
  if (c.is_null()) return "outside";
  return kNotAvailable;
}

/// The verdict's statement, else its class (plain text).
std::string statement_text(const json& v) {
  const auto st = str(v, "statement");
  return st.empty() ? "class " + class_text(at(v, "class")) : st;
}

/// "; by B: …; by N: …" from two statements, each left out when absent.
std::string by_parameter(const std::string& b, const std::string& n) {
  return (b.empty() ? "" : "; by B: " + esc(b)) + (n.empty() ? "" : "; by N: " + esc(n));
}

std::string source_name(const json& a) {
  const auto s = str(a, "source");
  return s.empty() ? std::string("(unnamed run)") : std::filesystem::path(s).filename().string();
}

/// The class an estimate's reported value falls in (no probability): for the cross-check methods.
std::string class_by_value(const json& estimate, const json& run, const char* parameter) {
  const auto v = num(estimate, "value");
  if (!v) return kNotAvailable;
  for (const auto& [cls, limit] : view::class_limits(run, parameter))
    if (*v <= limit) return fmt::format("{}", cls);
  return "outside";
}

/// Figures are numbered in the order they appear on the page.
struct Figures {
  bool enabled = true;
  int next = 1;
  std::string html(const std::string& id, const std::vector<Figure>& figures, const std::string& caption) {
    const auto svg = render_figures(figures, PlotFormat::Svg, 960);
    return fmt::format(
        "<figure id=\"{0}\">\n<img alt=\"{1}\" src=\"data:image/svg+xml;base64,{2}\"/>\n"
        "<figcaption><b>Fig. {3}.</b> {1}</figcaption>\n</figure>\n",
        id, esc(caption), base64_encode(svg), next++);
  }
};

constexpr const char* kStyle = R"(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; font-size: 14px; color: #222;
       max-width: 1100px; margin: 1.5em auto; padding: 0 1em; line-height: 1.4; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.25em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
h3 { font-size: 1.05em; margin-top: 1.2em; }
.meta { color: #555; }
table { border-collapse: collapse; margin: 0.6em 0 1em; font-size: 0.95em; }
th, td { border: 1px solid #bbb; padding: 0.3em 0.6em; text-align: left; vertical-align: top;
         overflow-wrap: break-word; }
th { background: #f0f0f0; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
caption { caption-side: top; text-align: left; font-weight: bold; padding-bottom: 0.3em; }
.ci { display: block; color: #666; font-size: 0.85em; }
.na { color: #999; }
.verdict { font-size: 1.15em; padding: 0.6em 0.9em; border-left: 5px solid #2c7bb6; background: #f4f8fb; }
.note { color: #7a4b00; background: #fff6e0; padding: 0.3em 0.6em; border-left: 4px solid #e6a000; }
.warning { color: #7a0000; background: #fff0f0; padding: 0.3em 0.6em; border-left: 4px solid #c00000; }
figure { margin: 1em 0; }
figure img { width: 100%; max-width: 960px; height: auto; border: 1px solid #eee; }
figcaption { color: #444; font-size: 0.92em; }
footer { margin-top: 2em; color: #777; font-size: 0.85em; border-top: 1px solid #ddd; padding-top: 0.5em; }
@media print {
  body { max-width: none; margin: 0; font-size: 11px; }
  h2 { page-break-after: avoid; }
  table, figure, .verdict { page-break-inside: avoid; }
  figure img { max-width: 100%; border: none; }
  a { color: inherit; text-decoration: none; }
}
)";

/// Worst (highest) class over runs; null when any run is outside the table or unclassified.
json worst_class(const std::vector<json>& analyses, const char* key) {
  int worst = 0;
  for (const auto& a : analyses) {
    const auto& c = at(at(a, "verdict"), key);
    if (!c.is_number_integer()) return nullptr;
    worst = std::max(worst, c.get<int>());
  }
  return worst > 0 ? json(worst) : json(nullptr);
}

/// A table row: the run and its temperature, then the cells (class="num"; bold when asked).
std::string run_row(const json& run, const std::vector<std::string>& cells, std::string_view tail = "") {
  std::string s = fmt::format("<tr><td>{}</td><td class=\"num\">{}</td>", esc(source_name(run)), temperature_text(run));
  for (const auto& c : cells) s += fmt::format("<td class=\"num\">{}</td>", c);
  return s + std::string(tail) + "</tr>\n";
}

std::string table1(const std::vector<json>& a, const std::vector<std::size_t>& order) {
  std::string s = fmt::format(
      "<table id=\"table1\">\n<caption>Table 1. Noise coefficients per temperature: value ± standard error "
      "[95 % interval]</caption>\n<tr><th>run</th><th>temperature</th><th>N by Allan variance ({0})</th>"
      "<th>N direct method ({0})</th><th>B by Allan variance ({1})</th><th>B by 100-s averaging ({1})</th></tr>\n",
      lbl::arw, lbl::rate);
  for (auto i : order) {
    const auto& fit = at(a[i], "fit");
    const auto& methods = at(a[i], "methods");
    s += run_row(a[i], {coef_cell(at(fit, "N_deg_per_sqrt_h")), coef_cell(at(methods, "N_direct_deg_per_sqrt_h")),
                        coef_cell(at(fit, "B_deg_per_h")), coef_cell(at(methods, "B_100s_deg_per_h"))});
  }
  return s + "</table>\n";
}

std::string table2(const std::vector<json>& a, const std::vector<std::size_t>& order, const json& overall) {
  std::string s =
      "<table id=\"table2\">\n<caption>Table 2. Accuracy class per parameter (1 best; “outside”: beyond the "
      "last class)</caption>\n<tr><th>run</th><th>temperature</th><th>class by N (AV)</th>"
      "<th>class by N direct</th><th>class by B (verdict estimate)</th><th>class by B 100-s</th>"
      "<th>class</th><th>verdict with probability</th></tr>\n";
  for (auto i : order) {
    const auto& run = a[i];
    const auto& v = at(run, "verdict");
    const auto& methods = at(run, "methods");
    std::string statement = esc(str(v, "statement"));
    if (statement.empty()) {
      const auto p = num(v, "p_class");
      statement = p ? fmt::format("class {} (P = {:.2f})", class_text(at(v, "class")), *p) : kNotAvailable;
    }
    if (const auto& changed = at(v, "tolerance_changed"); changed.is_boolean() && changed.get<bool>())
      statement += fmt::format(" <span class=\"note\">changed by the +{:g} % B tolerance</span>",
                               num(v, "tolerance_pct").value_or(0.0));
    s += run_row(run,
                 {class_text(at(v, "class_N")), class_by_value(at(methods, "N_direct_deg_per_sqrt_h"), run, "N"),
                  class_text(at(v, "class_B")), class_by_value(at(methods, "B_100s_deg_per_h"), run, "B"),
                  "<b>" + class_text(at(v, "class")) + "</b>"},
                 "<td>" + statement + "</td>");
  }
  s += fmt::format(
      "<tr><th colspan=\"2\">over the temperature range</th><td class=\"num\"><b>{}</b></td><td></td>"
      "<td class=\"num\"><b>{}</b></td><td></td><td class=\"num\"><b>{}</b></td><td>worst case over the "
      "runs</td></tr>\n",
      class_text(at(overall, "class_N")), class_text(at(overall, "class_B")), class_text(at(overall, "class")));
  return s +
         "</table>\n<p class=\"meta\">Classes by N direct and by B 100-s compare the reported value with the "
         "class limits only (no probability); the verdict uses the estimates named in the settings.</p>\n";
}

std::string kv_row(std::string_view key, const std::string& value_html) {
  return fmt::format("<tr><th>{}</th><td>{}</td></tr>\n", esc(key), value_html);
}

std::string json_value_html(const json& v) {
  if (v.is_string()) return esc(v.get<std::string>());
  if (v.is_number_float()) return g(v.get<double>(), 6);
  if (v.is_null()) return kNotAvailable;
  if (v.is_array()) {  // one item after another, so long lists wrap
    std::string s;
    for (const auto& e : v) s += (s.empty() ? "" : ", ") + json_value_html(e);
    return s;
  }
  // (replace: a file name that is not UTF-8 must not make the dump throw)
  return esc(v.dump(-1, ' ', false, json::error_handler_t::replace));
}

/// What was done with the outliers, in words.
std::string outlier_action_html(const json& outliers, std::size_t count) {
  const std::string action = str(outliers, "action");
  if (action == "keep") return "kept in the analysis (--outliers remove or replace leaves them out)";
  if (action == "remove")
    return fmt::format("{:.0f} removed before the analysis (later samples move one period earlier)",
                       num(outliers, "removed").value_or(static_cast<double>(count)));
  if (action == "replace")
    return fmt::format("{:.0f} replaced by the median of their nearest good neighbours before the analysis",
                       num(outliers, "replaced").value_or(static_cast<double>(count)));
  return "action " + (action.empty() ? std::string(kNotAvailable) : esc(action));
}

constexpr std::size_t kReportOutlierPositions = 10;  ///< positions listed per run (the JSON has more)

/// The outlier line of a run or a diagnosis: count, action and the first positions.
std::string outliers_html(const json& outliers) {
  if (!outliers.is_object()) return "<span class=\"na\">not in these results (no outlier summary)</span>";
  const auto count_value = num(outliers, "count");
  if (!count_value) return kNotAvailable;
  const auto count = static_cast<std::size_t>(*count_value);
  const auto z = num(outliers, "threshold_robust_z");
  const std::string threshold = z ? fmt::format(" (threshold {:g} robust σ)", *z) : std::string();
  if (count == 0) return "none found" + threshold;
  std::string s = fmt::format("<b>{} found</b>{}; {}", count, threshold, outlier_action_html(outliers, count));
  const auto& positions = at(outliers, "positions");
  std::size_t listed = 0;
  if (positions.is_array()) {
    for (const auto& p : positions) {
      if (listed == kReportOutlierPositions) break;
      const auto line = num(p, "line"), time = num(p, "time_s"), value = num(p, "value_deg_per_h");
      s += listed++ ? ", " : ": ";
      s += line ? fmt::format("line {:.0f}", *line) : std::string("line ") + kNotAvailable;
      if (time)
        s += fmt::format(" (t = {:g} s", *time) + (value ? fmt::format(", {:.6g} {})", *value, lbl::rate) : ")");
    }
  }
  if (count > listed) s += fmt::format("{}… {} more in the JSON results", listed ? ", " : ": ", count - listed);
  return s;
}

std::string data_table(const json& run, std::size_t index) {
  std::string s =
      fmt::format("<table class=\"run\" id=\"run{}-data\">\n<caption>Data and rates</caption>\n", index + 1);
  s += kv_row("file", esc(str(run, "source")));
  const json& input = at(run, "input");
  if (const json& id = at(input, "identification"); id.is_object())
    for (const auto& [key, label] : {std::pair{"serial", "gyro serial"}, std::pair{"operator", "operator"},
                                     std::pair{"test_date", "test date"}, std::pair{"conditions", "test conditions"}})
      if (const auto v = str(id, key); !v.empty()) s += kv_row(label, esc(v));
  if (const auto sha = str(input, "sha256"); !sha.empty())
    s += kv_row("file size, SHA-256", fmt::format("{:.0f} bytes, <code>{}</code>", num(input, "file_bytes").value_or(0),
                                                  esc(sha)));
  if (const auto n = num(run, "samples")) s += kv_row("samples", fmt::format("{:.0f}", *n));
  if (const auto r = num(run, "rate_hz")) s += kv_row("sample rate", fmt::format("{:g} Hz", *r));
  if (const auto d = num(run, "duration_s")) s += kv_row("duration", fmt::format("{:.1f} s ({:.2f} h)", *d, *d / 3600));
  s += kv_row("temperature", temperature_text(run));
  auto rate = [&](const char* key, const char* name, int digits) {
    if (const auto v = num(run, key)) s += kv_row(name, fmt::format("{} {}", g(*v, digits), lbl::rate));
  };
  rate("mean_rate_deg_per_h", "mean rate", 5);
  rate("earth_rate_deg_per_h", "expected Earth rate", 5);
  rate("bias_deg_per_h", "bias (mean − Earth rate)", 4);
  s += fmt::format("<tr id=\"run{}-outliers\"><th>outliers</th><td>{}</td></tr>\n", index + 1,
                   outliers_html(at(run, "outliers")));
  return s + "</table>\n";
}

std::string fit_table(const json& fit, std::size_t index) {
  std::string s = fmt::format(
      "<table class=\"run\" id=\"run{}-fit\">\n<caption>Allan-variance fit "
      "σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2</caption>\n"
      "<tr><th>term</th><th>value ± standard error [95 %]</th><th>unit</th></tr>\n",
      index + 1);
  static constexpr std::array<std::array<const char*, 3>, 5> kCoefficientRows{
      {{"Q_arcsec", "Q quantization", lbl::angle},
       {"N_deg_per_sqrt_h", "N angle random walk", lbl::arw},
       {"B_deg_per_h", "B bias instability", lbl::rate},
       {"K_deg_per_h_per_sqrt_h", "K rate random walk", lbl::rrw},
       {"R_deg_per_h2", "R rate ramp", lbl::ramp}}};
  for (const auto& [key, name, unit] : kCoefficientRows)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td>{}</td></tr>\n", name, coef_cell(at(fit, key)), unit);
  if (const auto c = num(fit, "chi2_per_dof")) {
    std::string gof = fmt::format("χ²/dof = {:.3g}", *c);
    if (const auto p = num(fit, "p_value")) gof += fmt::format(", p = {:.3g}", *p);
    if (const auto lo = num(fit, "tau_min_s"), hi = num(fit, "tau_max_s"); lo && hi)
      gof += fmt::format("; τ fitted {:g}–{:g} s", *lo, *hi);
    s += fmt::format("<tr><td>goodness of fit</td><td colspan=\"2\">{}</td></tr>\n", gof);
  }
  if (const auto& range = at(fit, "range"); range.is_object())
    s += fmt::format("<tr><td>fit range</td><td colspan=\"2\">{}</td></tr>\n", esc(str(range, "reason")));
  if (const auto& scaled = at(fit, "intervals_scaled"); scaled.is_boolean() && scaled.get<bool>())
    s += fmt::format(
        "<tr><td>intervals</td><td colspan=\"2\">scaled by √(χ²/dof) = {}: the model is rejected</td></tr>\n",
        g(num(fit, "interval_scale").value_or(1.0)));
  return s + "</table>\n";
}

/// The run's warnings (analysis JSON "warnings": code, message, suggested command), if any.
std::string warnings_html(const json& run) {
  const auto& w = at(run, "warnings");
  if (!w.is_array() || w.empty()) return {};
  std::string s = "<div class=\"warning\"><b>Warnings</b><ul>\n";
  for (const auto& x : w) {
    s += fmt::format("<li><b>{}</b>: {}", esc(str(x, "code")), esc(str(x, "message")));
    if (const std::string c = str(x, "command"); !c.empty()) s += fmt::format(" <code>{}</code>", esc(c));
    s += "</li>\n";
  }
  return s + "</ul></div>\n";
}

std::string run_summary(const json& run, std::size_t index) {
  std::string s = warnings_html(run) + data_table(run, index) + fit_table(at(run, "fit"), index);
  if (const auto& v = at(run, "verdict"); v.is_object())
    s += "<p>Verdict: <b>" + esc(statement_text(v)) + "</b>" +
         by_parameter(str(v, "statement_B"), str(v, "statement_N")) + ".</p>\n";
  return s;
}

/// A number of a finding with the unit its key names as a suffix (frequency_hz, time_s…).
std::string number_with_unit_key(std::string_view key, const json& v) {
  static constexpr std::array<std::pair<const char*, const char*>, 9> kUnits{{{"_deg_per_h_per_sqrt_h", lbl::rrw},
                                                                              {"_deg_per_sqrt_h", lbl::arw},
                                                                              {"_deg_per_h2", lbl::ramp},
                                                                              {"_deg_per_h", lbl::rate},
                                                                              {"_arcsec", lbl::angle},
                                                                              {"_hz", "Hz"},
                                                                              {"_s", "s"},
                                                                              {"_c", lbl::celsius},
                                                                              {"_pct", "%"}}};
  if (!v.is_number()) return json_value_html(v);
  for (const auto& [suffix, unit] : kUnits)
    if (key.size() > std::string_view(suffix).size() && key.ends_with(suffix))
      return fmt::format("{} {}", g(v.get<double>(), 4), unit);
  return g(v.get<double>(), 4);
}

std::string findings_html(const json& findings, std::size_t index) {
  if (!findings.is_array() || findings.empty())
    return "<p>No finding: the five-term model's simulations explain the measurement.</p>\n";
  std::string s = fmt::format(
      "<table id=\"run{}-findings\">\n<caption>Findings</caption>\n<tr><th>effect</th><th>parameters</th></tr>\n",
      index + 1);
  for (const auto& f : findings) {
    std::string params;
    if (f.is_object())
      for (const auto& [k, v] : f.items())
        if (k != "effect" && !v.is_object() && !v.is_array())
          params += fmt::format("{}{} = {}", params.empty() ? "" : "; ", esc(k), number_with_unit_key(k, v));
    s += fmt::format("<tr><td>{}</td><td>{}</td></tr>\n", esc(str(f, "effect")), params);
  }
  return s + "</table>\n";
}

std::string gain_html(const json& gain, std::size_t index) {
  if (!gain.is_object()) return {};
  std::string s = fmt::format(
      "<table id=\"run{}-gain\">\n<caption>Gain of the extended model</caption>\n"
      "<tr><th>measure</th><th>base model</th><th>extended model</th></tr>\n",
      index + 1);
  static constexpr std::array<std::array<const char*, 3>, 3> kRows{
      {{"Allan-variance misfit (EDF-weighted)", "misfit_base", "misfit_extended"},
       {"share of measured τ inside the simulated band", "coverage_base", "coverage_extended"},
       {"out-of-sample misfit (fit on one part, predict the other)", "holdout_misfit_base",
        "holdout_misfit_extended"}}};
  auto cell = [&](const char* key) {
    const auto v = num(gain, key);
    return v ? g(*v, 4) : std::string(kNotAvailable);
  };
  for (const auto& [name, base, ext] : kRows)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n", name, cell(base),
                     cell(ext));
  return s + "</table>\n";
}

std::string diagnosis_html(const json& d, std::size_t index, const json& run, Figures& figures) {
  std::string s = fmt::format("<h3 id=\"run{}-diagnosis\">Diagnosis: what the noise model misses</h3>\n", index + 1);
  s += fmt::format("<p id=\"run{}-diagnosis-outliers\">Outliers of the diagnosed record: {}.</p>\n", index + 1,
                   outliers_html(at(d, "outliers")));
  s += findings_html(at(d, "findings"), index) + gain_html(at(d, "gain"), index);
  if (figures.enabled && (at(at(d, "base_model"), "band").is_array() || at(d, "band").is_array()))
    s += figures.html(fmt::format("fig-run{}-diagnosis", index + 1), {diagnosis_figure(d, PlotOptions{})},
                      fmt::format("{}: measured Allan deviation against the simulated bands of the base and the "
                                  "extended model",
                                  source_name(run)));
  return s;
}

/// The verdict first: it is what the report is for.
std::string verdict_html(const std::vector<json>& a, const std::vector<std::size_t>& order, const json& overall) {
  std::string h = "<h2 id=\"verdict\">Verdict</h2>\n";
  h += fmt::format("<p class=\"verdict\">Overall class over {}: <b>{}</b> (by B: {}, by N: {}).</p>\n",
                   a.size() == 1 ? "the run" : "the temperature range", class_text(at(overall, "class")),
                   class_text(at(overall, "class_B")), class_text(at(overall, "class_N")));
  // A batch's combined verdict states its probability (the product of the runs' probabilities).
  if (const auto st = str(overall, "statement"); !st.empty())
    h += "<p id=\"verdict-probability\">Over all runs: <b>" + esc(st) + "</b>" +
         by_parameter(str(at(overall, "B"), "statement"), str(at(overall, "N"), "statement")) + ".</p>\n";
  h += "<ul>\n";
  for (auto i : order)
    h += fmt::format("<li>{} ({}): {}</li>\n", esc(source_name(a[i])), temperature_text(a[i]),
                     esc(statement_text(at(a[i], "verdict"))));
  h += "</ul>\n";
  const auto& v0 = at(a[order.front()], "verdict");
  if (const auto t = num(v0, "tolerance_pct"); t && *t > 0)
    h += fmt::format(
        "<p class=\"note\">The seed paper's heading-gyro rule is applied: a B up to {:g} % above a "
        "class limit is accepted for that class.</p>\n",
        *t);
  h += "<p class=\"meta\">P is the probability, from the estimates' uncertainty, that the true class is the one "
       "stated; where it is low the runner-up class is named.";
  if (auto table = str(v0, "table"); !table.empty()) h += " Class table: " + esc(table) + ".";
  return h + "</p>\n";
}

std::string batch_figures_html(const std::vector<json>& a, Figures& figures) {
  const json runs(a);
  std::string h = "<h2 id=\"figures\">Figures over the temperature range</h2>\n";
  h += figures.html("fig-batch-allan", {batch_allan_figure(runs, PlotOptions{})},
                    "Allan deviation at each temperature with 68 % confidence bars and the class limits for B drawn "
                    "at their floor levels 0.6643·B");
  if (auto direct = batch_direct_figure(runs, PlotOptions{}); direct.series > 0)
    return h + figures.html("fig-batch-direct", {direct},
                            fmt::format("Direct method: variance of the angle accumulated over t, Earth rate removed, "
                                        "with the regression line per temperature (slope (60·N)² {}/s)",
                                        lbl::angle2));
  return h +
         "<p class=\"note\">The direct-method curves are not in the analysis results, so the angle-variance "
         "figure is left out.</p>\n";
}

std::string settings_html(const ReportOptions& options, const json& first) {
  std::string h = "<h2 id=\"settings\">Settings and conventions</h2>\n<table id=\"settings-table\">\n";
  h += kv_row("rwcalc version", esc(version_line()));
  if (options.settings.is_object())
    for (const auto& [k, v] : options.settings.items()) h += kv_row(k, json_value_html(v));
  const bool b_in_settings = options.settings.is_object() && options.settings.contains("B estimate");
  if (auto b = str(at(first, "verdict"), "b_estimate"); !b.empty() && !b_in_settings)
    h += kv_row("B estimate used by the verdict", esc(b));
  if (const auto& conventions = at(first, "conventions"); conventions.is_object())
    for (const auto& [k, v] : conventions.items()) h += kv_row("convention: " + k, json_value_html(v));
  return h + "</table>\n";
}

}  // namespace

std::string report_html(const ReportInput& input, const ReportOptions& options) {
  const auto& a = input.analyses;
  if (a.empty()) throw AnalysisError("a report needs at least one analysed run");
  const auto order = view::by_temperature(a);
  json overall = input.overall;
  if (!overall.is_object())
    overall = {{"class_B", worst_class(a, "class_B")},
               {"class_N", worst_class(a, "class_N")},
               {"class", worst_class(a, "class")}};
  Figures figures{options.figures};

  std::string h = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n"
      "<meta name=\"generator\" content=\"rwcalc {0}\"/>\n<title>{1}</title>\n<style>{2}</style>\n</head>\n<body>\n"
      "<h1>{1}</h1>\n<p class=\"meta\">rwcalc {0} · {3} run{4}",
      RWCALC_VERSION, esc(options.title), kStyle, a.size(), a.size() == 1 ? "" : "s");
  if (!options.generated.empty()) h += " · generated " + esc(options.generated);
  h += "</p>\n" + verdict_html(a, order, overall);
  h += "<h2 id=\"tables\">Tables 1 and 2</h2>\n" + table1(a, order) + table2(a, order, overall);
  if (options.figures && a.size() > 1) h += batch_figures_html(a, figures);
  h += "<h2 id=\"runs\">Runs</h2>\n";
  for (auto i : order) {
    const auto& run = a[i];
    h += fmt::format("<h3 id=\"run{}\">{} at {}</h3>\n", i + 1, esc(source_name(run)), temperature_text(run));
    h += run_summary(run, i);
    if (options.figures)
      h += figures.html(fmt::format("fig-run{}-allan", i + 1), {analysis_figure(run, PlotOptions{})},
                        fmt::format("{}: Allan deviation with confidence bars, the fitted model and its terms, and "
                                    "the class limits for B",
                                    source_name(run)));
    if (i < input.diagnoses.size() && input.diagnoses[i].is_object())
      h += diagnosis_html(input.diagnoses[i], i, run, figures);
  }
  if (!options.figures) h += "<p class=\"note\">Figures were left out of this report (--no-figures).</p>\n";
  h += settings_html(options, a[order.front()]);
  h += fmt::format("<footer>Generated by rwcalc {}. Allan deviations in {} (1{}/s = 1 {}); τ in s.</footer>\n",
                   RWCALC_VERSION, lbl::rate, lbl::angle, lbl::rate);
  return h + "</body>\n</html>\n";
}

std::string write_report(const std::string& dir, const ReportInput& input, const ReportOptions& options, bool force) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw OutputError(fmt::format("{}: cannot create the report directory: {}", dir,
                                  ec ? ec.message() : std::string("not a directory")));
  const auto path = (std::filesystem::path(dir) / "report.html").string();
  write_file_atomic(path, report_html(input, options), force);
  return path;
}

}  // namespace rwcalc
