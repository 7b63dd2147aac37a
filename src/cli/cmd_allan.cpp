// 'rwcalc allan FILE': the Allan deviation table of a recording, with noise type, EDF and
// confidence bounds per τ, as text, CSV or JSON.
#include <fmt/format.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>

#include "cli/commands.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"

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
  unsigned threads = 0;
};

int run_allan(const AllanArgs& a, Io& io) {
  AllanOptions o;
  o.estimator = parse_estimator(a.estimator);
  o.grid = TauGrid::parse(a.tau);
  o.confidence = a.confidence;
  o.threads = a.threads;
  const ReadOptions ro = a.input.options();
  const Recording rec = read_recording(a.file, ro);
  // Increment and rate samples are frequency data for the noise identification, as Stable32
  // treats a frequency file; cumulative counters and angles are phase data.
  o.noise_id_domain = (rec.mode == InputMode::Pulses || rec.mode == InputMode::Rate) ? NoiseIdDomain::Frequency
                                                                                      : NoiseIdDomain::Phase;
  const AllanResult res = compute_allan(rec.phase, o);
  if (a.json) {
    nlohmann::json j = to_json(res);
    j["source"] = rec.source;
    j["samples"] = rec.samples;
    j["rate_hz"] = rec.rate_hz;
    j["convention"] = res.unit == "deg/h" ? "1 arcsec/s = 1 deg/h" : "deviation in input units per second";
    io.out << j.dump(2) << "\n";
  } else if (a.csv) {
    io.out << format_allan_csv(res);
  } else {
    io.out << format_allan_table(res, {rec.source, rec.samples, rec.rate_hz, std::string(to_string(rec.rate_source))});
  }
  return 0;
}

}  // namespace

void register_allan(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<AllanArgs>();
  auto* sub = app.add_subcommand(
      "allan",
      "Allan deviation of a recording per τ, with noise type α, equivalent degrees of freedom and\n"
      "χ² confidence bounds (Stable32 conventions). Deviations in °/h for gyro input (1″/s = 1 °/h),\n"
      "in input units per second for clock data.");
  sub->add_option("FILE", args->file, "Recording to read ('-' for standard input; .gz accepted)")->required();
  args->input.add_to(*sub);
  sub->add_option("--estimator", args->estimator,
                  "oadev (fully overlapping Allan, default), adev (non-overlapping) or mdev (modified)")
      ->capture_default_str();
  sub->add_option("--tau", args->tau,
                  "τ grid: octave, decade (1,2,4 per decade), dense[:P] (P per decade), all, or a list of "
                  "seconds such as 0.01,1,10 (each a whole number of samples)")
      ->capture_default_str();
  sub->add_option("--confidence", args->confidence, "Two-sided confidence of the bounds (0..1)")
      ->capture_default_str();
  sub->add_option("--threads", args->threads, "Worker threads across τ (0: all cores)")->capture_default_str();
  auto* json = sub->add_flag("--json", args->json, "Print JSON instead of the table");
  auto* csv = sub->add_flag("--csv", args->csv, "Print CSV instead of the table");
  json->excludes(csv);
  sub->callback([&runner, args] { runner = [args](Io& io) { return run_allan(*args, io); }; });
}

}  // namespace rwcalc::cli
