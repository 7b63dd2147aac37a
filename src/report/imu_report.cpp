// The page of `rwcalc imu --report`: the IMU's tables from its result as the report shows it
// (shown_results.hpp, read from the JSON at the entry) in the test report's look (report/html.hpp),
// so that it prints to A4 with nothing running off the page.
#include "rwcalc/imu_report.hpp"

#include <fmt/format.h>

#include <array>
#include <filesystem>
#include <functional>
#include <string_view>
#include <vector>

#include "html.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/quantity_text.hpp"
#include "rwcalc/version.hpp"
#include "shown_results.hpp"

namespace rwcalc {

namespace imu_page {

using shown::Analysis;
using shown::Term;

/// The rows of a kind's table: the fit's five terms, then the two noise-file values in SI.
struct TermRow {
  Term term;
  const char* gyro_name;
  const char* accel_name;
};
constexpr std::array<TermRow, 5> kTermRows{{
    {Term::Q, N_("Q angle quantisation"), N_("Q velocity quantisation")},
    {Term::N, N_("N angle random walk"), N_("N velocity random walk")},
    {Term::B, N_("B bias instability"), N_("B bias instability")},
    {Term::K, N_("K rate random walk"), N_("K acceleration random walk")},
    {Term::R, N_("R rate ramp"), N_("R acceleration ramp")},
}};

std::string g(double v) { return fmt::format("{:.4g}", v); }

/// A unit's ASCII name (JSON) as printed, encoded for the page.
std::string unit_label(std::string_view ascii) { return html::text(unit_text(ascii)); }

std::vector<const Analysis*> channels_of(const shown::Imu& imu, std::string_view kind) {
  std::vector<const Analysis*> out;
  for (const auto& ch : imu.channels)
    if (ch.sensor == kind) out.push_back(&ch);
  return out;
}

/// One row: a name (with its unit) and one cell per axis.
std::string row(const std::string& name_html, const std::vector<const Analysis*>& axes,
                const std::function<std::string(const Analysis&)>& cell) {
  std::string s = fmt::format("<tr><th>{}</th>", name_html);
  for (const auto* a : axes) s += fmt::format("<td class=\"num\">{}</td>", cell(*a));
  return s + "</tr>\n";
}

/// An axis' coefficient in SI; not available without one.
const shown::CoefficientValues& si_of(const shown::Coefficient& c) {
  static const shown::CoefficientValues none;
  return c.si ? *c.si : none;
}

std::string kind_table(const std::vector<const Analysis*>& axes, bool gyro, int number) {
  std::string s = fmt::format(
      "<table class=\"imu\">\n<caption><b>{}.</b> {}</caption>\n<tr><th>{}</th>", trf("Table {}", number),
      gyro ? tr("Gyro axes: value ± standard error [95 % interval]; < : not resolved, 95 % upper bound")
           : tr("Accelerometer axes: value ± standard error [95 % interval]; < : not resolved, 95 % upper bound"),
      tr("term"));
  for (const auto* a : axes) s += fmt::format("<th class=\"axis\">{}</th>", html::typed(a->column));
  s += "</tr>\n";
  s += row(fmt::format("{} <span class=\"unit\">({})</span>", tr("mean"), unit_label(axes.front()->rate_unit)), axes,
           [](const Analysis& a) { return a.mean_rate ? g(*a.mean_rate) : std::string("—"); });
  for (const auto& t : kTermRows) {
    const auto& c0 = axes.front()->fit[t.term];
    s += row(fmt::format("{} <span class=\"unit\">({})</span>", tr(gyro ? t.gyro_name : t.accel_name),
                         unit_label(c0.unit)),
             axes, [&](const Analysis& a) { return html::coefficient_cell(a.fit[t.term]); });
  }
  for (const auto& si_row : {std::pair{Term::N, "N"}, std::pair{Term::K, "K"}}) {
    const Term term = si_row.first;  // not a structured binding: clang 14 (the fuzz build) cannot capture one
    const auto& si0 = si_of(axes.front()->fit[term]);
    s += row(fmt::format("{} <span class=\"unit\">({})</span>", trf("{} in SI", si_row.second), unit_label(si0.unit)),
             axes, [&](const Analysis& a) { return html::coefficient_cell(si_of(a.fit[term])); });
  }
  s += row(html::text(tr("fit χ²/dof (p)")), axes, [](const Analysis& a) {
    const auto chi2 = a.fit.chi2_per_dof, p = a.fit.p_value;
    return chi2 ? fmt::format("{:.2f}{}", *chi2, p ? fmt::format(" ({:.2g})", *p) : std::string()) : std::string("—");
  });
  s += row(html::text(tr("fit τ (s)")), axes, [](const Analysis& a) {
    const auto lo = a.fit.tau_min_s, hi = a.fit.tau_max_s;
    return lo && hi ? fmt::format("{}–{}", g(*lo), g(*hi)) : std::string("—");
  });
  return s + "</table>\n";
}

/// Each axis' warnings and why no verdict is given, as notes below its table.
std::string axis_notes(const std::vector<const Analysis*>& axes) {
  std::string s;
  for (const auto* a : axes)
    for (const auto& x : a->warnings)
      s += fmt::format("<p class=\"note\"><b>{}</b>: {}</p>\n", html::typed(a->column), html::text(x.message));
  return s;
}

/// The noise file's keys: each kind's noise density and random walk, with the axis it comes from.
std::string noise_keys(const shown::Imu& imu, const ImuPageOptions& o) {
  std::string s =
      fmt::format("<table id=\"noise-keys\">\n<caption>{}</caption>\n<tr><th></th><th>{}</th><th>{}</th></tr>\n",
                  trf("The noise file's keys ({}): the worst axis with an accepted fit and a resolved value",
                      fmt::format("<a href=\"{0}\">{0}</a>", html::typed(o.noise_file))),
                  tr("noise density N"), tr("random walk K"));
  for (const bool gyro : {true, false}) {
    const auto& worst = gyro ? imu.gyro_worst : imu.accelerometer_worst;
    if (!worst) continue;
    auto cell = [&](std::optional<double> v, const std::string& axis, const char* unit) {
      if (!v) return std::string("—");
      return fmt::format("{} <span class=\"unit\">{}</span> <span class=\"ci\">{}</span>", g(*v), unit,
                         html::typed(axis));
    };
    s += fmt::format("<tr><th>{}</th><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n",
                     gyro ? tr("gyro") : tr("accelerometer"),
                     cell(worst->noise_density, worst->noise_density_axis, gyro ? "rad/s/√Hz" : "m/s²/√Hz"),
                     cell(worst->random_walk, worst->random_walk_axis, gyro ? "rad/s²/√Hz" : "m/s³/√Hz"));
  }
  return s + "</table>\n";
}

std::string title_block(const shown::Imu& imu) {
  const std::string& source = imu.source;
  const std::string name = std::filesystem::path(source).filename().string();
  std::string h = fmt::format("<header class=\"title\">\n<h1>{}</h1>\n<table id=\"title-block\">\n",
                              html::typed(trf("IMU noise: {}", name)));
  auto kv = [&h](const std::string& key, const std::string& value_html) {
    h += fmt::format("<tr><th>{}</th><td>{}</td></tr>\n", html::text(key), value_html);
  };
  kv(tr("recording"), fmt::format("<code>{}</code>", html::typed(source)));
  const auto rate = imu.rate_hz, duration = imu.duration_s;
  kv(tr("samples"), trf("{} at {} Hz, {} s", imu.samples.value_or("—"), rate ? g(*rate) : "—",
                        duration ? fmt::format("{:.1f}", *duration) : "—"));
  if (!imu.channels.empty())
    if (const auto& sha = imu.channels.front().sha256; !sha.empty())
      kv("SHA-256", fmt::format("<code>{}</code>", html::typed(sha)));
  kv(tr("report generated"), html::text(version_line()));
  return h + "</table>\n</header>\n";
}

}  // namespace imu_page

std::string imu_report_html(const nlohmann::json& imu_json, const ImuPageOptions& o) {
  require_valid(o);
  using namespace imu_page;
  const auto imu = shown::read_imu(imu_json);
  const std::string title = trf("IMU noise: {}", std::filesystem::path(imu.source).filename().string());
  std::string h = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"{}\">\n<head>\n<meta charset=\"utf-8\"/>\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n<title>{}</title>\n<style>{}"
      "table.imu {{ width: 100%; table-layout: fixed; }}\ntable.imu th.axis {{ overflow-wrap: anywhere; }}\n"
      "table.imu th:first-child {{ width: 30%; }}\n"
      // The figure's two panels are taller than they are wide: on paper they keep to one page.
      "@media print {{ figure img {{ width: auto; max-width: 100%; max-height: 230mm; }} "
      "}}\n</style>\n</head>\n<body>\n",
      language_code(), html::typed(title), html::stylesheet());
  h += title_block(imu);
  h += fmt::format("<h2 id=\"noise-file\">1. {}</h2>\n", html::text(tr("Noise file")));
  h += noise_keys(imu, o);
  h += fmt::format("<h2 id=\"tables\">2. {}</h2>\n", html::text(tr("Noise coefficients per axis")));
  int table = 1;
  for (const bool gyro : {true, false}) {
    const auto axes = channels_of(imu, gyro ? "gyro" : "accelerometer");
    if (axes.empty()) continue;
    h += kind_table(axes, gyro, table++) + axis_notes(axes);
  }
  if (!o.figure.empty())
    h += fmt::format(
        "<figure id=\"figure\">\n<img alt=\"{0}\" src=\"{1}\"/>\n<figcaption><b>{2}.</b> {0}</figcaption>\n"
        "</figure>\n",
        html::text(tr("Allan deviation of every axis with 68 % confidence bars and its fitted model")),
        html::typed(o.figure), trf("Figure {}", 1));
  h += fmt::format("<footer>{}</footer>\n",
                   trf("All results: {}; the tables as text: {}. {}",
                       fmt::format("<a href=\"{0}\">{0}</a>", html::typed(o.json_file)),
                       fmt::format("<a href=\"{0}\">{0}</a>", html::typed(o.text_file)), html::text(version_line())));
  return localize_html(h + "</body>\n</html>\n");
}

}  // namespace rwcalc
