// The HTML test report: tables from the analysis JSON, figures by gnuplot, all in one file.
#include "rwcalc/report.hpp"
#include "rwcalc/version.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <optional>

#include "html.hpp"
#include "json_view.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/option_words.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/quantity_text.hpp"

namespace rwcalc {

using nlohmann::json;

std::string base64_encode(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (unsigned{static_cast<unsigned char>(bytes[i])} << 16) |
                       (unsigned{static_cast<unsigned char>(bytes[i + 1])} << 8) |
                       unsigned{static_cast<unsigned char>(bytes[i + 2])};
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    unsigned v = unsigned{static_cast<unsigned char>(bytes[i])} << 16;
    if (i + 1 < bytes.size()) v |= unsigned{static_cast<unsigned char>(bytes[i + 1])} << 8;
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

/// Outside text (a file name, a serial, the laboratory, a command line) escaped for HTML and shown
/// as typed: no decimal comma is put into it (as_typed, i18n.hpp).
std::string typed(std::string_view text) { return marked_as_typed(esc(text)); }

/// A number without uncertainty, never in e-notation (quantity_text.hpp).
std::string g(double v, int digits = 3) { return number_text(v, digits); }

/// A unit label of units.hpp in the report's language (°/h → °/ч).
std::string unit(const char* label) { return tr(label); }

constexpr const char* kNotAvailable = "<span class=\"na\">—</span>";

/// A coefficient cell: "value ± u" rounded by the GUM rule with the 95 % interval below, rounded to
/// the same digit, or "< bound" when unresolved.
std::string coef_cell(const json& c) {
  const auto v = num(c, "value");
  if (!v) return kNotAvailable;
  const auto& resolved = at(c, "resolved");
  if (resolved.is_boolean() && !resolved.get<bool>())
    return fmt::format("&lt; {} <span class=\"ci\">{}</span>", g(*v, 2), tr("95 % upper bound"));
  const auto sigma = num(c, "sigma");
  const bool has_sigma = sigma && *sigma > 0 && std::isfinite(*sigma);
  std::string s = has_sigma ? value_with_uncertainty(*v, *sigma) : g(*v);
  const auto lo = num(c, "low95"), hi = num(c, "high95");
  if (lo && hi)
    s += fmt::format(" <span class=\"ci\">{}</span>", has_sigma ? interval_at(*lo, *hi, gum_last_digit(*sigma))
                                                                : fmt::format("[{}, {}]", g(*lo), g(*hi)));
  return s;
}

std::string temperature_text(const json& run) {
  const auto t = view::temperature_label(at(run, "temperature_c"));
  return t.empty() ? tr("not given") : t;
}

std::string class_text(const json& c) {
  if (c.is_number_integer()) return fmt::format("{}", c.get<int>());
  if (c.is_null()) return tr("outside");
  return kNotAvailable;
}

/// Whether a verdict (a run's or the overall one) is withheld: its fit rejected, no class stated.
bool is_withheld(const json& v) {
  const auto& w = at(v, "withheld");
  return w.is_boolean() && w.get<bool>();
}

/// A verdict's class cell: "no verdict" when it is withheld, else the class under `key`.
std::string verdict_class(const json& v, std::string_view key) {
  return is_withheld(v) ? std::string(tr("no verdict")) : class_text(at(v, key));
}

/// The verdict's statement, else its class (plain text).
std::string statement_text(const json& v) {
  const auto st = str(v, "statement");
  return st.empty() ? trf("class {}", class_text(at(v, "class"))) : st;
}

/// "; by B: …; by N: …" from two statements, each left out when absent.
std::string by_parameter(const std::string& b, const std::string& n) {
  return (b.empty() ? "" : trf("; by B: {}", esc(b))) + (n.empty() ? "" : trf("; by N: {}", esc(n)));
}

/// A verdict in words: the class, its probability in per cent and, when that is not decisive
/// (below 90 %), the runner-up; from the verdict's "class", "p_is" and "classes" (empty without).
std::string verdict_in_words(const json& v, const json& classes_json) {
  const auto& p_is = at(v, "p_is");
  if (!p_is.is_array() || !classes_json.is_array() || p_is.size() != classes_json.size() + 1) return {};
  const auto classes = classes_json.get<std::vector<int>>();
  const auto& c = at(v, "class");
  std::size_t s = classes.size();
  for (std::size_t k = 0; k < classes.size(); ++k)
    if (c.is_number_integer() && classes[k] == c.get<int>()) s = k;
  auto name = [&](std::size_t k) {
    return k < classes.size() ? trf("accuracy class {}", classes[k]) : trf("outside class {}", classes.back());
  };
  auto pct = [&](std::size_t k) { return 100.0 * p_is[k].get<double>(); };
  // Rounding must not turn 99.7 % into a certainty, nor 0.3 % into an impossibility.
  auto words = [&](std::size_t k) {
    const double p = pct(k);
    return p > 99.5 && p < 100 ? std::string(tr("more than 99 %"))
           : p < 0.5 && p > 0  ? std::string(tr("less than 1 %"))
                               : fmt::format("{:.0f} %", p);
  };
  std::string w = trf("{} with a probability of {}", name(s), words(s));
  if (pct(s) >= 90.0 || classes.empty()) return w;
  std::size_t r = s > 0 ? s - 1 : s + 1;
  if (s > 0 && s + 1 <= classes.size() && pct(s + 1) > pct(s - 1)) r = s + 1;
  return w + trf("; the next most probable: {} ({})", name(r), words(r));
}

std::string source_name(const json& a) {
  const auto s = str(a, "source");
  return s.empty() ? std::string(tr("(unnamed run)")) : std::filesystem::path(s).filename().string();
}

/// The class an estimate's reported value falls in (no probability): for the cross-check methods.
std::string class_by_value(const json& estimate, const json& run, const char* parameter) {
  const auto v = num(estimate, "value");
  if (!v) return kNotAvailable;
  for (const auto& [cls, limit] : view::class_limits(run, parameter))
    if (*v <= limit) return fmt::format("{}", cls);
  return tr("outside");
}

/// Tables and figures are numbered in the order they appear on the page, as in a filed report.
struct Numbering {
  bool figures_enabled = true;
  int next_table = 1;
  int next_figure = 1;
  int next_section = 1;
  /// "<h2 id=…>N. title</h2>" (the title is plain text).
  std::string section(const char* id, const std::string& title) {
    return fmt::format("<h2 id=\"{}\">{}. {}</h2>\n", id, next_section++, esc(title));
  }
  /// "<table id=…><caption>Table N. caption</caption>" (the caption is HTML).
  std::string table(const std::string& id, const std::string& caption_html, const char* css_class = nullptr) {
    return fmt::format("<table id=\"{}\"{}>\n<caption><b>{}.</b> {}</caption>\n", id,
                       css_class ? fmt::format(" class=\"{}\"", css_class) : std::string(),
                       trf("Table {}", next_table++), caption_html);
  }
  std::string figure(const std::string& id, const std::vector<Figure>& figures, const std::string& caption) {
    const auto svg = render_figures(figures, PlotFormat::Svg, 960);
    return fmt::format(
        "<figure id=\"{0}\">\n<img alt=\"{1}\" src=\"data:image/svg+xml;base64,{2}\"/>\n"
        "<figcaption><b>{3}.</b> {1}</figcaption>\n</figure>\n",
        id, esc(caption), base64_encode(svg), trf("Figure {}", next_figure++));
  }
};

/// The page style; @page gives the A4 print layout with the page number in its bottom margin
/// (the words of "Page N of M" are inserted: kStyle is a format string).
constexpr const char* kStyle = R"(
body {{ font-family: "DejaVu Sans", "Liberation Sans", Helvetica, Arial, sans-serif; font-size: 14px; color: #222;
       max-width: 1100px; margin: 1.5em auto; padding: 0 1em; line-height: 1.4; }}
h1 {{ font-size: 1.6em; margin: 0 0 0.3em; }}
h2 {{ font-size: 1.25em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }}
h3 {{ font-size: 1.05em; margin-top: 1.2em; }}
.meta {{ color: #555; }}
header.title {{ border: 2px solid #333; padding: 0.8em 1em; margin-bottom: 1.2em; }}
header.title table {{ margin: 0.4em 0 0; border: none; width: 100%; }}
header.title th, header.title td {{ border: none; border-bottom: 1px dotted #bbb; padding: 0.2em 0.6em 0.2em 0; }}
header.title th {{ background: none; width: 28%; font-weight: normal; color: #555; }}
table {{ border-collapse: collapse; margin: 0.6em 0 1em; font-size: 0.95em; }}
th, td {{ border: 1px solid #bbb; padding: 0.3em 0.6em; text-align: left; vertical-align: top;
         overflow-wrap: break-word; }}
th {{ background: #f0f0f0; }}
td.num {{ text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }}
caption {{ caption-side: top; text-align: left; padding-bottom: 0.3em; }}
.ci {{ display: block; color: #666; font-size: 0.85em; }}
.na {{ color: #999; }}
.verdict {{ font-size: 1.15em; padding: 0.6em 0.9em; border-left: 5px solid #2c7bb6; background: #f4f8fb; }}
.note {{ color: #7a4b00; background: #fff6e0; padding: 0.3em 0.6em; border-left: 4px solid #e6a000; }}
.warning {{ color: #7a0000; background: #fff0f0; padding: 0.3em 0.6em; border-left: 4px solid #c00000; }}
.unit {{ white-space: nowrap; }}
.formula {{ font-family: "DejaVu Serif", "Times New Roman", serif; white-space: nowrap; }}
code {{ overflow-wrap: anywhere; }}
#table1, #table2 {{ width: 100%; }}
figure {{ margin: 1em 0; }}
figure img {{ width: 100%; max-width: 960px; height: auto; border: 1px solid #eee; }}
figcaption {{ color: #444; font-size: 0.92em; }}
footer {{ margin-top: 2em; color: #777; font-size: 0.85em; border-top: 1px solid #ddd; padding-top: 0.5em; }}
@page {{ size: A4; margin: 16mm 14mm 18mm 16mm;
        @bottom-center {{ content: "{2}{0} " counter(page) " {1} " counter(pages); font-size: 9pt; color: #555;
                          font-family: "DejaVu Sans", "Liberation Sans", Helvetica, Arial, sans-serif; }} }}
section.protocol {{ margin-bottom: 1.5em; }}
section.protocol h1 {{ text-align: center; font-size: 1.4em; margin: 0.6em 0 0.1em; text-transform: uppercase; }}
.protocol-date, .subject {{ text-align: center; margin: 0.1em 0; }}
.approval {{ margin: 0 0 0.5em auto; width: 45%; }}
.approval p {{ margin: 0.15em 0; }}
.approved {{ font-weight: bold; letter-spacing: 0.08em; }}
span.sign {{ display: inline-block; width: 9em; border-bottom: 1px solid #222; }}
#protocol-block {{ width: 100%; }}
#protocol-block th {{ width: 28%; font-weight: normal; color: #555; background: none; }}
table.protocol {{ width: 100%; }}
table.signatures {{ margin-top: 1.5em; border: none; width: 100%; }}
table.signatures th, table.signatures td {{ border: none; background: none; padding: 0.8em 0.6em 0.2em 0; }}
table.signatures td.sign {{ border-bottom: 1px solid #222; width: 25%; }}
@media print {{
  body {{ max-width: none; margin: 0; padding: 0; font-size: 10.5px; }}
  h2, h3, caption {{ page-break-after: avoid; break-after: avoid; }}
  section.protocol {{ break-after: page; font-size: 10px; }}
  table, figure, .verdict, header.title, .approval, table.signatures {{ page-break-inside: avoid; }}
  figure img {{ max-width: 100%; border: none; }}
  a {{ color: inherit; text-decoration: none; }}
}}
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
  std::string s =
      fmt::format("<tr><td>{}</td><td class=\"num\">{}</td>", typed(source_name(run)), temperature_text(run));
  for (const auto& c : cells) s += fmt::format("<td class=\"num\">{}</td>", c);
  return s + std::string(tail) + "</tr>\n";
}

std::string table1(const std::vector<json>& a, const std::vector<std::size_t>& order, Numbering& numbering) {
  std::string s = numbering.table("table1", tr("Noise coefficients per temperature: value ± standard uncertainty "
                                               "[coverage interval, p = 0.95]"));
  s +=
      trf("<tr><th>run</th><th>temperature</th><th>N by Allan variance ({0})</th><th>N direct method ({0})</th>"
          "<th>B by Allan variance ({1})</th><th>B by 100-s averaging ({1})</th></tr>\n",
          "<span class=\"unit\">" + unit(lbl::arw) + "</span>", "<span class=\"unit\">" + unit(lbl::rate) + "</span>");
  for (auto i : order) {
    const auto& fit = at(a[i], "fit");
    const auto& methods = at(a[i], "methods");
    s += run_row(a[i], {coef_cell(at(fit, "N")), coef_cell(at(methods, "N_direct")), coef_cell(at(fit, "B")),
                        coef_cell(at(methods, "B_100s"))});
  }
  return s + "</table>\n";
}

std::string table2(const std::vector<json>& a, const std::vector<std::size_t>& order, const json& overall,
                   Numbering& numbering) {
  std::string s = numbering.table("table2", tr("Accuracy class per parameter (1 best; “outside”: beyond the last "
                                               "class)"));
  s +=
      tr("<tr><th>run</th><th>temperature</th><th>class by N (AV)</th><th>class by N direct</th>"
         "<th>class by B (verdict estimate)</th><th>class by B 100-s</th><th>class</th>"
         "<th>verdict with probability</th></tr>\n");
  for (auto i : order) {
    const auto& run = a[i];
    const auto& v = at(run, "verdict");
    const auto& methods = at(run, "methods");
    std::string statement = esc(str(v, "statement"));
    if (statement.empty()) {
      const auto p = num(v, "p_class");
      statement = p ? trf("class {} (P = {:.2f})", class_text(at(v, "class")), *p) : kNotAvailable;
    }
    if (const auto& changed = at(v, "tolerance_changed"); changed.is_boolean() && changed.get<bool>())
      statement += fmt::format(" <span class=\"note\">{}</span>",
                               trf("changed by the +{} % B tolerance", g(num(v, "tolerance_pct").value_or(0.0))));
    s += run_row(run,
                 // The cross-checks' classes too depend on the rejected fit (the terms they take off).
                 {verdict_class(v, "class_N"),
                  is_withheld(v) ? tr("no verdict") : class_by_value(at(methods, "N_direct"), run, "N"),
                  verdict_class(v, "class_B"),
                  is_withheld(v) ? tr("no verdict") : class_by_value(at(methods, "B_100s"), run, "B"),
                  "<b>" + verdict_class(v, "class") + "</b>"},
                 "<td>" + statement + "</td>");
  }
  s += fmt::format(
      "<tr><th colspan=\"2\">{}</th><td class=\"num\"><b>{}</b></td><td></td><td class=\"num\"><b>{}</b></td><td></td>"
      "<td class=\"num\"><b>{}</b></td><td>{}</td></tr>\n",
      tr("over the temperature range"), verdict_class(overall, "class_N"), verdict_class(overall, "class_B"),
      verdict_class(overall, "class"), tr("worst case over the runs"));
  return s + "</table>\n<p class=\"meta\">" +
         tr("Classes by N direct and by B 100-s compare the reported value with the class limits only (no "
            "probability); the verdict uses the estimates named in the settings.") +
         "</p>\n";
}

std::string kv_row(std::string_view key, const std::string& value_html) {
  return fmt::format("<tr><th>{}</th><td>{}</td></tr>\n", esc(key), value_html);
}

std::string json_value_html(const json& v) {
  if (v.is_string()) return esc(tr(v.get<std::string>()));
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
  if (action == "keep") return tr("kept in the analysis (--outliers remove or replace leaves them out)");
  if (action == "remove")
    return trf("{:.0f} removed before the analysis (later samples move one period earlier)",
               num(outliers, "removed").value_or(static_cast<double>(count)));
  if (action == "replace")
    return trf("{:.0f} replaced by the median of their nearest good neighbours before the analysis",
               num(outliers, "replaced").value_or(static_cast<double>(count)));
  return trf("action {}", action.empty() ? std::string(kNotAvailable) : esc(action));
}

constexpr std::size_t kReportOutlierPositions = 10;  ///< positions listed per run (the JSON has more)

/// The outlier line of a run or a diagnosis: count, action and the first positions.
std::string outliers_html(const json& outliers) {
  if (!outliers.is_object())
    return fmt::format("<span class=\"na\">{}</span>", tr("not in these results (no outlier summary)"));
  const auto count_value = num(outliers, "count");
  if (!count_value) return kNotAvailable;
  const auto count = static_cast<std::size_t>(*count_value);
  const auto z = num(outliers, "threshold_robust_z");
  const std::string threshold = z ? trf(" (threshold {} robust σ)", g(*z)) : std::string();
  if (count == 0) return tr("none found") + threshold;
  std::string s =
      fmt::format("<b>{}</b>{}; {}", trf("{} found", count), threshold, outlier_action_html(outliers, count));
  const auto& positions = at(outliers, "positions");
  std::size_t listed = 0;
  if (positions.is_array()) {
    for (const auto& p : positions) {
      if (listed == kReportOutlierPositions) break;
      const auto line = num(p, "line"), time = num(p, "time_s"), value = num(p, "value");
      s += listed++ ? ", " : ": ";
      s += line ? trf("line {:.0f}", *line) : trf("line {}", kNotAvailable);
      if (time)
        s += trf(" (t = {} s", g(*time, 6)) + (value ? fmt::format(", {} {})", g(*value, 6), unit(lbl::rate)) : ")");
    }
  }
  if (count > listed) s += (listed ? ", " : ": ") + trf("… {} more in the JSON results", count - listed);
  return s;
}

/// The identification keys of the input metadata, with their labels.
constexpr std::array<std::pair<const char*, const char*>, 4> kIdentification{{{"serial", N_("gyro serial")},
                                                                              {"operator", N_("operator")},
                                                                              {"test_date", N_("test date")},
                                                                              {"conditions", N_("test conditions")}}};

/// A record read with --gaps segments: how many segments, the gaps between them and their lengths
/// (the text report's line); empty for a record in one piece.
std::string segments_text(const json& segments) {
  const auto n = num(segments, "count");
  if (!n || *n < 2) return {};
  std::string gaps, lengths;
  for (const auto& gap : at(segments, "gaps"))
    if (const auto line = num(gap, "line"), missing = num(gap, "missing_s"); line && missing)
      gaps += trf("{}{} s missing before line {:.0f}", gaps.empty() ? "" : ", ", g(*missing, 6), *line);
  for (const auto& d : at(segments, "durations_s"))
    if (const auto v = num(d)) lengths += fmt::format("{}{:.1f}", lengths.empty() ? "" : ", ", *v);
  return trf(
      "{:.0f} segments, split at the time column's gaps by --gaps segments ({}); lengths {} s. The Allan "
      "variance pools them (no difference spans a gap); the cross-checks use the longest",
      *n, gaps, lengths);
}

std::string data_table(const json& run, std::size_t index, Numbering& numbering) {
  std::string s = numbering.table(fmt::format("run{}-data", index + 1),
                                  trf("Data and identification: {}", typed(source_name(run))), "run");
  s += kv_row(tr("file"), typed(str(run, "source")));
  const json& input = at(run, "input");
  if (const json& id = at(input, "identification"); id.is_object())
    for (const auto& [key, label] : kIdentification)
      if (const auto v = str(id, key); !v.empty()) s += kv_row(tr(label), typed(v));
  if (const auto sha = str(input, "sha256"); !sha.empty())
    s += kv_row(tr("file size, SHA-256"),
                trf("{:.0f} bytes, <code>{}</code>", num(input, "file_bytes").value_or(0), esc(sha)));
  if (const auto n = num(run, "samples")) s += kv_row(tr("samples"), fmt::format("{:.0f}", *n));
  if (const auto r = num(run, "rate_hz")) s += kv_row(tr("sample rate"), trf("{} Hz", g(*r, 6)));
  if (const auto d = num(run, "duration_s")) s += kv_row(tr("duration"), trf("{:.1f} s ({:.2f} h)", *d, *d / 3600));
  if (const auto text = segments_text(at(run, "segments")); !text.empty()) s += kv_row(tr("segments"), esc(text));
  s += kv_row(tr("temperature"), temperature_text(run));
  auto rate = [&](const char* key, const char* name, int digits) {
    if (const auto v = num(run, key)) s += kv_row(tr(name), fmt::format("{} {}", g(*v, digits), unit(lbl::rate)));
  };
  rate("mean_rate", N_("mean rate"), 5);
  rate("earth_rate", N_("expected Earth rate"), 5);
  rate("bias", N_("bias (mean − Earth rate)"), 4);
  s += fmt::format("<tr id=\"run{}-outliers\"><th>{}</th><td>{}</td></tr>\n", index + 1, tr("outliers"),
                   outliers_html(at(run, "outliers")));
  return s + "</table>\n";
}

/// The five-term model, typeset.
constexpr const char* kModelFormula = "σ²(τ) = 3Q²/τ² + N²/τ + (2 ln 2/π)·B² + K²τ/3 + R²τ²/2";

std::string fit_table(const json& fit, std::size_t index, Numbering& numbering) {
  std::string s = numbering.table(fmt::format("run{}-fit", index + 1),
                                  trf("Allan-variance fit <span class=\"formula\">{}</span>", kModelFormula), "run");
  s += tr("<tr><th>term</th><th>value ± standard uncertainty [coverage interval, p = 0.95]</th><th>unit</th></tr>\n");
  static constexpr std::array<std::array<const char*, 3>, 5> kCoefficientRows{
      {{"Q", N_("Q quantization noise"), lbl::angle},
       {"N", N_("N angle random walk"), lbl::arw},
       {"B", N_("B bias instability"), lbl::rate},
       {"K", N_("K rate random walk"), lbl::rrw},
       {"R", N_("R rate ramp"), lbl::ramp}}};
  for (const auto& [key, name, u] : kCoefficientRows)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td>{}</td></tr>\n", tr(name), coef_cell(at(fit, key)),
                     unit(u));
  auto row = [&](const char* name, const std::string& html) {
    s += fmt::format("<tr><td>{}</td><td colspan=\"2\">{}</td></tr>\n", tr(name), html);
  };
  if (const auto c = num(fit, "chi2_per_dof")) {
    std::string gof = trf("χ²/dof = {}", g(*c));
    if (const auto p = num(fit, "p_value")) gof += fmt::format(", p = {}", g(*p));
    if (const auto lo = num(fit, "tau_min_s"), hi = num(fit, "tau_max_s"); lo && hi)
      gof += trf("; τ fitted {}–{} s", g(*lo, 6), g(*hi, 6));
    row(N_("goodness of fit"), gof);
  }
  if (const auto& range = at(fit, "range"); range.is_object()) row(N_("fit range"), esc(str(range, "reason")));
  if (const auto& scaled = at(fit, "intervals_scaled"); scaled.is_boolean() && scaled.get<bool>())
    row(N_("intervals"),
        trf("scaled by √(χ²/dof) = {}: the model is rejected", g(num(fit, "interval_scale").value_or(1.0))));
  return s + "</table>\n";
}

/// The run's warnings (analysis JSON "warnings": code, message, suggested command), if any.
std::string warnings_html(const json& run) {
  const auto& w = at(run, "warnings");
  if (!w.is_array() || w.empty()) return {};
  std::string s = fmt::format("<div class=\"warning\"><b>{}</b><ul>\n", tr("Warnings"));
  for (const auto& x : w) {
    s += fmt::format("<li><b>{}</b>: {}", esc(str(x, "code")), esc(str(x, "message")));
    if (const std::string c = str(x, "command"); !c.empty()) s += fmt::format(" <code>{}</code>", typed(c));
    s += "</li>\n";
  }
  return s + "</ul></div>\n";
}

/// A withheld verdict: the statement, why, and the command to run next.
std::string withheld_html(const json& v) {
  std::string s = fmt::format("<p>{} <b>{}</b>.</p>\n", tr("Verdict:"), esc(statement_text(v)));
  if (const auto why = str(v, "reason"); !why.empty()) s += fmt::format("<p>{}</p>\n", esc(trf("Why: {}.", why)));
  if (const auto c = str(v, "command"); !c.empty())
    s += fmt::format("<p>{} <code>{}</code></p>\n", tr("Run next:"), typed(c));
  return s;
}

std::string run_summary(const json& run, std::size_t index, Numbering& numbering) {
  std::string s = warnings_html(run);
  s += data_table(run, index, numbering);  // one statement each: the tables are numbered in order
  s += fit_table(at(run, "fit"), index, numbering);
  if (const auto& v = at(run, "verdict"); is_withheld(v)) {
    s += withheld_html(v);
  } else if (v.is_object()) {
    s += fmt::format("<p>{} <b>{}</b>{}.</p>\n", tr("Verdict:"), esc(statement_text(v)),
                     by_parameter(str(v, "statement_B"), str(v, "statement_N")));
    if (const auto words = verdict_in_words(v, at(v, "classes")); !words.empty())
      s += fmt::format("<p>{}</p>\n", esc(trf("In words: {}.", words)));
  }
  return s;
}

/// A finding parameter's unit, from its ASCII name in the diagnosis's JSON, in the report's language.
std::string finding_unit(const std::string& ascii) { return esc(unit_text(ascii)); }

/// One parameter of a finding (docs/diagnosis.md, JSON): "value ± u unit" rounded by the GUM rule.
std::string finding_parameter_html(const json& p) {
  const auto& v = at(p, "value");
  if (!v.is_number()) return kNotAvailable;
  const auto& u = at(p, "standard_uncertainty");
  const std::string number =
      u.is_number() ? value_with_uncertainty(v.get<double>(), u.get<double>()) : g(v.get<double>(), 4);
  return fmt::format("{} {}", number, finding_unit(str(p, "unit")));
}

std::string findings_html(const json& findings, std::size_t index, Numbering& numbering) {
  if (!findings.is_array() || findings.empty())
    return fmt::format("<p>{}</p>\n", tr("No finding: the five-term model's simulations explain the measurement."));
  std::string s = numbering.table(fmt::format("run{}-findings", index + 1), tr("Findings"));
  s += tr("<tr><th>effect</th><th>parameters</th></tr>\n");
  for (const auto& f : findings) {
    std::string params;
    if (const auto& ps = at(f, "parameters"); ps.is_object())
      for (const auto& [k, p] : ps.items())
        params += fmt::format("{}{} = {}", params.empty() ? "" : "; ", esc(k), finding_parameter_html(p));
    s += fmt::format("<tr><td>{}</td><td>{}</td></tr>\n", esc(str(f, "effect")), params);
  }
  return s + "</table>\n";
}

std::string gain_html(const json& gain, std::size_t index, Numbering& numbering) {
  if (!gain.is_object()) return {};
  std::string s = numbering.table(fmt::format("run{}-gain", index + 1), tr("Gain of the extended model"));
  s += tr("<tr><th>measure</th><th>base model</th><th>extended model</th></tr>\n");
  static constexpr std::array<std::array<const char*, 3>, 2> kRows{
      {{N_("Allan-variance misfit (EDF-weighted)"), "misfit_base", "misfit_extended"},
       {N_("share of measured τ inside the simulated band"), "coverage_base", "coverage_extended"}}};
  auto cell = [&](const char* key) {
    const auto v = num(gain, key);
    return v ? g(*v, 4) : std::string(kNotAvailable);
  };
  for (const auto& [name, base, ext] : kRows)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n", tr(name), cell(base),
                     cell(ext));
  // The likelihood gains are of the extended model over the base: one figure each.
  static constexpr std::array<std::array<const char*, 2>, 2> kGains{
      {{N_("likelihood gain in sample (−2Δ ln L − 2k)"), "likelihood_in_sample"},
       {N_("likelihood gain on held-out runs (−2Δ ln L)"), "likelihood_holdout"}}};
  for (const auto& [name, key] : kGains)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">—</td><td class=\"num\">{}</td></tr>\n", tr(name), cell(key));
  return s + "</table>\n";
}

std::string diagnosis_html(const json& d, std::size_t index, const json& run, Numbering& numbering) {
  std::string s =
      fmt::format("<h3 id=\"run{}-diagnosis\">{}</h3>\n", index + 1, tr("Diagnosis: what the noise model misses"));
  s += fmt::format("<p id=\"run{}-diagnosis-outliers\">{}</p>\n", index + 1,
                   trf("Outliers of the diagnosed record: {}.", outliers_html(at(d, "outliers"))));
  s += findings_html(at(d, "findings"), index, numbering);
  s += gain_html(at(d, "gain"), index, numbering);
  if (numbering.figures_enabled && (at(at(d, "base_model"), "band").is_array() || at(d, "band").is_array()))
    s += numbering.figure(
        fmt::format("fig-run{}-diagnosis", index + 1), {diagnosis_figure(d, PlotOptions{})},
        trf("{}: measured Allan deviation against the simulated bands of the base and the extended model",
            source_name(run)));
  return s;
}

/// No verdict over the runs (a run's fit is rejected): said first, with each run's reason and command.
std::string withheld_verdict_html(const std::vector<json>& a, const std::vector<std::size_t>& order,
                                  const json& overall) {
  std::string h =
      fmt::format("<p class=\"verdict\">{}</p>\n",
                  a.size() == 1
                      ? std::string(tr("<b>No verdict</b>: the noise model does not describe this record, so no "
                                       "class and no probability is stated."))
                      : trf("<b>No verdict</b> over the temperature range: the noise model does not describe {} of "
                            "the {} records, so no class and no probability is stated.",
                            std::count_if(a.begin(), a.end(),
                                          [](const json& r) { return is_withheld(at(r, "verdict")); }),
                            a.size()));
  if (const auto st = str(overall, "statement"); !st.empty() && a.size() > 1)
    h += fmt::format("<p id=\"verdict-probability\">{} <b>{}</b>.</p>\n", tr("Over all runs:"), esc(st));
  h += "<ul>\n";
  for (auto i : order) {
    const auto& v = at(a[i], "verdict");
    h += fmt::format("<li>{} ({}): {}", typed(source_name(a[i])), temperature_text(a[i]), esc(statement_text(v)));
    if (is_withheld(v)) {
      h += esc(fmt::format(" ({})", str(v, "reason")));
      if (const auto c = str(v, "command"); !c.empty())
        h += fmt::format("; {} <code>{}</code>", tr("run next:"), typed(c));
    }
    h += "</li>\n";
  }
  return h + "</ul>\n";
}

/// The verdict first: it is what the report is for.
std::string verdict_html(const std::vector<json>& a, const std::vector<std::size_t>& order, const json& overall,
                         Numbering& numbering) {
  std::string h = numbering.section("verdict", tr("Verdict"));
  if (is_withheld(overall)) return h + withheld_verdict_html(a, order, overall);
  h += fmt::format("<p class=\"verdict\">{}</p>\n",
                   trf("Overall class over {}: <b>{}</b> (by B: {}, by N: {}).",
                       a.size() == 1 ? tr("the run") : tr("the temperature range"), class_text(at(overall, "class")),
                       class_text(at(overall, "class_B")), class_text(at(overall, "class_N"))));
  const auto& v0 = at(a[order.front()], "verdict");
  const json& classes = at(overall, "classes").is_array() ? at(overall, "classes") : at(v0, "classes");
  if (const auto words = verdict_in_words(overall, classes); !words.empty())
    h += fmt::format("<p id=\"verdict-words\">{}</p>\n",
                     trf("In words: the gyro is of {} by GOST RV 52339-2005.", esc(words)));
  // A batch's combined verdict states its probability (the product of the runs' probabilities).
  if (const auto st = str(overall, "statement"); !st.empty())
    h += fmt::format("<p id=\"verdict-probability\">{} <b>{}</b>{}.</p>\n", tr("Over all runs:"), esc(st),
                     by_parameter(str(at(overall, "B"), "statement"), str(at(overall, "N"), "statement")));
  h += "<ul>\n";
  for (auto i : order)
    h += fmt::format("<li>{} ({}): {}</li>\n", typed(source_name(a[i])), temperature_text(a[i]),
                     esc(statement_text(at(a[i], "verdict"))));
  h += "</ul>\n";
  if (const auto t = num(v0, "tolerance_pct"); t && *t > 0)
    h += fmt::format("<p class=\"note\">{}</p>\n",
                     trf("The seed paper's heading-gyro rule is applied: a B up to {} % above a class limit is "
                         "accepted for that class.",
                         g(*t)));
  h += "<p class=\"meta\">" +
       std::string(tr("P is the probability, from the estimates' uncertainty, that the true class is the one stated; "
                      "where it is low the runner-up class is named."));
  if (auto table = str(v0, "table"); !table.empty()) h += " " + trf("Class table: {}.", typed(tr(table)));
  return h + "</p>\n";
}

std::string batch_figures_html(const std::vector<json>& a, Numbering& numbering) {
  const json runs(a);
  std::string h = numbering.section("figures", tr("Figures over the temperature range"));
  h += numbering.figure("fig-batch-allan", {batch_allan_figure(runs, PlotOptions{})},
                        tr("Allan deviation at each temperature with 68 % confidence bars and the class limits for B "
                           "drawn at their floor levels 0.6643·B"));
  if (auto direct = batch_direct_figure(runs, PlotOptions{}); direct.series > 0)
    return h + numbering.figure("fig-batch-direct", {direct},
                                trf("Direct method: variance of the angle accumulated over t, Earth rate removed, "
                                    "with the regression line per temperature (slope (60·N)² {}/s)",
                                    unit(lbl::angle2)));
  return h + fmt::format("<p class=\"note\">{}</p>\n",
                         tr("The direct-method curves are not in the analysis results, so the angle-variance figure "
                            "is left out."));
}

/// The conventions of the results, typeset (the JSON's "conventions" say the same in ASCII);
/// a convention this list does not know is shown as the JSON gives it.
std::string conventions_rows(const json& conventions) {
  static constexpr std::array<std::array<const char*, 3>, 8> kConventions{
      {{"Q", N_("Q, quantization noise"),
        N_("σ²(τ) = 3Q²/τ², Q the rms white angle error (IEEE 952); the paper's "
           "eq. (2) gives √3·Q")},
       {"N", N_("N, angle random walk"), N_("σ²(τ) = N²/τ; N = σ(τ = 1 h)")},
       {"B", N_("B, bias instability"),
        N_("σ² = (2 ln 2/π)·B², floor 0.6643·B (the paper prints B where B² is meant)")},
       {"K", N_("K, rate random walk"), N_("σ²(τ) = K²τ/3; K = σ(τ = 3 h)")},
       {"R", N_("R, rate ramp"), N_("σ²(τ) = R²τ²/2")},
       {"deviation_unit", N_("unit of the Allan deviation"), N_("°/h (1″/s = 1 °/h)")},
       {"intervals", N_("intervals"),
        N_("value ± standard uncertainty u; the coverage interval for p = 0.95 from the profile likelihood; "
           "“< x”: not resolved, x is the 95 % upper bound")},
       {"rounding", N_("rounding"),
        N_("the uncertainty to two significant digits when its first digit is 1 or 2, else to one; the value and "
           "its interval to the same digit ({}, 7.2.6)")}}};
  std::string h;
  for (const auto& [key, name, text] : kConventions) {
    const std::string shown = esc(tr(text));
    // The standard is named as typed: no decimal comma goes into "34100.3".
    h += kv_row(tr(name), std::string_view(key) == "rounding"
                              ? fmt::format(fmt::runtime(shown), typed(tr(N_("JCGM 100:2008, the GUM"))))
                              : shown);
  }
  if (conventions.is_object())
    for (const auto& item : conventions.items()) {
      const std::string& k = item.key();  // a structured binding, clang 14 (the fuzz build) cannot capture
      // "units" says where the JSON names its units (docs/result-json.md); the report names each unit itself.
      if (k != "units" &&
          std::none_of(kConventions.begin(), kConventions.end(), [&](const auto& c) { return k == c[0]; }))
        h += kv_row(k, json_value_html(item.value()));
    }
  return h;
}

std::string settings_html(const ReportOptions& options, const json& first, Numbering& numbering) {
  std::string h = numbering.section("settings", tr("Settings and conventions"));
  h += numbering.table("settings-table", tr("Settings of the analysis"));
  h += kv_row(tr("rwcalc version"), esc(version_line()));
  const bool have_settings = options.settings.is_object();
  if (have_settings)
    for (const auto& [k, v] : options.settings.items()) h += kv_row(tr(k), json_value_html(v));
  if (auto b = str(at(first, "verdict"), "b_estimate");
      !b.empty() && !(have_settings && options.settings.contains("B estimate")))
    h += kv_row(tr("B estimate"), esc(option_value_words("--b-estimate", b)));
  h += "</table>\n" + numbering.table("conventions-table", tr("Conventions of the results"));
  return h + conventions_rows(at(first, "conventions")) + "</table>\n";
}

/// The distinct values of an identification key over the runs, in run order, joined by "; ".
std::string identification_values(const std::vector<json>& a, const char* key) {
  std::vector<std::string> seen;
  for (const auto& run : a)
    if (const auto v = str(at(at(run, "input"), "identification"), key); !v.empty())
      if (std::find(seen.begin(), seen.end(), v) == seen.end()) seen.push_back(v);
  std::string s;
  for (const auto& v : seen) s += (s.empty() ? "" : "; ") + typed(v);
  return s;
}

/// The title block: what a filed report names first (laboratory, gyro, serial, test, date).
std::string title_block(const std::vector<json>& a, const ReportOptions& options, const std::string& title) {
  std::string h = fmt::format("<header class=\"title\">\n<h1>{}</h1>\n<table id=\"title-block\">\n", typed(title));
  auto row = [&](const char* name, const std::string& html) {
    h += kv_row(tr(name), html.empty() ? std::string(kNotAvailable) : html);
  };
  row(N_("laboratory"), options.lab.empty() ? std::string() : typed(options.lab));
  row(N_("gyro"), options.gyro.empty() ? std::string() : typed(options.gyro));
  row(N_("gyro serial"), identification_values(a, "serial"));
  row(N_("test date"), identification_values(a, "test_date"));
  row(N_("operator"), identification_values(a, "operator"));
  row(N_("test conditions"), identification_values(a, "conditions"));
  row(N_("runs"), trf("{} (each recording's size and SHA-256 under “Runs”)", a.size()));
  row(N_("report generated"), esc(options.generated) + " · " + esc(version_line()));
  return h + "</table>\n</header>\n";
}

/// Text for a CSS string: everything but letters, digits, blanks and bytes of UTF-8 sequences as
/// a CSS escape, so that no quote, backslash or "</style>" leaves the string.
std::string css_string(std::string_view text) {
  std::string out;
  for (const char ch : printable(text)) {
    const auto c = static_cast<unsigned char>(ch);
    out += std::isalnum(c) || c == ' ' || c >= 0x80 ? std::string(1, static_cast<char>(c)) : fmt::format("\\{:x} ", c);
  }
  return out;
}

}  // namespace

std::string html::stylesheet(const std::string& page_prefix) {
  return fmt::format(fmt::runtime(kStyle), tr("Page"), tr("of"), page_prefix);
}
std::string html::text(std::string_view s) { return esc(s); }
std::string html::typed(std::string_view s) { return rwcalc::typed(s); }
std::string html::coefficient_cell(const json& c) { return coef_cell(c); }
std::string html::not_available() { return kNotAvailable; }
std::string html::kv_row(std::string_view key, const std::string& value_html) {
  return rwcalc::kv_row(key, value_html);
}
std::string html::run_row(const json& run, const std::vector<std::string>& cells) {
  return rwcalc::run_row(run, cells);
}
std::string html::verdict_class(const json& v, std::string_view key) { return rwcalc::verdict_class(v, key); }
bool html::is_withheld(const json& v) { return rwcalc::is_withheld(v); }
std::string html::verdict_in_words(const json& v, const json& classes) { return rwcalc::verdict_in_words(v, classes); }
std::string html::class_text(const json& c) { return rwcalc::class_text(c); }
std::string html::identification_values(const std::vector<json>& a, const char* key) {
  return rwcalc::identification_values(a, key);
}

std::string report_html(const ReportInput& input, const ReportOptions& options) {
  require_valid(options);
  const auto& a = input.analyses;
  if (a.empty()) throw AnalysisError(tr("a report needs at least one analysed run"));
  const auto order = view::by_temperature(a);
  json overall = input.overall;
  if (!overall.is_object())
    overall = {{"class_B", worst_class(a, "class_B")},
               {"class_N", worst_class(a, "class_N")},
               {"class", worst_class(a, "class")},
               {"withheld",
                std::any_of(a.begin(), a.end(), [](const json& r) { return is_withheld(at(r, "verdict")); })}};
  Numbering numbering{options.figures};
  // The default title is the program's text, translated; a title given is the user's own.
  const std::string title = options.title == ReportOptions{}.title ? tr(options.title) : options.title;

  std::string h = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"{0}\">\n<head>\n<meta charset=\"utf-8\"/>\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n"
      "<meta name=\"generator\" content=\"rwcalc {1}\"/>\n<title>{2}</title>\n<style>{3}</style>\n</head>\n<body>\n",
      language_code(), RWCALC_VERSION, typed(title),
      html::stylesheet(options.profile ? css_string(trf("Test protocol No. {}", options.protocol_number)) + " · "
                                       : ""));
  h += options.profile ? html::protocol_block(a, order, overall, options, title) : title_block(a, options, title);
  h += verdict_html(a, order, overall, numbering);
  // One statement each: the tables are numbered in the order they are made.
  h += numbering.section("tables", tr("Tables 1 and 2"));
  h += table1(a, order, numbering);
  h += table2(a, order, overall, numbering);
  if (options.figures && a.size() > 1) h += batch_figures_html(a, numbering);
  const int runs_section = numbering.next_section;
  h += numbering.section("runs", tr("Runs"));
  std::size_t k = 0;
  for (auto i : order) {
    const auto& run = a[i];
    // "4&#46;1." : the entity keeps the decimal comma of Russian text out of the heading number.
    h += fmt::format("<h3 id=\"run{}\">{}&#46;{}. {}</h3>\n", i + 1, runs_section, ++k,
                     trf("{} at {}", typed(source_name(run)), temperature_text(run)));
    h += run_summary(run, i, numbering);
    if (options.figures)
      h += numbering.figure(fmt::format("fig-run{}-allan", i + 1), {analysis_figure(run, PlotOptions{})},
                            trf("{}: Allan deviation with confidence bars, the fitted model and its terms, and the "
                                "class limits for B",
                                source_name(run)));
    if (i < input.diagnoses.size() && input.diagnoses[i].is_object())
      h += diagnosis_html(input.diagnoses[i], i, run, numbering);
  }
  if (!options.figures)
    h += fmt::format("<p class=\"note\">{}</p>\n", tr("Figures were left out of this report (--no-figures)."));
  h += settings_html(options, a[order.front()], numbering);
  h += fmt::format("<footer>{}</footer>\n",
                   trf("Generated by rwcalc {}. Allan deviations in {} (1 {}/s = 1 {}); τ in s.", RWCALC_VERSION,
                       unit(lbl::rate), unit(lbl::angle), unit(lbl::rate)));
  return localize_html(h + "</body>\n</html>\n");
}

std::string write_report(const std::string& dir, const ReportInput& input, const ReportOptions& options, bool force) {
  require_valid(options);  // before the directory is made
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw OutputError(
        trf("{}: cannot create the report directory: {}", dir, ec ? ec.message() : std::string(tr("not a directory"))));
  const auto path = (std::filesystem::path(dir) / "report.html").string();
  write_file_atomic(path, report_html(input, options), force);
  return path;
}

}  // namespace rwcalc
