// The page of `rwcalc imu --report`: the IMU's tables from its JSON in the test report's look
// (report/html.hpp), so that it prints to A4 with nothing running off the page.
#include "rwcalc/imu_report.hpp"

#include <fmt/format.h>

#include <array>
#include <filesystem>
#include <functional>
#include <string_view>
#include <vector>

#include "html.hpp"
#include "json_view.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/quantity_text.hpp"
#include "rwcalc/version.hpp"

namespace rwcalc {

namespace imu_page {

using nlohmann::json;
using view::at;
using view::num;
using view::str;

/// The rows of a kind's table: the fit's five terms, then the two noise-file values in SI.
struct TermRow {
  const char* key;
  const char* gyro_name;
  const char* accel_name;
};
constexpr std::array<TermRow, 5> kTermRows{{
    {"Q", N_("Q angle quantisation"), N_("Q velocity quantisation")},
    {"N", N_("N angle random walk"), N_("N velocity random walk")},
    {"B", N_("B bias instability"), N_("B bias instability")},
    {"K", N_("K rate random walk"), N_("K acceleration random walk")},
    {"R", N_("R rate ramp"), N_("R acceleration ramp")},
}};

std::string g(double v) { return fmt::format("{:.4g}", v); }

/// A unit's ASCII name (JSON) as printed, encoded for the page.
std::string unit_label(std::string_view ascii) { return html::text(unit_text(ascii)); }

std::vector<const json*> channels_of(const json& imu, std::string_view kind) {
  std::vector<const json*> out;
  if (const auto& c = at(imu, "channels"); c.is_array())
    for (const auto& ch : c)
      if (str(ch, "sensor") == kind) out.push_back(&ch);
  return out;
}

/// One row: a name (with its unit) and one cell per axis.
std::string row(const std::string& name_html, const std::vector<const json*>& axes,
                const std::function<std::string(const json&)>& cell) {
  std::string s = fmt::format("<tr><th>{}</th>", name_html);
  for (const auto* a : axes) s += fmt::format("<td class=\"num\">{}</td>", cell(*a));
  return s + "</tr>\n";
}

std::string kind_table(const std::vector<const json*>& axes, bool gyro, int number) {
  std::string s = fmt::format(
      "<table class=\"imu\">\n<caption><b>{}.</b> {}</caption>\n<tr><th>{}</th>", trf("Table {}", number),
      gyro ? tr("Gyro axes: value ± standard error [95 % interval]; < : not resolved, 95 % upper bound")
           : tr("Accelerometer axes: value ± standard error [95 % interval]; < : not resolved, 95 % upper bound"),
      tr("term"));
  for (const auto* a : axes) s += fmt::format("<th class=\"axis\">{}</th>", html::typed(str(*a, "column")));
  s += "</tr>\n";
  const auto& first_units = at(*axes.front(), "units");
  s += row(fmt::format("{} <span class=\"unit\">({})</span>", tr("mean"), unit_label(str(first_units, "rate"))), axes,
           [](const json& a) {
             const auto v = num(a, "mean_rate");
             return v ? g(*v) : std::string("—");
           });
  for (const auto& t : kTermRows) {
    const auto& c0 = at(at(*axes.front(), "fit"), t.key);
    s += row(fmt::format("{} <span class=\"unit\">({})</span>", tr(gyro ? t.gyro_name : t.accel_name),
                         unit_label(str(c0, "unit"))),
             axes, [&](const json& a) { return html::coefficient_cell(at(at(a, "fit"), t.key)); });
  }
  for (const char* key : {"N", "K"}) {
    const auto& si0 = at(at(at(*axes.front(), "fit"), key), "si");
    s += row(fmt::format("{} <span class=\"unit\">({})</span>", trf("{} in SI", key), unit_label(str(si0, "unit"))),
             axes, [&](const json& a) { return html::coefficient_cell(at(at(at(a, "fit"), key), "si")); });
  }
  s += row(html::text(tr("fit χ²/dof (p)")), axes, [](const json& a) {
    const auto chi2 = num(at(a, "fit"), "chi2_per_dof"), p = num(at(a, "fit"), "p_value");
    return chi2 ? fmt::format("{:.2f}{}", *chi2, p ? fmt::format(" ({:.2g})", *p) : std::string()) : std::string("—");
  });
  s += row(html::text(tr("fit τ (s)")), axes, [](const json& a) {
    const auto lo = num(at(a, "fit"), "tau_min_s"), hi = num(at(a, "fit"), "tau_max_s");
    return lo && hi ? fmt::format("{}–{}", g(*lo), g(*hi)) : std::string("—");
  });
  return s + "</table>\n";
}

/// Each axis' warnings and why no verdict is given, as notes below its table.
std::string axis_notes(const std::vector<const json*>& axes) {
  std::string s;
  for (const auto* a : axes) {
    if (const auto& w = at(*a, "warnings"); w.is_array())
      for (const auto& x : w)
        s += fmt::format("<p class=\"note\"><b>{}</b>: {}</p>\n", html::typed(str(*a, "column")),
                         html::text(str(x, "message")));
  }
  return s;
}

/// The noise file's keys: each kind's noise density and random walk, with the axis it comes from.
std::string noise_keys(const json& imu, const ImuPageOptions& o) {
  std::string s =
      fmt::format("<table id=\"noise-keys\">\n<caption>{}</caption>\n<tr><th></th><th>{}</th><th>{}</th></tr>\n",
                  trf("The noise file's keys ({}): the worst axis with an accepted fit and a resolved value",
                      fmt::format("<a href=\"{0}\">{0}</a>", html::typed(o.noise_file))),
                  tr("noise density N"), tr("random walk K"));
  for (const char* kind : {"gyro", "accelerometer"}) {
    const auto& worst = at(at(at(imu, "noise"), kind), "worst");
    if (!worst.is_object()) continue;
    auto cell = [&](const char* key, const char* unit) {
      const auto v = num(worst, key);
      if (!v) return std::string("—");
      return fmt::format("{} <span class=\"unit\">{}</span> <span class=\"ci\">{}</span>", g(*v), unit,
                         html::typed(str(worst, fmt::format("{}_axis", key).c_str())));
    };
    const bool gyro = std::string_view(kind) == "gyro";
    s += fmt::format("<tr><th>{}</th><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n",
                     gyro ? tr("gyro") : tr("accelerometer"), cell("noise_density", gyro ? "rad/s/√Hz" : "m/s²/√Hz"),
                     cell("random_walk", gyro ? "rad/s²/√Hz" : "m/s³/√Hz"));
  }
  return s + "</table>\n";
}

std::string title_block(const json& imu) {
  const std::string source = str(imu, "source");
  const std::string name = std::filesystem::path(source).filename().string();
  std::string h = fmt::format("<header class=\"title\">\n<h1>{}</h1>\n<table id=\"title-block\">\n",
                              html::typed(trf("IMU noise: {}", name)));
  auto kv = [&h](const std::string& key, const std::string& value_html) {
    h += fmt::format("<tr><th>{}</th><td>{}</td></tr>\n", html::text(key), value_html);
  };
  kv(tr("recording"), fmt::format("<code>{}</code>", html::typed(source)));
  const auto rate = num(imu, "rate_hz"), duration = num(imu, "duration_s");
  const auto samples = at(imu, "samples");
  kv(tr("samples"), trf("{} at {} Hz, {} s", samples.is_number() ? samples.dump() : "—", rate ? g(*rate) : "—",
                        duration ? fmt::format("{:.1f}", *duration) : "—"));
  if (const auto& ch = at(imu, "channels"); ch.is_array() && !ch.empty())
    if (const auto sha = str(at(ch[0], "input"), "sha256"); !sha.empty())
      kv("SHA-256", fmt::format("<code>{}</code>", html::typed(sha)));
  kv(tr("report generated"), html::text(version_line()));
  return h + "</table>\n</header>\n";
}

}  // namespace imu_page

std::string imu_report_html(const nlohmann::json& imu, const ImuPageOptions& o) {
  require_valid(o);
  using namespace imu_page;
  const std::string title = trf("IMU noise: {}", std::filesystem::path(str(imu, "source")).filename().string());
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
