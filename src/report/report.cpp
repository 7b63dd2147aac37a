// The HTML test report: tables from the analysis results as they are shown (shown_results.hpp, read
// from the JSON at the entry), figures by gnuplot, all in one file.
#include "rwcalc/report.hpp"
#include "rwcalc/version.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <optional>

#include "html.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/option_words.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/quantity_text.hpp"
#include "rwcalc/units.hpp"
#include "shown_figures.hpp"
#include "shown_results.hpp"

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

using shown::Analysis;
using shown::ClassValue;
using shown::Id;
using shown::Term;
using shown::Verdict;
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
std::string coef_cell(const shown::CoefficientValues& c) {
  const auto v = c.value;
  if (!v) return kNotAvailable;
  if (c.resolved && !*c.resolved)
    return fmt::format("&lt; {} <span class=\"ci\">{}</span>", g(*v, 2), tr("95 % upper bound"));
  const auto sigma = c.sigma;
  const bool has_sigma = sigma && *sigma > 0 && std::isfinite(*sigma);
  std::string s = has_sigma ? value_with_uncertainty(*v, *sigma) : g(*v);
  const auto lo = c.low95, hi = c.high95;
  if (lo && hi)
    s += fmt::format(" <span class=\"ci\">{}</span>", has_sigma ? interval_at(*lo, *hi, gum_last_digit(*sigma))
                                                                : fmt::format("[{}, {}]", g(*lo), g(*hi)));
  return s;
}

std::string temperature_text(const Analysis& run) {
  const auto t = shown::temperature_label(run.temperature_c);
  return t.empty() ? tr("not given") : t;
}

std::string class_text(const ClassValue& c) {
  switch (c.kind) {
    case ClassValue::Kind::Number: return fmt::format("{}", c.number);
    case ClassValue::Kind::Outside: return tr("outside");
    case ClassValue::Kind::NotAvailable: break;
  }
  return kNotAvailable;
}

/// A verdict's class cell: "no verdict" when it is withheld (its fit rejected), else the class `c`.
std::string verdict_class(const Verdict& v, const ClassValue& c) {
  return v.withheld ? std::string(tr("no verdict")) : class_text(c);
}

/// The verdict's statement, else its class (plain text).
std::string statement_text(const Verdict& v) {
  return v.statement.empty() ? trf("class {}", class_text(v.cls)) : v.statement;
}

/// "; by B: …; by N: …" from two statements, each left out when absent.
std::string by_parameter(const std::string& b, const std::string& n) {
  return (b.empty() ? "" : trf("; by B: {}", esc(b))) + (n.empty() ? "" : trf("; by N: {}", esc(n)));
}

/// A verdict in words: the class, its probability in per cent and, when that is not decisive
/// (below 90 %), the runner-up; from the verdict's "class", "p_is" and "classes" (empty without).
std::string verdict_in_words(const Verdict& v, const std::optional<std::vector<int>>& classes_given) {
  if (!v.p_is || !classes_given || v.p_is->size() != classes_given->size() + 1) return {};
  const auto& classes = *classes_given;
  const auto& p_is = *v.p_is;
  std::size_t s = classes.size();
  for (std::size_t k = 0; k < classes.size(); ++k)
    if (v.cls.kind == ClassValue::Kind::Number && classes[k] == v.cls.number) s = k;
  auto name = [&](std::size_t k) {
    return k < classes.size() ? trf("accuracy class {}", classes[k]) : trf("outside class {}", classes.back());
  };
  auto pct = [&](std::size_t k) { return 100.0 * p_is[k]; };
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

std::string source_name(const Analysis& a) {
  return a.source.empty() ? std::string(tr("(unnamed run)")) : std::filesystem::path(a.source).filename().string();
}

/// The class an estimate's reported value falls in (no probability): for the cross-check methods.
std::string class_by_value(const shown::CoefficientValues& estimate, const Analysis& run, char parameter) {
  const auto v = estimate.value;
  if (!v) return kNotAvailable;
  for (const auto& [cls, limit] : shown::class_limits(run.verdict, parameter))
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

/// Worst (highest) class over runs; outside when any run is outside the table or unclassified.
ClassValue worst_class(const std::vector<Analysis>& analyses, ClassValue Verdict::*which) {
  int worst = 0;
  for (const auto& a : analyses) {
    const auto& c = a.verdict.*which;
    if (c.kind != ClassValue::Kind::Number) return {};
    worst = std::max(worst, c.number);
  }
  return worst > 0 ? ClassValue{ClassValue::Kind::Number, worst} : ClassValue{};
}

/// The overall verdict without a batch's: the worst class of the runs, withheld when a run's is.
Verdict worst_verdict(const std::vector<Analysis>& a) {
  Verdict v;
  v.present = true;
  v.class_B = worst_class(a, &Verdict::class_B);
  v.class_N = worst_class(a, &Verdict::class_N);
  v.cls = worst_class(a, &Verdict::cls);
  v.withheld = std::any_of(a.begin(), a.end(), [](const Analysis& r) { return r.verdict.withheld; });
  return v;
}

/// A table row: the run and its temperature, then the cells (class="num"; bold when asked).
std::string run_row(const Analysis& run, const std::vector<std::string>& cells, std::string_view tail = "") {
  std::string s =
      fmt::format("<tr><td>{}</td><td class=\"num\">{}</td>", typed(source_name(run)), temperature_text(run));
  for (const auto& c : cells) s += fmt::format("<td class=\"num\">{}</td>", c);
  return s + std::string(tail) + "</tr>\n";
}

std::string table1(const std::vector<Analysis>& a, const std::vector<std::size_t>& order, Numbering& numbering) {
  std::string s = numbering.table("table1", tr("Noise coefficients per temperature: value ± standard uncertainty "
                                               "[coverage interval, p = 0.95]"));
  s +=
      trf("<tr><th>run</th><th>temperature</th><th>N by Allan variance ({0})</th><th>N direct method ({0})</th>"
          "<th>B by Allan variance ({1})</th><th>B by 100-s averaging ({1})</th></tr>\n",
          "<span class=\"unit\">" + unit(lbl::arw) + "</span>", "<span class=\"unit\">" + unit(lbl::rate) + "</span>");
  for (auto i : order) {
    const auto& fit = a[i].fit;
    s += run_row(a[i],
                 {coef_cell(fit[Term::N]), coef_cell(a[i].n_direct), coef_cell(fit[Term::B]), coef_cell(a[i].b_100s)});
  }
  return s + "</table>\n";
}

std::string table2(const std::vector<Analysis>& a, const std::vector<std::size_t>& order, const Verdict& overall,
                   Numbering& numbering) {
  std::string s = numbering.table("table2", tr("Accuracy class per parameter (1 best; “outside”: beyond the last "
                                               "class)"));
  s +=
      tr("<tr><th>run</th><th>temperature</th><th>class by N (AV)</th><th>class by N direct</th>"
         "<th>class by B (verdict estimate)</th><th>class by B 100-s</th><th>class</th>"
         "<th>verdict with probability</th></tr>\n");
  for (auto i : order) {
    const auto& run = a[i];
    const auto& v = run.verdict;
    std::string statement = esc(v.statement);
    if (statement.empty())
      statement = v.p_class ? trf("class {} (P = {:.2f})", class_text(v.cls), *v.p_class) : kNotAvailable;
    if (v.tolerance_changed)
      statement += fmt::format(" <span class=\"note\">{}</span>",
                               trf("changed by the +{} % B tolerance", g(v.tolerance_pct.value_or(0.0))));
    s += run_row(run,
                 // The cross-checks' classes too depend on the rejected fit (the terms they take off).
                 {verdict_class(v, v.class_N), v.withheld ? tr("no verdict") : class_by_value(run.n_direct, run, 'N'),
                  verdict_class(v, v.class_B), v.withheld ? tr("no verdict") : class_by_value(run.b_100s, run, 'B'),
                  "<b>" + verdict_class(v, v.cls) + "</b>"},
                 "<td>" + statement + "</td>");
  }
  s += fmt::format(
      "<tr><th colspan=\"2\">{}</th><td class=\"num\"><b>{}</b></td><td></td><td class=\"num\"><b>{}</b></td><td></td>"
      "<td class=\"num\"><b>{}</b></td><td>{}</td></tr>\n",
      tr("over the temperature range"), verdict_class(overall, overall.class_N),
      verdict_class(overall, overall.class_B), verdict_class(overall, overall.cls), tr("worst case over the runs"));
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
std::string outlier_action_html(const shown::Outliers& outliers, std::size_t count) {
  const std::string& action = outliers.action;
  if (action == "keep") return tr("kept in the analysis (--outliers remove or replace leaves them out)");
  if (action == "remove")
    return trf("{:.0f} removed before the analysis (later samples move one period earlier)",
               outliers.removed.value_or(static_cast<double>(count)));
  if (action == "replace")
    return trf("{:.0f} replaced by the median of their nearest good neighbours before the analysis",
               outliers.replaced.value_or(static_cast<double>(count)));
  return trf("action {}", action.empty() ? std::string(kNotAvailable) : esc(action));
}

constexpr std::size_t kReportOutlierPositions = 10;  ///< positions listed per run (the JSON has more)

/// The outlier line of a run or a diagnosis: count, action and the first positions.
std::string outliers_html(const shown::Outliers& outliers) {
  if (!outliers.present)
    return fmt::format("<span class=\"na\">{}</span>", tr("not in these results (no outlier summary)"));
  const auto count_value = outliers.count;
  if (!count_value) return kNotAvailable;
  const auto count = static_cast<std::size_t>(*count_value);
  const auto z = outliers.threshold_robust_z;
  const std::string threshold = z ? trf(" (threshold {} robust σ)", g(*z)) : std::string();
  if (count == 0) return tr("none found") + threshold;
  std::string s =
      fmt::format("<b>{}</b>{}; {}", trf("{} found", count), threshold, outlier_action_html(outliers, count));
  std::size_t listed = 0;
  for (const auto& p : outliers.positions) {
    if (listed == kReportOutlierPositions) break;
    const auto line = p.line, time = p.time_s, value = p.value;
    s += listed++ ? ", " : ": ";
    s += line ? trf("line {:.0f}", *line) : trf("line {}", kNotAvailable);
    if (time)
      s += trf(" (t = {} s", g(*time, 6)) + (value ? fmt::format(", {} {})", g(*value, 6), unit(lbl::rate)) : ")");
  }
  if (count > listed) s += (listed ? ", " : ": ") + trf("… {} more in the JSON results", count - listed);
  return s;
}

/// The identification of the input metadata, with its labels.
constexpr std::array<std::pair<Id, const char*>, 4> kIdentification{{{Id::Serial, N_("gyro serial")},
                                                                     {Id::Operator, N_("operator")},
                                                                     {Id::TestDate, N_("test date")},
                                                                     {Id::Conditions, N_("test conditions")}}};

/// A record read with --gaps segments: how many segments, the gaps between them and their lengths
/// (the text report's line); empty for a record in one piece.
std::string segments_text(const shown::Segments& segments) {
  const auto n = segments.count;
  if (!n || *n < 2) return {};
  std::string gaps, lengths;
  for (const auto& gap : segments.gaps)
    if (const auto line = gap.line, missing = gap.missing_s; line && missing)
      gaps += trf("{}{} s missing before line {:.0f}", gaps.empty() ? "" : ", ", g(*missing, 6), *line);
  for (const auto& d : segments.durations_s)
    if (const auto v = d) lengths += fmt::format("{}{:.1f}", lengths.empty() ? "" : ", ", *v);
  return trf(
      "{:.0f} segments, split at the time column's gaps by --gaps segments ({}); lengths {} s. The Allan "
      "variance pools them (no difference spans a gap); the cross-checks use the longest",
      *n, gaps, lengths);
}

std::string data_table(const Analysis& run, std::size_t index, Numbering& numbering) {
  std::string s = numbering.table(fmt::format("run{}-data", index + 1),
                                  trf("Data and identification: {}", typed(source_name(run))), "run");
  s += kv_row(tr("file"), typed(run.source));
  for (const auto& [id, label] : kIdentification)
    if (const auto& v = run[id]; !v.empty()) s += kv_row(tr(label), typed(v));
  if (!run.sha256.empty())
    s += kv_row(tr("file size, SHA-256"),
                trf("{:.0f} bytes, <code>{}</code>", run.file_bytes.value_or(0), esc(run.sha256)));
  if (const auto n = run.samples) s += kv_row(tr("samples"), fmt::format("{:.0f}", *n));
  if (const auto r = run.rate_hz) s += kv_row(tr("sample rate"), trf("{} Hz", g(*r, 6)));
  if (const auto d = run.duration_s) s += kv_row(tr("duration"), trf("{:.1f} s ({:.2f} h)", *d, *d / 3600));
  if (const auto text = segments_text(run.segments); !text.empty()) s += kv_row(tr("segments"), esc(text));
  s += kv_row(tr("temperature"), temperature_text(run));
  auto rate = [&](std::optional<double> v, const char* name, int digits) {
    if (v) s += kv_row(tr(name), fmt::format("{} {}", g(*v, digits), unit(lbl::rate)));
  };
  rate(run.mean_rate, N_("mean rate"), 5);
  rate(run.earth_rate, N_("expected Earth rate"), 5);
  rate(run.bias, N_("bias (mean − Earth rate)"), 4);
  s += fmt::format("<tr id=\"run{}-outliers\"><th>{}</th><td>{}</td></tr>\n", index + 1, tr("outliers"),
                   outliers_html(run.outliers));
  return s + "</table>\n";
}

/// The five-term model, typeset.
constexpr const char* kModelFormula = "σ²(τ) = 3Q²/τ² + N²/τ + (2 ln 2/π)·B² + K²τ/3 + R²τ²/2";

std::string fit_table(const shown::Fit& fit, std::size_t index, Numbering& numbering) {
  std::string s = numbering.table(fmt::format("run{}-fit", index + 1),
                                  trf("Allan-variance fit <span class=\"formula\">{}</span>", kModelFormula), "run");
  s += tr("<tr><th>term</th><th>value ± standard uncertainty [coverage interval, p = 0.95]</th><th>unit</th></tr>\n");
  struct CoefficientRow {
    Term term;
    const char *name, *unit;
  };
  static constexpr std::array<CoefficientRow, 5> kCoefficientRows{{{Term::Q, N_("Q quantization noise"), lbl::angle},
                                                                   {Term::N, N_("N angle random walk"), lbl::arw},
                                                                   {Term::B, N_("B bias instability"), lbl::rate},
                                                                   {Term::K, N_("K rate random walk"), lbl::rrw},
                                                                   {Term::R, N_("R rate ramp"), lbl::ramp}}};
  for (const auto& [term, name, u] : kCoefficientRows)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td>{}</td></tr>\n", tr(name), coef_cell(fit[term]),
                     unit(u));
  auto row = [&](const char* name, const std::string& html) {
    s += fmt::format("<tr><td>{}</td><td colspan=\"2\">{}</td></tr>\n", tr(name), html);
  };
  if (const auto c = fit.chi2_per_dof) {
    std::string gof = trf("χ²/dof = {}", g(*c));
    if (const auto p = fit.p_value) gof += fmt::format(", p = {}", g(*p));
    if (const auto lo = fit.tau_min_s, hi = fit.tau_max_s; lo && hi)
      gof += trf("; τ fitted {}–{} s", g(*lo, 6), g(*hi, 6));
    row(N_("goodness of fit"), gof);
  }
  if (fit.range_reason) row(N_("fit range"), esc(*fit.range_reason));
  if (fit.intervals_scaled)
    row(N_("intervals"), trf("scaled by √(χ²/dof) = {}: the model is rejected", g(fit.interval_scale.value_or(1.0))));
  return s + "</table>\n";
}

/// The run's warnings (analysis JSON "warnings": code, message, suggested command), if any.
std::string warnings_html(const Analysis& run) {
  if (run.warnings.empty()) return {};
  std::string s = fmt::format("<div class=\"warning\"><b>{}</b><ul>\n", tr("Warnings"));
  for (const auto& x : run.warnings) {
    s += fmt::format("<li><b>{}</b>: {}", esc(x.code), esc(x.message));
    if (!x.command.empty()) s += fmt::format(" <code>{}</code>", typed(x.command));
    s += "</li>\n";
  }
  return s + "</ul></div>\n";
}

/// A withheld verdict: the statement, why, and the command to run next.
std::string withheld_html(const Verdict& v) {
  std::string s = fmt::format("<p>{} <b>{}</b>.</p>\n", tr("Verdict:"), esc(statement_text(v)));
  if (!v.reason.empty()) s += fmt::format("<p>{}</p>\n", esc(trf("Why: {}.", v.reason)));
  if (!v.command.empty()) s += fmt::format("<p>{} <code>{}</code></p>\n", tr("Run next:"), typed(v.command));
  return s;
}

std::string run_summary(const Analysis& run, std::size_t index, Numbering& numbering) {
  std::string s = warnings_html(run);
  s += data_table(run, index, numbering);  // one statement each: the tables are numbered in order
  s += fit_table(run.fit, index, numbering);
  if (const auto& v = run.verdict; v.withheld) {
    s += withheld_html(v);
  } else if (v.present) {
    s += fmt::format("<p>{} <b>{}</b>{}.</p>\n", tr("Verdict:"), esc(statement_text(v)),
                     by_parameter(v.statement_B, v.statement_N));
    if (const auto words = verdict_in_words(v, v.classes); !words.empty())
      s += fmt::format("<p>{}</p>\n", esc(trf("In words: {}.", words)));
  }
  return s;
}

/// A finding parameter's unit, from its ASCII name in the diagnosis's JSON, in the report's language.
std::string finding_unit(const std::string& ascii) { return esc(unit_text(ascii)); }

/// One parameter of a finding (docs/diagnosis.md, JSON): "value ± u unit" rounded by the GUM rule.
std::string finding_parameter_html(const shown::FindingParameter& p) {
  if (!p.value) return kNotAvailable;
  const std::string number =
      p.standard_uncertainty ? value_with_uncertainty(*p.value, *p.standard_uncertainty) : g(*p.value, 4);
  return fmt::format("{} {}", number, finding_unit(p.unit));
}

std::string findings_html(const std::vector<shown::Finding>& findings, std::size_t index, Numbering& numbering) {
  if (findings.empty())
    return fmt::format("<p>{}</p>\n", tr("No finding: the five-term model's simulations explain the measurement."));
  std::string s = numbering.table(fmt::format("run{}-findings", index + 1), tr("Findings"));
  s += tr("<tr><th>effect</th><th>parameters</th></tr>\n");
  for (const auto& f : findings) {
    std::string params;
    for (const auto& p : f.parameters)
      params += fmt::format("{}{} = {}", params.empty() ? "" : "; ", esc(p.name), finding_parameter_html(p));
    s += fmt::format("<tr><td>{}</td><td>{}</td></tr>\n", esc(f.effect), params);
  }
  return s + "</table>\n";
}

std::string gain_html(const std::optional<shown::Gain>& gain, std::size_t index, Numbering& numbering) {
  if (!gain) return {};
  std::string s = numbering.table(fmt::format("run{}-gain", index + 1), tr("Gain of the extended model"));
  s += tr("<tr><th>measure</th><th>base model</th><th>extended model</th></tr>\n");
  using Value = std::optional<double> shown::Gain::*;
  struct Row {
    const char* name;
    Value base, extended;
  };
  static constexpr std::array<Row, 2> kRows{
      {{N_("Allan-variance misfit (EDF-weighted)"), &shown::Gain::misfit_base, &shown::Gain::misfit_extended},
       {N_("share of measured τ inside the simulated band"), &shown::Gain::coverage_base,
        &shown::Gain::coverage_extended}}};
  auto cell = [&](Value value) {
    const auto v = (*gain).*value;
    return v ? g(*v, 4) : std::string(kNotAvailable);
  };
  for (const auto& [name, base, ext] : kRows)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n", tr(name), cell(base),
                     cell(ext));
  // The likelihood gains are of the extended model over the base: one figure each.
  static constexpr std::array<std::pair<const char*, Value>, 2> kGains{
      {{N_("likelihood gain in sample (−2Δ ln L − 2k)"), &shown::Gain::likelihood_in_sample},
       {N_("likelihood gain on held-out runs (−2Δ ln L)"), &shown::Gain::likelihood_holdout}}};
  for (const auto& [name, key] : kGains)
    s += fmt::format("<tr><td>{}</td><td class=\"num\">—</td><td class=\"num\">{}</td></tr>\n", tr(name), cell(key));
  return s + "</table>\n";
}

std::string diagnosis_html(const shown::Diagnosis& d, std::size_t index, const Analysis& run, Numbering& numbering) {
  std::string s =
      fmt::format("<h3 id=\"run{}-diagnosis\">{}</h3>\n", index + 1, tr("Diagnosis: what the noise model misses"));
  s += fmt::format("<p id=\"run{}-diagnosis-outliers\">{}</p>\n", index + 1,
                   trf("Outliers of the diagnosed record: {}.", outliers_html(d.outliers)));
  s += findings_html(d.findings, index, numbering);
  s += gain_html(d.gain, index, numbering);
  if (numbering.figures_enabled && d.band)
    s += numbering.figure(
        fmt::format("fig-run{}-diagnosis", index + 1), {shown::diagnosis_figure(d, PlotOptions{})},
        trf("{}: measured Allan deviation against the simulated bands of the base and the extended model",
            source_name(run)));
  return s;
}

/// No verdict over the runs (a run's fit is rejected): said first, with each run's reason and command.
std::string withheld_verdict_html(const std::vector<Analysis>& a, const std::vector<std::size_t>& order,
                                  const Verdict& overall) {
  std::string h =
      fmt::format("<p class=\"verdict\">{}</p>\n",
                  a.size() == 1
                      ? std::string(tr("<b>No verdict</b>: the noise model does not describe this record, so no "
                                       "class and no probability is stated."))
                      : trf("<b>No verdict</b> over the temperature range: the noise model does not describe {} of "
                            "the {} records, so no class and no probability is stated.",
                            std::count_if(a.begin(), a.end(), [](const Analysis& r) { return r.verdict.withheld; }),
                            a.size()));
  if (const auto& st = overall.statement; !st.empty() && a.size() > 1)
    h += fmt::format("<p id=\"verdict-probability\">{} <b>{}</b>.</p>\n", tr("Over all runs:"), esc(st));
  h += "<ul>\n";
  for (auto i : order) {
    const auto& v = a[i].verdict;
    h += fmt::format("<li>{} ({}): {}", typed(source_name(a[i])), temperature_text(a[i]), esc(statement_text(v)));
    if (v.withheld) {
      h += esc(fmt::format(" ({})", v.reason));
      if (!v.command.empty()) h += fmt::format("; {} <code>{}</code>", tr("run next:"), typed(v.command));
    }
    h += "</li>\n";
  }
  return h + "</ul>\n";
}

/// The verdict first: it is what the report is for.
std::string verdict_html(const std::vector<Analysis>& a, const std::vector<std::size_t>& order, const Verdict& overall,
                         Numbering& numbering) {
  std::string h = numbering.section("verdict", tr("Verdict"));
  if (overall.withheld) return h + withheld_verdict_html(a, order, overall);
  h += fmt::format("<p class=\"verdict\">{}</p>\n",
                   trf("Overall class over {}: <b>{}</b> (by B: {}, by N: {}).",
                       a.size() == 1 ? tr("the run") : tr("the temperature range"), class_text(overall.cls),
                       class_text(overall.class_B), class_text(overall.class_N)));
  const auto& v0 = a[order.front()].verdict;
  const auto& classes = overall.classes ? overall.classes : v0.classes;
  if (const auto words = verdict_in_words(overall, classes); !words.empty())
    h += fmt::format("<p id=\"verdict-words\">{}</p>\n",
                     trf("In words: the gyro is of {} by GOST RV 52339-2005.", esc(words)));
  // A batch's combined verdict states its probability (the product of the runs' probabilities).
  if (const auto& st = overall.statement; !st.empty())
    h += fmt::format("<p id=\"verdict-probability\">{} <b>{}</b>{}.</p>\n", tr("Over all runs:"), esc(st),
                     by_parameter(overall.by_B_statement, overall.by_N_statement));
  h += "<ul>\n";
  for (auto i : order)
    h += fmt::format("<li>{} ({}): {}</li>\n", typed(source_name(a[i])), temperature_text(a[i]),
                     esc(statement_text(a[i].verdict)));
  h += "</ul>\n";
  if (const auto t = v0.tolerance_pct; t && *t > 0)
    h += fmt::format("<p class=\"note\">{}</p>\n",
                     trf("The seed paper's heading-gyro rule is applied: a B up to {} % above a class limit is "
                         "accepted for that class.",
                         g(*t)));
  h += "<p class=\"meta\">" +
       std::string(tr("P is the probability, from the estimates' uncertainty, that the true class is the one stated; "
                      "where it is low the runner-up class is named."));
  if (const auto& table = v0.table; !table.empty()) h += " " + trf("Class table: {}.", typed(tr(table)));
  return h + "</p>\n";
}

std::string batch_figures_html(const std::vector<Analysis>& a, Numbering& numbering) {
  std::string h = numbering.section("figures", tr("Figures over the temperature range"));
  h += numbering.figure("fig-batch-allan", {shown::batch_allan_figure(a, PlotOptions{})},
                        tr("Allan deviation at each temperature with 68 % confidence bars and the class limits for B "
                           "drawn at their floor levels 0.6643·B"));
  if (auto direct = shown::batch_direct_figure(a, PlotOptions{}); direct.series > 0)
    return h + numbering.figure("fig-batch-direct", {direct},
                                trf("Direct method: variance of the angle accumulated over t, Earth rate removed, "
                                    "with the regression line per temperature (slope (60·N)² {}/s)",
                                    unit(lbl::angle2)));
  return h + fmt::format("<p class=\"note\">{}</p>\n",
                         tr("The direct-method curves are not in the analysis results, so the angle-variance figure "
                            "is left out."));
}

/// The conventions of the results, typeset (the JSON's "conventions" say the same in ASCII);
/// a convention the schema does not define is shown as the JSON gives it.
std::string conventions_rows(const Analysis& first) {
  static constexpr std::array<std::array<const char*, 2>, 8> kConventions{
      {{N_("Q, quantization noise"), N_("σ²(τ) = 3Q²/τ², Q the rms white angle error (IEEE 952); the paper's "
                                        "eq. (2) gives √3·Q")},
       {N_("N, angle random walk"), N_("σ²(τ) = N²/τ; N = σ(τ = 1 h)")},
       {N_("B, bias instability"), N_("σ² = (2 ln 2/π)·B², floor 0.6643·B (the paper prints B where B² is meant)")},
       {N_("K, rate random walk"), N_("σ²(τ) = K²τ/3; K = σ(τ = 3 h)")},
       {N_("R, rate ramp"), N_("σ²(τ) = R²τ²/2")},
       {N_("unit of the Allan deviation"), N_("°/h (1″/s = 1 °/h)")},
       {N_("intervals"),
        N_("value ± standard uncertainty u; the coverage interval for p = 0.95 from the profile likelihood; "
           "“< x”: not resolved, x is the 95 % upper bound")},
       {N_("rounding"),
        N_("the uncertainty to two significant digits when its first digit is 1 or 2, else to one; the value and "
           "its interval to the same digit ({}, 7.2.6)")}}};
  std::string h;
  for (std::size_t k = 0; k < kConventions.size(); ++k) {
    const auto& [name, text] = kConventions[k];
    const std::string typeset = esc(tr(text));
    // The last, rounding, names its standard as typed: no decimal comma goes into "34100.3".
    h += kv_row(tr(name), k + 1 == kConventions.size()
                              ? fmt::format(fmt::runtime(typeset), typed(tr(N_("JCGM 100:2008, the GUM"))))
                              : typeset);
  }
  for (const auto& [key, value] : first.other_conventions) h += kv_row(key, json_value_html(value));
  return h;
}

std::string settings_html(const ReportOptions& options, const Analysis& first, Numbering& numbering) {
  std::string h = numbering.section("settings", tr("Settings and conventions"));
  h += numbering.table("settings-table", tr("Settings of the analysis"));
  h += kv_row(tr("rwcalc version"), esc(version_line()));
  const bool have_settings = options.settings.is_object();
  if (have_settings)
    for (const auto& [k, v] : options.settings.items()) h += kv_row(tr(k), json_value_html(v));
  if (const auto& b = first.verdict.b_estimate;
      !b.empty() && !(have_settings && options.settings.contains("B estimate")))
    h += kv_row(tr("B estimate"), esc(option_value_words("--b-estimate", b)));
  h += "</table>\n" + numbering.table("conventions-table", tr("Conventions of the results"));
  return h + conventions_rows(first) + "</table>\n";
}

/// The distinct values of an identification over the runs, in run order, joined by "; ".
std::string identification_values(const std::vector<Analysis>& a, Id id) {
  std::vector<std::string> seen;
  for (const auto& run : a)
    if (const auto& v = run[id]; !v.empty())
      if (std::find(seen.begin(), seen.end(), v) == seen.end()) seen.push_back(v);
  std::string s;
  for (const auto& v : seen) s += (s.empty() ? "" : "; ") + typed(v);
  return s;
}

/// The title block: what a filed report names first (laboratory, gyro, serial, test, date).
std::string title_block(const std::vector<Analysis>& a, const ReportOptions& options, const std::string& title) {
  std::string h = fmt::format("<header class=\"title\">\n<h1>{}</h1>\n<table id=\"title-block\">\n", typed(title));
  auto row = [&](const char* name, const std::string& html) {
    h += kv_row(tr(name), html.empty() ? std::string(kNotAvailable) : html);
  };
  row(N_("laboratory"), options.lab.empty() ? std::string() : typed(options.lab));
  row(N_("gyro"), options.gyro.empty() ? std::string() : typed(options.gyro));
  row(N_("gyro serial"), identification_values(a, Id::Serial));
  row(N_("test date"), identification_values(a, Id::TestDate));
  row(N_("operator"), identification_values(a, Id::Operator));
  row(N_("test conditions"), identification_values(a, Id::Conditions));
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
std::string html::coefficient_cell(const shown::CoefficientValues& c) { return coef_cell(c); }
std::string html::not_available() { return kNotAvailable; }
std::string html::kv_row(std::string_view key, const std::string& value_html) {
  return rwcalc::kv_row(key, value_html);
}
std::string html::run_row(const Analysis& run, const std::vector<std::string>& cells) {
  return rwcalc::run_row(run, cells);
}
std::string html::verdict_class(const Verdict& v, const ClassValue& c) { return rwcalc::verdict_class(v, c); }
std::string html::verdict_in_words(const Verdict& v, const std::optional<std::vector<int>>& classes) {
  return rwcalc::verdict_in_words(v, classes);
}
std::string html::class_text(const ClassValue& c) { return rwcalc::class_text(c); }
std::string html::identification_values(const std::vector<Analysis>& a, Id id) {
  return rwcalc::identification_values(a, id);
}

std::string report_html(const ReportInput& input, const ReportOptions& options) {
  require_valid(options);
  if (input.analyses.empty()) throw AnalysisError(tr("a report needs at least one analysed run"));
  const auto a = shown::read_analyses(input.analyses);
  const auto diagnoses = shown::read_diagnoses(input.diagnoses);
  const auto order = shown::by_temperature(a);
  const Verdict overall = shown::read_overall(input.overall).value_or(worst_verdict(a));
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
      h += numbering.figure(fmt::format("fig-run{}-allan", i + 1), {shown::analysis_figure(run, PlotOptions{})},
                            trf("{}: Allan deviation with confidence bars, the fitted model and its terms, and the "
                                "class limits for B",
                                source_name(run)));
    if (i < diagnoses.size() && diagnoses[i]) h += diagnosis_html(*diagnoses[i], i, run, numbering);
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
