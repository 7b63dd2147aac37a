#pragma once
// The figures of plot.hpp drawn from the typed results (shown_results.hpp), for the report and the
// plot_* calls; the public functions of plot.hpp read the JSON and call these.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "rwcalc/plot.hpp"
#include "shown_results.hpp"

namespace rwcalc::shown {

[[nodiscard]] Figure analysis_figure(const Analysis& analysis, const PlotOptions& options);
[[nodiscard]] Figure batch_allan_figure(const std::vector<Analysis>& runs, const PlotOptions& options);
/// Empty script and series == 0 when no run carries a direct-method curve.
[[nodiscard]] Figure batch_direct_figure(const std::vector<Analysis>& runs, const PlotOptions& options);
[[nodiscard]] Figure diagnosis_figure(const Diagnosis& diagnosis, const PlotOptions& options);
[[nodiscard]] Figure imu_axes_figure(const std::vector<Analysis>& channels, const PlotOptions& options);
/// temperature_colour (plot.hpp) of a temperature that is read.
[[nodiscard]] std::string temperature_colour(std::optional<double> temperature_c, std::size_t index);

}  // namespace rwcalc::shown
