// Every rule of every options struct's validate() (validate.hpp): each broken alone on default
// options, its message asserted; the defaults keep every rule; and each library entry point refuses
// broken options with the same message before it does any work.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/imu.hpp"
#include "rwcalc/imu_report.hpp"
#include "rwcalc/imu_simulate.hpp"
#include "rwcalc/methods.hpp"
#include "rwcalc/noise_model.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/report.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/verdict.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// One rule: the options broken in that rule alone, and the message it must give.
struct Rule {
  const char* name;
  std::function<Violation()> broken;
  const char* message;
};

/// The violation of `T` default-constructed and then changed by `change`.
template <class T>
std::function<Violation()> with(std::function<void(T&)> change) {
  return [change] {
    T o;
    change(o);
    return o.validate();
  };
}

const std::vector<Rule>& rules() {
  static const std::vector<Rule> r{
      // AllanOptions
      {"AllanConfidence", with<AllanOptions>([](auto& o) { o.confidence = 1; }),
       "--confidence must be a finite number in (0, 1), got 1"},
      {"AllanAlpha", with<AllanOptions>([](auto& o) { o.noise_id = false, o.alpha = 3; }),
       "AllanOptions::alpha must be a finite number in [-2, 2], got 3"},
      {"AllanDensePerDecade",
       with<AllanOptions>([](auto& o) { o.grid.kind = TauGrid::Kind::Dense, o.grid.per_decade = 0; }),
       "--tau dense:P must be a finite number in [1, 1000], got 0"},
      {"AllanExplicitListEmpty", with<AllanOptions>([](auto& o) { o.grid.kind = TauGrid::Kind::Explicit; }),
       "--tau: the list of tau holds no value"},
      {"AllanExplicitTauPositive", with<AllanOptions>([](auto& o) {
         o.grid.kind = TauGrid::Kind::Explicit, o.grid.taus_s = {1, -1};
       }),
       "--tau must be a finite number in (0, inf) s, got -1"},
      {"AllanMaxM", with<AllanOptions>([](auto& o) { o.grid.max_m = -1; }),
       "TauGrid::max_m must be 0 (no cap) or a positive cluster size, got -1"},
      // FitOptions
      {"FitTauMin", with<FitOptions>([](auto& o) { o.tau_min_s = -1; }),
       "--fit-range TMIN must be a finite number in [0, inf) s, got -1"},
      {"FitTauMaxAboveTauMin", with<FitOptions>([](auto& o) { o.tau_min_s = 10, o.tau_max_s = 5; }),
       "--fit-range: TMAX (5 s) must be above TMIN (10 s)"},
      {"FitSomeTerm", with<FitOptions>([](auto& o) {
         o.enabled = {false, false, false, false, false};
       }),
       "--terms: give at least one of Q, N, B, K, R"},
      {"FitMinEdf", with<FitOptions>([](auto& o) { o.min_edf = -1; }),
       "--min-edf must be a finite number in [0, inf), got -1"},
      {"FitEdfCap", with<FitOptions>([](auto& o) { o.edf_cap = kNaN; }),
       "FitOptions::edf_cap must be a finite number in [0, inf), got nan"},
      {"FitConfidence", with<FitOptions>([](auto& o) { o.confidence = 1.5; }),
       "FitOptions::confidence must be a finite number in (0, 1), got 1.5"},
      {"FitDispersion", with<FitOptions>([](auto& o) { o.dispersion = 0; }),
       "FitOptions::dispersion must be a finite number in (0, inf), got 0"},
      {"FitEdfInflation", with<FitOptions>([](auto& o) { o.edf_inflation = -1; }),
       "FitOptions::edf_inflation must be a finite number in [0, inf), got -1"},
      {"FitMaxIterations", with<FitOptions>([](auto& o) { o.max_iterations = 0; }),
       "FitOptions::max_iterations must be a finite number in [1, 1e+06], got 0"},
      {"FitCounterPulseWeight", with<FitOptions>([](auto& o) {
         o.counter = CounterReadout{1, 0, 0.0025, 100};
       }),
       "--scale must be a finite number in (0, inf) arcsec, got 0"},
      {"FitCounterSamplePeriod", with<FitOptions>([](auto& o) {
         o.counter = CounterReadout{1, 0.92, 0, 100};
       }),
       "CounterReadout::tau0_s must be a finite number in (0, inf) s, got 0"},
      // MethodOptions
      {"DirectTmin", with<MethodOptions>([](auto& o) { o.direct_t_min_s = 0; }),
       "--direct-range TMIN must be a finite number in (0, inf) s, got 0"},
      {"DirectTmaxAboveTmin", with<MethodOptions>([](auto& o) { o.direct_t_min_s = 10, o.direct_t_max_s = 5; }),
       "--direct-range: TMAX (5 s) must be finite and above TMIN (10 s)"},
      {"DirectPoints", with<MethodOptions>([](auto& o) { o.direct_points = 3; }),
       "MethodOptions::direct_points must be a finite number in [4, 1000], got 3"},
      {"BootstrapReplicates", with<MethodOptions>([](auto& o) { o.bootstrap_replicates = -1; }),
       "MethodOptions::bootstrap_replicates must be a finite number in [0, 1e+06], got -1"},
      {"Block", with<MethodOptions>([](auto& o) { o.block_s = 0; }),
       "--block must be a finite number in (0, 1e+09] s, got 0"},
      // VerdictOptions
      {"ClassTableNotEmpty", with<VerdictOptions>([](auto& o) { o.table.classes.clear(); }),
       "--limits: the class table lists no class"},
      {"Tolerance", with<VerdictOptions>([](auto& o) { o.tolerance_pct = 1001; }),
       "--tolerance must be a finite number in [0, 1000] %, got 1001"},
      {"Decisive", with<VerdictOptions>([](auto& o) { o.decisive = 0; }),
       "VerdictOptions::decisive must be a finite number in (0, 1], got 0"},
      // AnalysisOptions
      {"AnalysisStagesOptions", with<AnalysisOptions>([](auto& o) { o.fit.confidence = 2; }),
       "FitOptions::confidence must be a finite number in (0, 1), got 2"},
      {"AnalysisNandB", with<AnalysisOptions>([](auto& o) { o.fit.enabled[static_cast<int>(Term::B)] = false; }),
       "--terms must include N and B (the verdict needs both)"},
      {"Latitude", with<AnalysisOptions>([](auto& o) { o.latitude_deg = 91; }),
       "--latitude must be a finite number in [-90, 90] deg, got 91"},
      {"EarthRate", with<AnalysisOptions>([](auto& o) { o.earth_rate_deg_per_h = kInf; }),
       "--earth-rate must be a finite number in [-1e+09, 1e+09] deg/h, got inf"},
      {"Temperature", with<AnalysisOptions>([](auto& o) { o.temperature_c = -300; }),
       "--temperature must be a finite number in [-273.15, 1000] deg C, got -300"},
      {"OutlierThreshold", with<AnalysisOptions>([](auto& o) { o.outlier_threshold = 2; }),
       "--outlier-threshold must be a finite number in [3, 1e+06] robust sigma, got 2"},
      // ReadOptions
      {"ReadRate", with<ReadOptions>([](auto& o) { o.rate_hz = 0; }),
       "--rate must be a finite number in [1e-09, 1e+09] Hz, got 0"},
      {"ReadScale", with<ReadOptions>([](auto& o) { o.scale_arcsec = kNaN; }),
       "--scale must be a finite number in [1e-09, 1e+09] arcsec, got nan"},
      {"ReadCounterBits", with<ReadOptions>([](auto& o) { o.counter_bits = 65; }),
       "--counter-bits must be a finite number in [1, 64], got 65"},
      {"ReadTimeTolerance", with<ReadOptions>([](auto& o) { o.time_tolerance = 0.6; }),
       "--time-tolerance must be a finite number in [0, 0.5], got 0.6"},
      // ImuOptions, NoiseFileOptions
      {"ImuReadOptions", with<ImuOptions>([](auto& o) { o.read.counter_bits = 0; }),
       "--counter-bits must be a finite number in [1, 64], got 0"},
      {"ImuAnalysisOptions", with<ImuOptions>([](auto& o) { o.analysis.latitude_deg = -91; }),
       "--latitude must be a finite number in [-90, 90] deg, got -91"},
      {"ImuVerticalGyro", with<ImuOptions>([](auto& o) { o.gyro_columns = {"gx"}, o.vertical_gyro = "gz"; }),
       "--vertical-gyro gz: not one of the --gyro columns"},
      {"ImuGyroUnit", with<ImuOptions>([](auto& o) { o.gyro_unit = RateUnit::G; }),
       "--gyro-unit g is not a gyro unit: expected deg/h, deg/s, rad/s (rates) or arcsec, deg, rad (increments)"},
      {"ImuAccelUnit", with<ImuOptions>([](auto& o) { o.accel_unit = RateUnit::DegPerSecond; }),
       "--accel-unit deg/s is not an accelerometer unit: expected m/s^2, g, mg, ug (rates) or m/s (increments)"},
      {"NoiseFileInflate", with<NoiseFileOptions>([](auto& o) { o.inflate = 0.5; }),
       "--inflate must be a finite number in [1, 1e+06], got 0.5"},
      {"NoiseFileDiscrete", with<NoiseFileOptions>([](auto& o) { o.discrete = true; }),
       "--discrete: this --noise-format takes continuous-time values only (its reader converts them); --discrete is "
       "for vins-fusion"},
      // DiagnoseOptions
      {"DiagnoseAnalysisOptions", with<DiagnoseOptions>([](auto& o) { o.analysis.verdict.tolerance_pct = -1; }),
       "--tolerance must be a finite number in [0, 1000] %, got -1"},
      {"DiagnoseRuns", with<DiagnoseOptions>([](auto& o) { o.runs = 5; }),
       "--runs must be a finite number in [10, 100000], got 5"},
      {"DiagnoseBandLevel", with<DiagnoseOptions>([](auto& o) { o.band_level = 1; }),
       "DiagnoseOptions::band_level must be a finite number in (0, 1), got 1"},
      {"DiagnoseFalseAlarm", with<DiagnoseOptions>([](auto& o) { o.alpha = 0.5; }),
       "--false-alarm must be a finite number in [1e-06, 0.2], got 0.5"},
      // PlotOptions, ReportOptions, ImuPageOptions
      {"PlotWidth", with<PlotOptions>([](auto& o) { o.width_px = 100; }),
       "PlotOptions::width_px must be a finite number in [200, 8000] px, got 100"},
      {"PlotHeight", with<PlotOptions>([](auto& o) { o.height_px = 20000; }),
       "PlotOptions::height_px must be a finite number in [150, 16000] px, got 20000"},
      {"PlotFormat", with<PlotOptions>([](auto& o) { o.output = "fig.bmp"; }),
       "fig.bmp: unknown figure format '.bmp'; name the file .svg, .png or .pdf"},
      {"ReportTitle", with<ReportOptions>([](auto& o) { o.title.clear(); }),
       "ReportOptions::title is empty: the report needs a title"},
      {"ReportProtocolDate", with<ReportOptions>([](auto& o) {
         o.profile = LabProfile{}, o.protocol_date = {2026, 2, 29};
       }),
       "ReportOptions::protocol_date 2026-02-29 is not a calendar date (a protocol needs its date)"},
      {"ImuPageFiles", with<ImuPageOptions>([](auto& o) { o.json_file.clear(); }),
       "ImuPageOptions: the noise, JSON and text files beside the page need names"},
      // SimulationSettings
      {"SimDuration", with<SimulationSettings>([](auto& o) { o.duration_s = 0; }),
       "duration_s must be a finite number in (0, inf), got 0"},
      {"SimRate", with<SimulationSettings>([](auto& o) { o.rate_hz = -1; }),
       "rate_hz must be a finite number in (0, inf), got -1"},
      {"SimScale", with<SimulationSettings>([](auto& o) { o.scale_arcsec = kInf; }),
       "scale_arcsec must be a finite number in (0, inf), got inf"},
      {"SimTemperature", with<SimulationSettings>([](auto& o) { o.temperature_c = kNaN; }),
       "temperature_c must be a finite number in (-inf, inf), got nan"},
      {"SimTwoSamples", with<SimulationSettings>([](auto& o) { o.duration_s = 1, o.rate_hz = 1; }),
       "the record must hold at least 2 samples (duration 1 s at 1 Hz)"},
      {"SimNotTooLong", with<SimulationSettings>([](auto& o) { o.duration_s = 1e7, o.rate_hz = 1e3; }),
       "the record is too long (more than 2^31 samples)"},
      // NoiseModel
      {"ModelArw", with<NoiseModel>([](auto& o) { o.arw_deg_per_sqrt_h = -1; }),
       "arw_deg_per_sqrt_h must be a finite number in [0, inf), got -1"},
      {"ModelBiasInstability", with<NoiseModel>([](auto& o) { o.bias_instability_deg_per_h = -1; }),
       "bias_instability_deg_per_h must be a finite number in [0, inf), got -1"},
      {"ModelRrw", with<NoiseModel>([](auto& o) { o.rrw_deg_per_h_per_sqrt_h = kNaN; }),
       "rrw_deg_per_h_per_sqrt_h must be a finite number in [0, inf), got nan"},
      {"ModelRamp", with<NoiseModel>([](auto& o) { o.ramp_deg_per_h2 = kInf; }),
       "ramp_deg_per_h2 must be a finite number in (-inf, inf), got inf"},
      {"ModelBias", with<NoiseModel>([](auto& o) { o.bias_deg_per_h = kNaN; }),
       "bias_deg_per_h must be a finite number in (-inf, inf), got nan"},
      {"ModelEarthRate", with<NoiseModel>([](auto& o) { o.earth_rate_deg_per_h = -kInf; }),
       "earth_rate_deg_per_h must be a finite number in (-inf, inf), got -inf"},
      {"ModelWhiteAngle", with<NoiseModel>([](auto& o) { o.white_angle_arcsec = -1; }),
       "white_angle_arcsec must be a finite number in [0, inf), got -1"},
      {"ModelLowpass", with<NoiseModel>([](auto& o) { o.lowpass_tc_s = -1; }),
       "lowpass_tc_s must be a finite number in [0, inf), got -1"},
      {"ModelOutputLowpass", with<NoiseModel>([](auto& o) { o.output_lowpass_tc_s = -1; }),
       "output_lowpass_tc_s must be a finite number in [0, inf), got -1"},
      {"ModelSinusoidFrequency", with<NoiseModel>([](auto& o) {
         o.sinusoids = {{0, 1, 0}};
       }),
       "sinusoid frequency_hz must be a finite number in (0, inf), got 0"},
      {"ModelSinusoidAmplitude", with<NoiseModel>([](auto& o) {
         o.sinusoids = {{1, kInf, 0}};
       }),
       "sinusoid amplitude_deg_per_h must be a finite number in (-inf, inf), got inf"},
      {"ModelSinusoidPhase", with<NoiseModel>([](auto& o) {
         o.sinusoids = {{1, 1, kNaN}};
       }),
       "sinusoid phase_rad must be a finite number in (-inf, inf), got nan"},
      {"ModelGaussMarkovSigma", with<NoiseModel>([](auto& o) {
         o.gauss_markov = {{-1, 1}};
       }),
       "gauss_markov sigma_deg_per_h must be a finite number in [0, inf), got -1"},
      {"ModelGaussMarkovTime", with<NoiseModel>([](auto& o) {
         o.gauss_markov = {{1, 0}};
       }),
       "gauss_markov correlation_time_s must be a finite number in (0, inf), got 0"},
      {"ModelBiasStepTime", with<NoiseModel>([](auto& o) {
         o.bias_steps = {{-1, 1}};
       }),
       "bias_step time_s must be a finite number in [0, inf), got -1"},
      {"ModelBiasStepSize", with<NoiseModel>([](auto& o) {
         o.bias_steps = {{1, kNaN}};
       }),
       "bias_step size_deg_per_h must be a finite number in (-inf, inf), got nan"},
      {"ModelWarmupAmplitude", with<NoiseModel>([](auto& o) {
         o.warmups = {{kNaN, 1}};
       }),
       "warmup amplitude_deg_per_h must be a finite number in (-inf, inf), got nan"},
      {"ModelWarmupTime", with<NoiseModel>([](auto& o) {
         o.warmups = {{1, 0}};
       }),
       "warmup time_constant_s must be a finite number in (0, inf), got 0"},
      {"ModelTemperatureCoefficient", with<NoiseModel>([](auto& o) {
         o.temperature_bias = TemperatureBias{kNaN, {TemperatureProfile::Kind::Ramp, 0, 1, 0, 0}};
       }),
       "temperature_bias coefficient_deg_per_h_per_c must be a finite number in (-inf, inf), got nan"},
      {"ModelTemperatureStart", with<NoiseModel>([](auto& o) {
         o.temperature_bias = TemperatureBias{1, {TemperatureProfile::Kind::Ramp, kNaN, 1, 0, 0}};
       }),
       "temperature profile start_c must be a finite number in (-inf, inf), got nan"},
      {"ModelTemperatureEnd", with<NoiseModel>([](auto& o) {
         o.temperature_bias = TemperatureBias{1, {TemperatureProfile::Kind::Ramp, 0, kInf, 0, 0}};
       }),
       "temperature profile end_c must be a finite number in (-inf, inf), got inf"},
      {"ModelTemperatureAmplitude", with<NoiseModel>([](auto& o) {
         o.temperature_bias = TemperatureBias{1, {TemperatureProfile::Kind::Cycle, 0, 0, kNaN, 10}};
       }),
       "temperature profile amp_c must be a finite number in (-inf, inf), got nan"},
      {"ModelTemperaturePeriod", with<NoiseModel>([](auto& o) {
         o.temperature_bias = TemperatureBias{1, {TemperatureProfile::Kind::Cycle, 0, 0, 1, 0}};
       }),
       "temperature profile period_s must be a finite number in (0, inf), got 0"},
      // ImuLayout
      {"ImuLayoutNoise", with<ImuLayout>([](auto& o) { o.accel[2].k = -1; }),
       "the IMU layout's noise terms must be finite and >= 0"},
      {"ImuLayoutSteps", with<ImuLayout>([](auto& o) { o.gyro_lsb_dps = 0; }),
       "the IMU layout's output steps must be finite and > 0"},
  };
  return r;
}

class OptionRule : public ::testing::TestWithParam<Rule> {};

TEST_P(OptionRule, IsBrokenAloneAndSaysSo) {
  const Violation v = GetParam().broken();
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(*v, GetParam().message);
}

INSTANTIATE_TEST_SUITE_P(Every, OptionRule, ::testing::ValuesIn(rules()),
                         [](const ::testing::TestParamInfo<Rule>& rule) { return std::string(rule.param.name); });

TEST(OptionRules, DefaultsKeepEveryRule) {
  EXPECT_EQ(AllanOptions{}.validate(), std::nullopt);
  EXPECT_EQ(FitOptions{}.validate(), std::nullopt);
  EXPECT_EQ(MethodOptions{}.validate(), std::nullopt);
  EXPECT_EQ(VerdictOptions{}.validate(), std::nullopt);
  EXPECT_EQ(AnalysisOptions{}.validate(), std::nullopt);
  EXPECT_EQ(ReadOptions{}.validate(), std::nullopt);
  EXPECT_EQ(ImuOptions{}.validate(), std::nullopt);
  EXPECT_EQ(NoiseFileOptions{}.validate(), std::nullopt);
  EXPECT_EQ(DiagnoseOptions{}.validate(), std::nullopt);
  EXPECT_EQ(PlotOptions{}.validate(), std::nullopt);
  EXPECT_EQ(ReportOptions{}.validate(), std::nullopt);
  EXPECT_EQ(ImuPageOptions{}.validate(), std::nullopt);
  EXPECT_EQ(SimulationSettings{}.validate(), std::nullopt);
  EXPECT_EQ(NoiseModel{}.validate(), std::nullopt);
  EXPECT_EQ(adis16405_like_layout().validate(), std::nullopt);
  // Open ends and infinities the rules allow: no upper end of the fit range, an unlimited EDF cap.
  FitOptions open;
  open.tau_max_s = kInf;
  open.edf_cap = 0;
  EXPECT_EQ(open.validate(), std::nullopt);
}

/// The message `call` throws as a UsageError ("" when it throws none).
std::string refusal(const std::function<void()>& call) {
  try {
    call();
  } catch (const UsageError& e) {
    return e.what();
  }
  return {};
}

/// A short white-rate record (400 Hz pulses).
PhaseSeries short_series() {
  PhaseSeries x;
  x.tau0_s = 0.0025;
  x.arcsec_per_count = 0.92;
  x.counts.push_back(0);
  for (int i = 0; i < 4000; ++i) x.counts.push_back(x.counts.back() + 5 + (i * 7919) % 3);
  return x;
}

TEST(OptionRules, EntryPointsRefuseAsValidateSays) {
  const PhaseSeries x = short_series();
  AllanOptions allan;
  allan.confidence = 0;
  EXPECT_EQ(refusal([&] { (void)compute_allan(x, allan); }), *allan.validate());

  FitOptions fit;
  fit.dispersion = 0;
  const std::vector<FitPoint> points{{1, 1, 100, 0, 0}, {2, 0.5, 100, 0, 0}, {4, 0.25, 100, 0, 0}};
  EXPECT_EQ(refusal([&] { (void)fit_noise(points, fit); }), *fit.validate());

  MethodOptions methods;
  methods.block_s = -1;
  EXPECT_EQ(refusal([&] { (void)direct_n(x, methods); }), *methods.validate());

  VerdictOptions verdict;
  verdict.tolerance_pct = kNaN;
  const EstimateInput estimate = lognormal_estimate(0.004, 0.001);
  EXPECT_EQ(refusal([&] { (void)decide(estimate, estimate, 0, verdict); }), *verdict.validate());

  Recording rec;
  rec.phase = x;
  rec.rate_hz = 400;
  AnalysisOptions analysis;
  analysis.latitude_deg = 100;
  EXPECT_EQ(refusal([&] { (void)analyze(rec, analysis); }), *analysis.validate());

  DiagnoseOptions diagnose_options;
  diagnose_options.band_level = 0;
  EXPECT_EQ(refusal([&] { (void)diagnose(rec, diagnose_options); }), *diagnose_options.validate());

  ImuOptions imu;
  imu.gyro_columns = {"gyro_x_dps"};
  imu.vertical_gyro = "gyro_z_dps";
  EXPECT_EQ(refusal([&] { (void)analyze_imu("no-such-file.csv", imu); }), *imu.validate());

  NoiseFileOptions noise;
  noise.inflate = 0;
  EXPECT_EQ(refusal([&] { (void)noise_file(ImuResult{}, noise); }), *noise.validate());

  PlotOptions plot;
  plot.width_px = 0;
  EXPECT_EQ(refusal([&] { (void)plot_analysis(nlohmann::json::object(), plot); }), *plot.validate());

  ReportOptions report;
  report.title.clear();
  EXPECT_EQ(refusal([&] { (void)report_html(ReportInput{}, report); }), *report.validate());
  const test::TempDir dir;
  EXPECT_EQ(refusal([&] { (void)write_report((dir.path() / "r").string(), ReportInput{}, report, false); }),
            *report.validate());
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "r"));  // refused before the directory is made

  ImuPageOptions page;
  page.noise_file.clear();
  EXPECT_EQ(refusal([&] { (void)imu_report_html(nlohmann::json::object(), page); }), *page.validate());

  ReadOptions read;
  read.time_tolerance = -1;
  const std::string path = (dir.path() / "p.csv").string();
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("pulses\n1\n2\n3\n", f);
    std::fclose(f);
  }
  EXPECT_EQ(refusal([&] { (void)read_recording(path, read); }), *read.validate());

  SimulationSettings settings;
  settings.rate_hz = 0;
  EXPECT_EQ(refusal([&] { (void)simulate(NoiseModel{}, settings); }), *settings.validate());
  NoiseModel model;
  model.arw_deg_per_sqrt_h = -1;
  EXPECT_EQ(refusal([&] { (void)simulate(model, SimulationSettings{}); }), *model.validate());

  ImuLayout layout = adis16405_like_layout();
  layout.accel_lsb_mg = kNaN;
  EXPECT_EQ(refusal(
                [&] { write_imu_record(layout, SimulationSettings{}, {}, (dir.path() / "imu.csv").string(), false); }),
            *layout.validate());
}

// The command line gives the library's refusal: a rule with no option check of its own (the order
// of --fit-range's ends, N and B in --terms) reaches the user as validate() words it, before any
// file is read.
TEST(OptionRules, CommandLineGivesTheLibrarysRefusal) {
  const auto order = test::run_cli({"analyze", "no-such-file.csv", "--fit-range", "10:5"});
  EXPECT_EQ(order.status, 2);
  EXPECT_NE(order.err.find("--fit-range: TMAX (5 s) must be above TMIN (10 s)"), std::string::npos) << order.err;
  const auto terms = test::run_cli({"analyze", "no-such-file.csv", "--terms", "QN"});
  EXPECT_EQ(terms.status, 2);
  EXPECT_NE(terms.err.find("--terms must include N and B (the verdict needs both)"), std::string::npos) << terms.err;
  const auto direct = test::run_cli({"analyze", "no-such-file.csv", "--direct-range", "0:10"});
  EXPECT_EQ(direct.status, 2);
  EXPECT_NE(direct.err.find("--direct-range TMIN must be a finite number in (0, inf) s, got 0"), std::string::npos)
      << direct.err;
}

}  // namespace
}  // namespace rwcalc
