// The rules of the figures', the report's and the IMU page's options (validate.hpp).
#include "rwcalc/i18n.hpp"
#include "rwcalc/imu_report.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/report.hpp"

namespace rwcalc {

Violation PlotOptions::validate() const {
  // The canvas gnuplot can draw without running out of memory, and large enough for the legends.
  if (Violation v = first_of({check_in("PlotOptions::width_px", width_px, 200.0, 8000.0, "px"),
                              check_in("PlotOptions::height_px", height_px, 150.0, 16000.0, "px")}))
    return v;
  if (!output.empty()) {
    try {
      (void)plot_format_for(output);
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
  }
  return std::nullopt;
}

Violation ReportOptions::validate() const {
  if (title.empty()) return tr("ReportOptions::title is empty: the report needs a title");
  if (profile) {
    const CalendarDate& d = protocol_date;
    static constexpr int kDays[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    const bool leap = (d.year % 4 == 0 && d.year % 100 != 0) || d.year % 400 == 0;
    const bool valid = d.year >= 1 && d.year <= 9999 && d.month >= 1 && d.month <= 12 && d.day >= 1 &&
                       d.day <= kDays[d.month - 1] - (d.month == 2 && !leap ? 1 : 0);
    if (!valid)
      return trf("ReportOptions::protocol_date {:04}-{:02}-{:02} is not a calendar date (a protocol needs its date)",
                 d.year, d.month, d.day);
  }
  return std::nullopt;
}

Violation ImuPageOptions::validate() const {
  for (const std::string* f : {&noise_file, &json_file, &text_file})
    if (f->empty()) return tr("ImuPageOptions: the noise, JSON and text files beside the page need names");
  return std::nullopt;
}

}  // namespace rwcalc
