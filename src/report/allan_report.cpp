// Text and CSV renderings of an Allan-variance result (the JSON form is to_json in allan.cpp).
#include <fmt/format.h>

#include "rwcalc/allan_report.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc {

std::string unit_label(const AllanResult& r) {
  return r.unit == "deg/h" ? tr(units::label::rate) : r.unit == "m/s/h" ? "m/s/h" : tr("input units/s");
}

std::string format_allan_table(const AllanResult& r, const AllanReportInfo& info) {
  const std::string u = unit_label(r);
  std::string out;
  out += fmt::format("# rwcalc allan: {}\n", info.source.empty() ? "-" : as_typed(info.source));
  if (!info.input.empty()) out += trf("# input: {}\n", printable(info.input));
  out += trf("# estimator: {} ({})\n", deviation_name(r.estimator), to_string(r.estimator));
  out +=
      trf("# confidence: {:g} (two-sided chi-square bounds, Greenhall-Riley EDF, lag-1 ACF noise id)\n", r.confidence);
  if (r.unit == "deg/h")
    out += trf("# units: deviations in {0} (convention 1{1}/s = 1 {0} exactly); τ in s\n", tr(units::label::rate),
               tr(units::label::angle));
  else if (r.unit == "m/s/h")  // accelerometer (units.hpp): 1 m/s/h = 1/3600 m/s² = 28.33 µg
    out += tr("# units: deviations in m/s/h (accelerometer; 1 m/s/h = 1/3600 m/s^2); τ in s\n");
  else
    out += tr("# units: deviations in input units per second (dimensionless for phase in s); τ in s\n");
  out += trf("# samples: {}   phase points: {}   τ0: {:g} s", info.samples, r.points_in, r.tau0_s);
  if (info.rate_hz > 0)
    out += trf("   rate: {:g} Hz{}", info.rate_hz,
               info.rate_source.empty() ? "" : fmt::format(" ({})", tr(info.rate_source)));
  out += "\n";
  out += tr(
      "# α: noise exponent of S(f) ∝ f^α: +2 white angle/PM, +1 flicker PM, 0 white rate/FM, −1 flicker FM, −2 random "
      "walk\n");
  const std::string dev_hdr = fmt::format("σ ({})", u);
  out += fmt::format("{:>9} {:>13} {:>10} {:>3} {:>11} {:>13} {:>13} {:>13}\n", "AF", tr("τ (s)"), tr("terms"), "α",
                     tr("EDF"), "σ_min", dev_hdr.size() <= 13 ? dev_hdr : std::string("σ"), "σ_max");
  for (const AllanPoint& p : r.points)
    out += fmt::format("{:>9} {:>13.6g} {:>10} {:>3} {:>11.5g} {:>13.5e} {:>13.5e} {:>13.5e}\n", p.m, p.tau_s, p.n,
                       p.alpha, p.edf, p.dev_low, p.dev, p.dev_high);
  if (dev_hdr.size() > 13) out += trf("# σ_min, σ, σ_max in {}\n", u);
  return out;
}

std::string format_allan_csv(const AllanResult& r) {
  const std::string u = r.unit == "deg/h" ? "deg_h" : r.unit == "m/s/h" ? "m_s_h" : "1";
  std::string out = fmt::format("af,tau_s,n,alpha,edf,dev_low_{0},dev_{0},dev_high_{0}\n", u);
  for (const AllanPoint& p : r.points)
    out += fmt::format("{},{:.17g},{},{},{:.10g},{:.10g},{:.10g},{:.10g}\n", p.m, p.tau_s, p.n, p.alpha, p.edf,
                       p.dev_low, p.dev, p.dev_high);
  return out;
}

}  // namespace rwcalc
