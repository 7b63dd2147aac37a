// 'rwcalc allan FILE': the Allan deviation table of a recording, with noise type, EDF and
// confidence bounds per τ, as text, CSV or JSON.
#include <fmt/format.h>

#include <cmath>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>

#include "analyze_args.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/allan_report.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/segments.hpp"

namespace rwcalc::cli {

namespace {

struct AllanArgs {
  std::string file;
  InputArgs input;
  std::string estimator = "oadev";
  std::string tau = "octave";
  double confidence = 0.683;
  bool json = false;
  bool csv = false;
  std::string outliers = "keep";
  double outlier_threshold = kDefaultOutlierThreshold;
};

// The JSON of a result, written straight into one string: the same document as
// nlohmann::json::dump(2) of to_json() plus the header keys (keys in the same sorted order), without
// building a tree — a million-point `--tau all` result would otherwise take gigabytes and seconds.
void append_number(std::string& out, double v) {
  const std::size_t at = out.size();
  fmt::format_to(std::back_inserter(out), "{}", v);
  if (out.find_first_of(".e", at) == std::string::npos) out += ".0";
}

// A JSON value one level in, as dump(2) writes a nested object.
std::string nested(const nlohmann::json& j) {
  std::string s = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  for (std::size_t at = s.find('\n'); at != std::string::npos; at = s.find('\n', at + 3)) s.replace(at, 1, "\n  ");
  return s;
}

std::string allan_json_text(const AllanResult& r, const Recording& rec, const Recording& read,
                            const OutlierReport& outliers) {
  std::string out;
  out.reserve(256 + r.points.size() * 260);
  out += "{\n";
  out += fmt::format("  \"confidence\": ");
  append_number(out, r.confidence);
  out += ",\n";
  out += fmt::format(
      "  \"convention\": {},\n",
      nlohmann::json(r.unit == "deg/h" ? "1 arcsec/s = 1 deg/h" : "deviation in input units per second").dump());
  out += fmt::format("  \"estimator\": {},\n", nlohmann::json(std::string(to_string(r.estimator))).dump());
  if (r.fft_from_m > 0) out += fmt::format("  \"fft_from_af\": {},\n", r.fft_from_m);
  out += "  \"input\": " + nested(input_json(read)) + ",\n";
  out += "  \"outliers\": " + nested(to_json(outliers)) + ",\n";
  out += fmt::format("  \"phase_points\": {},\n", r.points_in);
  out += r.points.empty() ? "  \"points\": []" : "  \"points\": [";
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const AllanPoint& p = r.points[i];
    out += i ? ",\n    {\n" : "\n    {\n";
    fmt::format_to(std::back_inserter(out), "      \"af\": {},\n      \"alpha\": {},\n      \"dev\": ", p.m, p.alpha);
    append_number(out, p.dev);
    out += ",\n      \"dev_high\": ";
    append_number(out, p.dev_high);
    out += ",\n      \"dev_low\": ";
    append_number(out, p.dev_low);
    out += ",\n      \"edf\": ";
    append_number(out, p.edf);
    fmt::format_to(std::back_inserter(out), ",\n      \"n\": {},\n      \"tau_s\": ", p.n);
    append_number(out, p.tau_s);
    out += "\n    }";
  }
  if (!r.points.empty()) out += "\n  ]";
  out += ",\n  \"rate_hz\": ";
  append_number(out, rec.rate_hz);
  out += fmt::format(",\n  \"samples\": {},\n  \"schema_version\": {},\n  \"source\": {},\n  \"tau0_s\": ", rec.samples,
                     json_input::kResultSchemaVersion,
                     nlohmann::json(rec.source).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  append_number(out, r.tau0_s);
  out += fmt::format(",\n  \"unit\": {}\n}}\n", nlohmann::json(r.unit).dump());
  return out;
}

/// No output holds a non-finite number (JSON has none, and "inf" is no result): a value that
/// overflowed is an error that names it.
void require_finite(const AllanResult& r, const Recording& rec) {
  auto check = [&](const char* what, double v, double tau) {
    if (!std::isfinite(v))
      throw AnalysisError(
          trf("{}: the {} at tau = {:g} s is {} (the record's numbers overflow a double); "
              "nothing was printed",
              rec.source, what, tau, v));
  };
  check("sample period tau0", r.tau0_s, r.tau0_s);
  for (const AllanPoint& p : r.points) {
    check("tau", p.tau_s, p.tau_s);
    check("deviation", p.dev, p.tau_s);
    check("lower bound", p.dev_low, p.tau_s);
    check("upper bound", p.dev_high, p.tau_s);
    check("EDF", p.edf, p.tau_s);
  }
}

int run_allan(const AllanArgs& a, Io& io) {
  AllanOptions o;
  o.estimator = parse_estimator(a.estimator);
  o.grid = TauGrid::parse(a.tau);
  o.confidence = a.confidence;
  o.progress = io.progress;
  const OutlierAction outlier_action = parse_outlier_action(a.outliers);
  ReadOptions read_options = a.input.options();
  read_options.progress = io.progress;
  const Recording read = read_recording(a.file, read_options);
  print_input_notes(io.err, read);
  // Outliers are looked for, reported and dealt with as by analyze (--outliers).
  OutlierReport outliers;
  Recording edited;
  const Recording& rec = screen_outliers(read, outlier_action, a.outlier_threshold, outliers, edited);
  // Increment and rate samples are frequency data for the noise identification, as Stable32
  // treats a frequency file; cumulative counters and angles are phase data.
  o.noise_id_domain = (rec.mode == InputMode::Pulses || rec.mode == InputMode::Rate || rec.mode == InputMode::Increment)
                          ? NoiseIdDomain::Frequency
                          : NoiseIdDomain::Phase;
  // A record split at its gaps (--gaps segments): every τ pools the segments' terms.
  const AllanResult res = allan_of_record(rec, o);
  if (rec.segments.size() > 1)
    print_message(io.err, trf("{}: {} segments (split at the time column's gaps by --gaps segments); the Allan "
                              "variance pools them: no difference spans a gap",
                              as_typed(rec.source), rec.segments.size()));
  require_finite(res, rec);
  // Where fewer than 10 averages of τ fit in the record, Stable32's noise identification (the B1 ratio,
  // taken for the number of terms as Stable32 does) and the EDF that follows are weak: said on stderr,
  // so the table stays Stable32's.
  for (const auto& p : res.points)
    if ((rec.phase.points() - 1) / static_cast<std::size_t>(p.m) < 10) {
      print_message(io.err, trf("note: {}: from tau = {:g} s on fewer than 10 averages remain; the noise type and "
                                "the bounds there rest on few data ('rwcalc analyze' takes them from the fitted model)",
                                as_typed(rec.source), p.tau_s));
      break;
    }
  if (a.json) {
    io.out << allan_json_text(res, rec, read, outliers);
  } else if (a.csv) {
    io.out << format_allan_csv(res);
    // The CSV holds the table only; the outliers found are said on standard error.
    if (outliers.count > 0) print_message(io.err, trf("note: {}: {}", as_typed(rec.source), format_outliers(outliers)));
  } else {
    io.out << localize_numbers(
        format_allan_table(res, {rec.source, rec.samples, rec.rate_hz, std::string(to_string(rec.rate_source)),
                                 describe_input(read)}));
    io.out << "\n" << localize_numbers(format_outliers(outliers));
  }
  return 0;
}

}  // namespace

void register_allan(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<AllanArgs>();
  auto* sub = app.add_subcommand(
      "allan", tr("Allan deviation of a recording per τ, with noise type α, equivalent degrees of freedom and\n"
                  "χ² confidence bounds (Stable32 conventions). Deviations in °/h for gyro input (1″/s = 1 °/h),\n"
                  "in input units per second for clock data."));
  sub->add_option("FILE", args->file, tr("Recording to read ('-' for standard input; .gz accepted)"))->required();
  args->input.add_to(*sub);
  sub->add_option("--estimator", args->estimator,
                  tr("oadev (fully overlapping Allan, default), adev (non-overlapping), mdev (modified), "
                     "ohdev (overlapping Hadamard) or hdev (non-overlapping Hadamard)"))
      ->option_text("oadev|adev|mdev|ohdev|hdev")
      ->capture_default_str();
  sub->add_option("--tau", args->tau,
                  tr("τ grid: octave, decade (1,2,4 per decade), dense[:P] (P per decade), all, or a list of "
                     "seconds such as 0.01,1,10 (each a whole number of samples)"))
      ->capture_default_str();
  sub->add_option("--confidence", args->confidence, tr("Two-sided confidence of the bounds (0..1)"))
      ->check(real_in(0.0, 1.0, "", Ends::Open))
      ->capture_default_str();
  add_outlier_options(*sub, args->outliers, args->outlier_threshold);
  auto* json = sub->add_flag("--json", args->json, tr("Print JSON instead of the table"));
  auto* csv = sub->add_flag("--csv", args->csv, tr("Print CSV instead of the table"));
  json->excludes(csv);
  sub->callback([&runner, args] { runner = [args](Io& io) { return run_allan(*args, io); }; });
}

}  // namespace rwcalc::cli
