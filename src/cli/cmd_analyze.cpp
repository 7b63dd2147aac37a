// 'rwcalc analyze FILE': Allan variance, noise coefficients with uncertainties, the paper's
// cross-checks, Earth rate and bias, and the class verdict, as a report or JSON.
#include <fmt/format.h>

#include <memory>
#include <ostream>

#include "analyze_args.hpp"
#include "batch_format.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "plot_args.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/imu.hpp"
#include "rwcalc/output.hpp"

namespace rwcalc::cli {

namespace {

struct AnalyzeCmd {
  std::string file;
  InputArgs input;
  AnalyzeArgs analysis;
  std::optional<double> temperature;
  bool json = false;
  std::string output = "-";
  PlotArgs plot;
  bool force = false;
  std::string output_unit;  ///< "" : the classic report (gyro), the usual units (accelerometer)
};

}  // namespace

void register_analyze(CLI::App& app, Runner& runner) {
  auto cmd = std::make_shared<AnalyzeCmd>();
  auto* sub = app.add_subcommand(
      "analyze", tr("Noise coefficients (Q, N, B, K, R) with 95 % intervals, the paper's cross-checks (direct N, "
                    "100-s averages), Earth rate and bias, and the GOST RV 52339 class verdict with its probability"));
  sub->alias("analyse");  // the British spelling, which the documents use too
  sub->add_option("FILE", cmd->file, tr("Recording to analyse ('-' for standard input)"))->required();
  cmd->input.add_to(*sub);
  cmd->analysis.add_to(*sub);
  add_temperature_option(*sub, cmd->temperature, tr("Temperature of the run, °C (overrides the file)"));
  sub->add_flag("--json", cmd->json, tr("Print the JSON object instead of the report"));
  sub->add_option("--output-unit", cmd->output_unit,
                  tr("Show the results in this unit: deg/h, deg/s, rad/s (gyro); m/s^2, g, mg, ug (accelerometer). "
                     "Given, or for an accelerometer column, the report is the channel's table in these units and SI"))
      ->option_text("deg/h|deg/s|rad/s|m/s^2|g|mg|ug");
  add_output_options(*sub, cmd->output, cmd->force);
  cmd->plot.add_to(*sub, N_("the Allan deviation with its confidence bars, the fitted model, each term's line and the "
                            "class limits for B"));
  sub->callback([cmd, &runner] {
    runner = [cmd](Io& io) -> int {
      AnalysisOptions opt = cmd->analysis.options();
      opt.temperature_c = cmd->temperature;
      opt.progress = io.progress;
      // Output problems (figure format, existing files, two outputs naming one file, no gnuplot)
      // are reported before the analysis, and before anything is written.
      cmd->plot.check(cmd->force, {{"-o", cmd->output}});
      ReadOptions read = cmd->input.options();
      read.progress = io.progress;
      const Recording rec = read_recording(cmd->file, read);
      print_input_notes(io.err, rec);
      const AnalysisResult res = analyze(rec, opt);
      // One JSON schema for every sensor kind and unit; the readable report is the classic one for
      // a gyro in its usual units, else the channel's table in the units asked for.
      const UnitSet shown = output_units(res.sensor, cmd->output_unit);
      const bool classic = res.sensor == SensorKind::Gyro && cmd->output_unit.empty();
      const nlohmann::json j = to_json(res, shown);
      require_finite(j, rec.source);
      if (cmd->plot.any()) cmd->plot.draw_analysis(j, cmd->force, io);
      // A file name that is not UTF-8 is written with U+FFFD for its invalid bytes, not refused.
      const std::string text = cmd->json ? j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n"
                               : classic ? localize_numbers(format_report(res))
                                         : localize_numbers(format_channel(res, shown));
      emit(io, text, cmd->output, cmd->force);
      return 0;
    };
  });
}

}  // namespace rwcalc::cli
