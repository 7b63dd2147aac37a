// 'rwcalc imu FILE': every gyro and accelerometer column of one static IMU recording analysed, one
// table per sensor kind, the JSON `channels` list and the noise file (Kalibr, OpenVINS, VINS-Fusion, ORB-SLAM3).
#include <fmt/format.h>

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <ostream>

#include "analyze_args.hpp"
#include "batch_format.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "plot_args.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/imu.hpp"
#include "rwcalc/imu_report.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/version.hpp"

namespace rwcalc::cli {

namespace {

struct ImuCmd {
  std::string file;
  SourceArgs source;
  std::optional<double> rate_hz;
  double time_tolerance = 0.01;
  std::string gaps = "refuse";
  std::string max_memory;
  std::vector<std::string> gyro, accel;
  std::string vertical_gyro;
  std::string gyro_unit, accel_unit;
  std::vector<std::string> shown_units;
  AnalyzeArgs analysis;
  bool json = false;
  std::string output = "-";
  std::string kalibr, rostopic = "/imu0", combine = "worst";
  std::string noise_file, noise_format = "kalibr";
  double inflate = 1;
  bool keys_from_all_axes = false, discrete = false;
  std::string report_dir;
  PlotArgs plot;
  bool force = false;

  [[nodiscard]] ImuOptions options() const {
    ImuOptions o;
    o.read.rate_hz = rate_hz;
    o.read.time_tolerance = time_tolerance;
    o.read.gaps_as_segments = gaps == "segments";
    source.apply(o.read);
    o.read.memory = memory_ceiling_of(max_memory);
    o.gyro_columns = gyro;
    o.accel_columns = accel;
    o.vertical_gyro = vertical_gyro;
    // A rate unit means rate samples; an angle (velocity) unit per-sample increments Δθ (Δv).
    if (gyro_unit == "arcsec" || gyro_unit == "deg" || gyro_unit == "rad")
      o.gyro_increment_unit = parse_angle_unit(gyro_unit);
    else if (!gyro_unit.empty())
      o.gyro_unit = parse_rate_unit(gyro_unit);
    if (accel_unit == "m/s")
      o.accel_increment_unit = AngleUnit::MetrePerSecond;
    else if (!accel_unit.empty())
      o.accel_unit = parse_rate_unit(accel_unit);
    // Each --output-unit belongs to the kind whose unit it is.
    for (const auto& u : shown_units) {
      try {
        (void)rwcalc::output_units(SensorKind::Gyro, u);
        o.gyro_output_unit = u;
      } catch (const UsageError&) {
        (void)rwcalc::output_units(SensorKind::Accelerometer, u);  // throws for a unit of neither kind
        o.accel_output_unit = u;
      }
    }
    o.analysis = analysis.options();
    require_valid(o);  // before the file is read
    return o;
  }

  /// The noise files' options; `discrete_wanted` for --noise-file (--kalibr and --report's imu.yaml
  /// are continuous). UsageError for --discrete with a format whose consumer takes continuous-time
  /// values only.
  [[nodiscard]] NoiseFileOptions noise_options(NoiseFormat format, bool discrete_wanted) const {
    NoiseFileOptions k;
    k.format = format;
    k.rostopic = rostopic;
    k.combine = combine == "mean" ? AxisCombination::Mean : AxisCombination::Worst;
    k.all_axes = keys_from_all_axes;
    k.inflate = inflate;
    k.discrete = discrete_wanted;
    require_valid(k);
    return k;
  }
};

/// The files of --report DIR, for the check of every output before the first is written. A
/// directory still to be made holds none of them yet: only that it can be made is checked.
std::vector<OutputTarget> report_targets(const std::string& dir) {
  namespace fs = std::filesystem;
  if (dir.empty()) return {};
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    fs::path parent = fs::absolute(dir).parent_path();
    while (!fs::exists(parent, ec) && parent.has_relative_path()) parent = parent.parent_path();
    if (!fs::is_directory(parent, ec) || ::access(parent.c_str(), W_OK | X_OK) != 0)
      throw OutputError(
          trf("{}: cannot create the report directory: {} is not a writable directory", dir, parent.string()));
    return {};
  }
  if (!fs::is_directory(dir, ec))
    throw OutputError(trf("{}: cannot create the report directory: {}", dir, tr("not a directory")));
  std::vector<OutputTarget> files;
  for (const char* name : {"imu.txt", "imu.json", "imu.yaml", "imu.svg", "index.html"})
    files.push_back({fmt::format("--report ({})", name), (fs::path(dir) / name).string()});
  return files;
}

// --report DIR: the tables as a page (index.html, in the test report's look, with the figure when
// gnuplot is there), the JSON, the noise file and the figure beside it, so that one directory holds
// the whole result.
void write_report(const std::string& dir, const ImuResult& res, const nlohmann::json& j, const NoiseFileOptions& k,
                  bool force, Io& io) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw OutputError(
        trf("{}: cannot create the report directory: {}", dir, ec ? ec.message() : std::string(tr("not a directory"))));
  const auto at = [&dir](const char* name) { return (fs::path(dir) / name).string(); };
  const std::string text = localize_numbers(format_imu(res));
  write_file_atomic(at("imu.txt"), text, force);
  write_file_atomic(at("imu.json"), j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", force);
  write_file_atomic(at("imu.yaml"), noise_file(res, k), force);
  ImuPageOptions page;
  try {
    PlotOptions o;
    o.output = at("imu.svg");
    o.force = force;
    plot_imu(j, o);
    page.figure = "imu.svg";
  } catch (const OutputError& e) {  // no gnuplot: the page without the figure
    print_message(io.err, trf("note: --report without the figure: {}", e.what()));
  }
  write_file_atomic(at("index.html"), imu_report_html(j, page), force);
  print_message(io.err, trf("report written to {}", as_typed(at("index.html"))));
}

// The noise files' options: where, for which program, and how the values are written.
void add_noise_file_options(CLI::App& sub, ImuCmd& cmd) {
  sub.add_option("--kalibr", cmd.kalibr,
                 tr("Write the Kalibr IMU noise file (imu.yaml: noise densities and random walks in SI); the same as "
                    "--noise-file PATH --noise-format kalibr"))
      ->check(output_name())
      ->group(tr("Output"));
  sub.add_option("--noise-file", cmd.noise_file,
                 tr("Write the IMU noise file for the program --noise-format names (noise densities and random "
                    "walks in SI)"))
      ->check(output_name())
      ->group(tr("Output"));
  sub.add_option("--noise-format", cmd.noise_format,
                 tr("The program the --noise-file is for: kalibr (imu.yaml), openvins (the imu0 block of "
                    "kalibr_imu_chain.yaml), vins-fusion (acc_n, gyr_n, acc_w, gyr_w, g_norm), orb-slam3 "
                    "(IMU.NoiseGyro ...); the last three in OpenCV's %YAML:1.0 form"))
      ->capture_default_str()
      ->group(tr("Output"));
  sub.add_option("--inflate", cmd.inflate,
                 tr("Multiply every value of the noise files by F (≥ 1) for effects the static recording does not "
                    "show; said in the file"))
      ->check(real_in(1.0, 1e6, ""))
      ->capture_default_str()
      ->group(tr("Output"));
  sub.add_flag("--discrete", cmd.discrete,
               tr("Discrete-time values in the --noise-file: N*sqrt(rate) and K/sqrt(rate) (vins-fusion only; the "
                  "other programs convert continuous values themselves)"))
      ->group(tr("Output"));
  sub.add_option("--rostopic", cmd.rostopic, tr("rostopic written into the noise files"))
      ->capture_default_str()
      ->group(tr("Output"));
  sub.add_option("--combine", cmd.combine,
                 tr("How the noise files combine the axes of a kind: worst (the largest) or mean"))
      ->check(CLI::IsMember({"worst", "mean"}))
      ->capture_default_str()
      ->group(tr("Output"));
  sub.add_flag("--keys-from-all-axes", cmd.keys_from_all_axes,
               tr("Let every axis into the noise files' keys (default: only axes with an accepted fit and a resolved "
                  "value; the others are named in the file's comments)"))
      ->group(tr("Output"));
}

int run_imu(ImuCmd& cmd, Io& io) {
  ImuOptions opt = cmd.options();
  opt.read.progress = opt.analysis.progress = io.progress;
  // Every output is checked before the work and before the first is written.
  if (!cmd.kalibr.empty() || !cmd.report_dir.empty() || !cmd.noise_file.empty()) (void)rostopic_scalar(cmd.rostopic);
  const NoiseFileOptions chosen = cmd.noise_options(parse_noise_format(cmd.noise_format), cmd.discrete);
  const NoiseFileOptions k = cmd.noise_options(NoiseFormat::Kalibr, false);
  std::vector<OutputTarget> targets = report_targets(cmd.report_dir);
  targets.insert(targets.begin(), {{"-o", cmd.output}, {"--kalibr", cmd.kalibr}, {"--noise-file", cmd.noise_file}});
  cmd.plot.check(cmd.force, targets);
  const ImuResult res = analyze_imu(cmd.file, opt);
  for (const auto& c : res.channels)
    print_input_notes(io.err, nlohmann::json{{"source", c.result.source}, {"input", c.result.input}});
  const nlohmann::json j = to_json(res);
  cli::require_finite(j, res.source);  // not another command's of the same name (unity build)
  cmd.plot.draw_imu(j, cmd.force, io);
  for (const auto& [path, o] : {std::pair{cmd.kalibr, k}, std::pair{cmd.noise_file, chosen}}) {
    if (path.empty()) continue;
    write_file_atomic(path, noise_file(res, o), cmd.force);
    print_message(io.err, trf("noise file written to {}", as_typed(path)));
  }
  if (!cmd.report_dir.empty()) write_report(cmd.report_dir, res, j, k, cmd.force, io);
  emit(io,
       cmd.json ? j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n"
                : localize_numbers(format_imu(res)),
       cmd.output, cmd.force);
  return 0;
}

}  // namespace

void register_imu(CLI::App& app, Runner& runner) {
  auto cmd = std::make_shared<ImuCmd>();
  auto* sub = app.add_subcommand(
      "imu", tr("A whole IMU from one static recording: every gyro and accelerometer column's noise coefficients with "
                "95 % intervals, one table per sensor kind, and the noise file for Kalibr, OpenVINS, VINS-Fusion or "
                "ORB-SLAM3"));
  sub->add_option("FILE", cmd->file, tr("Recording with one column per axis ('-' for standard input)"))->required();
  sub->add_option("--rate", cmd->rate_hz, tr("Sample rate, Hz (else metadata rate_hz or a time column)"))
      ->check(real_in(kMinRateHz, kMaxRateHz, "Hz"))
      ->group(tr("Input"));
  sub->add_option("--time-tolerance", cmd->time_tolerance,
                  tr("Time-column steps off the sample period by more than this fraction of it are reported as jitter"))
      ->check(real_in(0.0, 0.5, ""))
      ->capture_default_str()
      ->group(tr("Input"));
  add_gaps_option(*sub, cmd->gaps);
  add_memory_option(*sub, cmd->max_memory);
  cmd->source.add_to(*sub);
  sub->add_option("--gyro", cmd->gyro, tr("Gyro columns: header names or 1-based indices, comma-separated"))
      ->delimiter(',')
      ->group(tr("Input"));
  sub->add_option("--gyro-unit", cmd->gyro_unit,
                  tr("Unit of the gyro columns: deg/h, deg/s, rad/s for rates; arcsec, deg, rad for per-sample angle "
                     "increments (delta theta). Default: each name's suffix (_dps, _rads ...)"))
      ->group(tr("Input"));
  sub->add_option("--vertical-gyro", cmd->vertical_gyro,
                  tr("The gyro column whose axis is vertical: the vertical Earth rate is subtracted from it and the "
                     "class verdict given (default: none, unless the input is pulses)"))
      ->group(tr("Input"));
  sub->add_option("--accel", cmd->accel, tr("Accelerometer columns: header names or 1-based indices, comma-separated"))
      ->delimiter(',')
      ->group(tr("Input"));
  sub->add_option(
         "--accel-unit", cmd->accel_unit,
         tr("Unit of the accelerometer columns: m/s^2, g, mg, ug for accelerations; m/s for per-sample velocity "
            "increments (delta v). Default: each name's suffix (_g, _mps2 ...)"))
      ->group(tr("Input"));
  sub->add_option(
         "--output-unit", cmd->shown_units,
         tr("Units the results are shown in, one per sensor kind: deg/h, deg/s, rad/s (gyro); m/s^2, g, mg, ug "
            "(accelerometer). Default: °/h with N in °/√h; µg with N in m/s/√h"))
      ->delimiter(',')
      ->group(tr("Output"));
  cmd->analysis.add_to(*sub);
  sub->add_flag("--json", cmd->json, tr("Print the JSON object instead of the tables"))->group(tr("Output"));
  add_noise_file_options(*sub, *cmd);
  sub->add_option("--report", cmd->report_dir,
                  tr("Write the whole result into DIR: index.html (tables and figure), imu.txt, imu.json, imu.yaml, "
                     "imu.svg (created when missing)"))
      ->check(output_name())
      ->group(tr("Output"));
  add_output_options(*sub, cmd->output, cmd->force);
  cmd->plot.add_to(*sub, N_("one panel per sensor kind with every axis' Allan deviation and its confidence bars"));
  sub->callback([cmd, &runner] { runner = [cmd](Io& io) { return run_imu(*cmd, io); }; });
}

}  // namespace rwcalc::cli
