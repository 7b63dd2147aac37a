// 'rwcalc report FILES… -o DIR': one self-contained HTML test report (DIR/report.html). FILES are
// recordings (analysed here) and/or saved results of 'analyze', 'batch' or 'diagnose --json', or
// the JSON lines of 'batch --jsonl'.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>

#include "analyze_args.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "rwcalc/batch.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/lab_profile.hpp"
#include "rwcalc/option_words.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/report.hpp"
#include "rwcalc/saved_results.hpp"

namespace rwcalc::cli {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

struct ReportCmd {
  std::vector<std::string> files;
  InputArgs input;
  AnalyzeArgs analysis;
  std::optional<double> temperature;
  std::string dir;
  std::string title;
  std::string lab;
  std::string gyro;
  std::string lab_profile;
  std::string protocol_number;
  bool pdf = false;
  bool docx = false;
  bool diagnose = false;
  std::size_t diagnose_runs = 50;
  std::uint64_t diagnose_seed = 1;
  bool no_figures = false;
  bool force = false;
};

/// The diagnoses of the recordings, one per file in file order: each recording is read again and
/// diagnosed as by `rwcalc diagnose FILE --runs K --seed N` with the report's analysis options.
std::vector<json> diagnose_recordings(const std::vector<std::string>& recordings, const ReadOptions& read,
                                      const AnalysisOptions& options, std::size_t runs, std::uint64_t seed,
                                      std::FILE* progress) {
  std::vector<json> out;
  out.reserve(recordings.size());
  for (const auto& f : recordings) {
    DiagnoseOptions d;
    d.analysis = options;
    d.runs = runs;
    d.seed = seed;
    out.push_back(to_json(diagnose_showing_progress(read_recording(f, read), d, progress)));
  }
  return out;
}

bool is_json_path(const std::string& path) {
  auto ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".json" || ext == ".jsonl";
}

std::string file_name(const json& j) {
  const auto it = j.find("source");
  return it != j.end() && it->is_string() ? fs::path(it->get<std::string>()).filename().string() : std::string();
}

/// Attach each saved diagnosis to the analysis with the same source (by file name), or to the
/// only run.
void attach_saved_diagnoses(const SavedResults& saved, const std::vector<json>& analyses,
                            std::vector<json>& diagnoses) {
  for (const auto& [d, path, line] : saved.diagnoses) {
    std::optional<std::size_t> target;
    const auto name = file_name(d);
    for (std::size_t i = 0; i < analyses.size() && !name.empty(); ++i)
      if (file_name(analyses[i]) == name) {
        target = i;
        break;
      }
    if (!target && analyses.size() == 1) target = 0;
    if (!target)
      throw InputError(path, 0,
                       trf("the diagnosis of '{}' matches no run of the report; give the run's recording or "
                           "its analysis JSON too",
                           name.empty() ? std::string(tr("(no source)")) : name));
    diagnoses.resize(analyses.size());
    if (diagnoses[*target].is_object())
      throw InputError(path, 0, trf("a second diagnosis for '{}'", file_name(analyses[*target])));
    diagnoses[*target] = d;
  }
}

/// The options behind the report, shown in its settings table.
json settings_of(const ReportCmd& c, const std::vector<std::string>& recordings,
                 const std::vector<std::string>& saved) {
  json s = json::object();
  if (!recordings.empty()) s[N_("recordings")] = recordings;
  if (!saved.empty()) s[N_("saved results")] = saved;
  if (recordings.empty()) return s;  // the analysis options below apply to recordings only
  const auto& in = c.input;
  // "pulses" unless a column name implies rate or angle
  s[N_("input")] = option_value_words("--input", in.input.empty() ? std::string("pulses") : in.input);
  if (!in.column.empty()) s[N_("column")] = in.column;
  if (in.rate_hz) s[N_("rate (Hz)")] = *in.rate_hz;
  if (in.scale_arcsec) s[N_("pulse weight (″)")] = *in.scale_arcsec;
  if (in.input == "counter") s[N_("counter bits")] = in.counter_bits;
  const std::string by_name = tr("from the column name, else ");
  if (in.input == "angle") s[N_("angle unit")] = in.angle_unit.empty() ? by_name + "arcsec" : in.angle_unit;
  if (in.input == "rate") s[N_("rate unit")] = in.rate_unit.empty() ? by_name + "deg/h" : in.rate_unit;
  const auto& a = c.analysis;
  s[N_("fit range (s)")] = a.fit_range.empty() ? std::string(tr("all τ")) : a.fit_range;
  s[N_("minimum EDF")] = a.min_edf;
  s[N_("terms")] = a.terms;
  s[N_("term selection")] =
      a.keep_all_terms ? tr("all fitted terms kept") : tr("unsupported K, R, Q left out (upper bounds)");
  if (a.earth_rate)
    s[N_("Earth rate (°/h)")] = *a.earth_rate;
  else
    s[N_("latitude (°)")] = a.latitude_deg;
  s[N_("B estimate")] = option_value_words("--b-estimate", a.b_estimate);
  s[N_("tolerance on B (%)")] = a.tolerance_pct;
  s[N_("class table")] = a.limits_file.empty() ? std::string(tr("GOST RV 52339 (built in)")) : a.limits_file;
  s[N_("averaging block (s)")] = a.block_s;
  s[N_("direct method t range (s)")] = a.direct_range;
  s[N_("outliers")] = option_value_words("--outliers", a.outliers);
  s[N_("outlier threshold (robust σ)")] = a.outlier_threshold;
  if (c.temperature) s[N_("temperature (°C)")] = *c.temperature;
  return s;
}

/// The local time as the report's language writes it, with its offset from UTC: "27.11.2026 14:05
/// UTC+03:00" in Russian, "2026-11-27 14:05 UTC+03:00" in English; and the local date.
std::string local_now(CalendarDate& date) {
  const auto now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  tzset();  // localtime_r need not read TZ itself
  localtime_r(&now, &tm);
  date = {tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday};
  const long offset_min = tm.tm_gmtoff / 60;
  return fmt::format("{} {:02}:{:02}:{:02} UTC{}{:02}:{:02}", date_text(date), tm.tm_hour, tm.tm_min, tm.tm_sec,
                     offset_min < 0 ? '-' : '+', std::labs(offset_min) / 60, std::labs(offset_min) % 60);
}

/// Writes DIR/report.pdf and DIR/report.docx as asked, after the HTML; a tool that is not installed
/// is an error for its output (exit status 3) once the other has been written.
void write_printed_copies(const ReportCmd& c, const std::string& html, Io& io) {
  std::vector<std::string> missing;
  if (c.pdf) {
    const std::string pdf = (fs::path(c.dir) / "report.pdf").string();
    const bool printed = [&] {
      const Progress progress(trf("printing {}", printable(pdf)), 0, io.progress);  // erased before the message
      return print_to_pdf(html, pdf, c.force);
    }();
    if (printed)
      io.out << trf("PDF written to {}\n", printable(pdf));
    else
      missing.push_back(
          tr("--pdf: no headless Chromium found (chromium, chromium-browser or google-chrome in PATH, "
             "or RWCALC_CHROMIUM; Debian: apt-get install chromium); the HTML report prints to PDF "
             "from any browser"));
  }
  if (c.docx) {
    const std::string docx = (fs::path(c.dir) / "report.docx").string();
    const bool converted = [&] {
      const Progress progress(trf("converting {}", printable(docx)), 0, io.progress);
      return convert_to_docx(html, docx, c.force);
    }();
    if (converted)
      io.out << trf("DOCX written to {}\n", printable(docx));
    else
      missing.push_back(tr("--docx: pandoc not found (in PATH, or RWCALC_PANDOC; Debian: apt-get install pandoc)"));
  }
  if (missing.empty()) return;
  std::string message;
  for (const auto& m : missing) message += (message.empty() ? "" : "; ") + m;
  throw OutputError(trf("{} (the HTML report is written: {})", message, printable(html)));
}

/// The runs (recordings analysed here, then the saved ones), their diagnoses and the overall verdict.
ReportInput report_input(const ReportCmd& c, const std::vector<std::string>& recordings,
                         const std::vector<std::string>& saved_files, const ReadOptions& read,
                         const AnalysisOptions& opt, Io& io) {
  SavedResults saved;
  for (const auto& f : saved_files) load_saved_result(f, saved);
  std::vector<json> diagnoses;
  if (c.diagnose) diagnoses = diagnose_recordings(recordings, read, opt, c.diagnose_runs, c.diagnose_seed, io.progress);
  ReportInput in;
  if (!recordings.empty()) in.analyses = analyze_files(recordings, read, opt);
  for (auto& a : saved.analyses) in.analyses.push_back(std::move(a.run));
  if (in.analyses.empty())
    throw UsageError(tr("report: no run to report; give recordings or saved analyses (the diagnoses need their runs)"));
  diagnoses.resize(in.analyses.size());
  attach_saved_diagnoses(saved, in.analyses, diagnoses);
  if (std::any_of(diagnoses.begin(), diagnoses.end(), [](const json& d) { return d.is_object(); }))
    in.diagnoses = std::move(diagnoses);
  // A single saved batch keeps the verdict it computed; otherwise the verdict over all runs.
  if (saved.overalls.size() == 1 && recordings.empty() && saved_files.size() == 1 + saved.diagnoses.size())
    in.overall = saved.overalls.front();
  else {
    try {
      in.overall = summarize_runs(in.analyses, "report")["overall"];
    } catch (const InputError& e) {
      // Saved results without the verdict's class probabilities (older or hand-made JSON): the
      // report still states the worst class over the runs, without a combined probability.
      print_message(io.err, trf("note: no combined verdict over the runs ({}); the report states the worst class "
                                "over the runs",
                                e.what()));
    }
  }
  return in;
}

int run_report(const ReportCmd& c, Io& io) {
  if (c.dir.empty())
    throw UsageError(tr("report: -o DIR is required (the directory that receives report.html; created when missing)"));
  std::vector<std::string> recordings, saved_files;
  for (const auto& f : c.files) (is_json_path(f) ? saved_files : recordings).push_back(f);
  AnalysisOptions opt = c.analysis.options();
  opt.progress = io.progress;
  if (c.temperature) {
    if (recordings.size() != 1)
      throw UsageError(tr("--temperature applies to a single recording; name the temperature in each file instead"));
    opt.temperature_c = c.temperature;
  }
  if (c.diagnose && recordings.empty())
    throw UsageError(tr("--diagnose needs recordings; saved diagnoses are given as 'rwcalc diagnose --json' files"));
  ReadOptions read = c.input.options();
  read.progress = io.progress;
  // Fail before the analysis: a report.html that cannot be written (existing without --force, a
  // directory…; a missing DIR is created later), no gnuplot for the figures.
  std::error_code ec;
  if (fs::is_directory(c.dir, ec)) {
    check_output_targets({{"-o", (fs::path(c.dir) / "report.html").string()}}, c.force);
    if (c.pdf) check_output_targets({{"--pdf", (fs::path(c.dir) / "report.pdf").string()}}, c.force);
    if (c.docx) check_output_targets({{"--docx", (fs::path(c.dir) / "report.docx").string()}}, c.force);
  }
  std::optional<LabProfile> profile;
  if (!c.lab_profile.empty()) profile = read_lab_profile(c.lab_profile);  // its errors before the analysis
  if (!c.no_figures) require_gnuplot();

  const ReportInput in = report_input(c, recordings, saved_files, read, opt, io);

  ReportOptions ro;
  if (!c.title.empty()) ro.title = c.title;
  ro.lab = c.lab;
  ro.gyro = c.gyro;
  ro.settings = settings_of(c, recordings, saved_files);
  ro.figures = !c.no_figures;
  ro.generated = local_now(ro.protocol_date);
  ro.profile = std::move(profile);
  ro.protocol_number = c.protocol_number;
  const auto path = write_report(c.dir, in, ro, c.force);
  io.out << localize_numbers(trnf("report written to {} ({} run{})\n", "report written to {} ({} runs{})\n",
                                  in.analyses.size(), as_typed(path), in.analyses.size(),
                                  c.no_figures ? tr(", no figures") : ""));
  write_printed_copies(c, path, io);
  return 0;
}

}  // namespace

void register_report(CLI::App& app, Runner& runner) {
  auto cmd = std::make_shared<ReportCmd>();
  auto* sub = app.add_subcommand(
      "report",
      tr("A self-contained HTML test report (DIR/report.html): run summaries, Tables 1 and 2, the verdict with its "
         "probability, figures inline, the settings and the version"));
  sub->add_option("FILES", cmd->files,
                  tr("Recordings, and/or saved results: .json of 'analyze --json', 'batch --json' or 'diagnose "
                     "--json', .jsonl of 'batch --jsonl'"))
      ->required();
  sub->add_option("-o,--output", cmd->dir, tr("Directory for report.html (created when missing); required"))
      ->check(output_name());
  cmd->input.add_to(*sub);
  cmd->analysis.add_to(*sub);
  add_temperature_option(*sub, cmd->temperature, tr("Temperature, °C (only with a single recording)"));
  sub->add_option("--title", cmd->title, tr("Title of the report"));
  auto* lab = sub->add_option("--lab", cmd->lab, tr("The testing laboratory, for the title block"));
  sub->add_option("--gyro", cmd->gyro, tr("The gyro's type or name, for the title block (e.g. GL-2D)"));
  auto* profile = sub->add_option("--lab-profile", cmd->lab_profile,
                                  tr("Lay the first page out as a test protocol, with the laboratory, approver, "
                                     "performer, checker, customer, test method, measuring instruments and ambient "
                                     "conditions of this YAML file (keys: docs/test-protocol.md)"))
                      ->check(CLI::ExistingFile)
                      ->excludes(lab);
  sub->add_option("--protocol-number", cmd->protocol_number,
                  tr("The protocol's number, e.g. 17/2026 (with --lab-profile)"))
      ->needs(profile);
  sub->add_flag("--pdf", cmd->pdf,
                tr("Also print DIR/report.pdf with a headless Chromium (exit status 3 when none is installed; the "
                   "HTML is written)"));
  sub->add_flag("--docx", cmd->docx,
                tr("Also write DIR/report.docx, an editable copy, with pandoc (exit status 3 when it is not installed; "
                   "the HTML is written)"));
  sub->add_flag("--diagnose", cmd->diagnose, tr("Also diagnose each recording (what the noise model misses)"));
  sub->add_option("--diagnose-runs", cmd->diagnose_runs,
                  tr("Accepted for earlier scripts; the diagnosis simulates no records"))
      ->check(whole_in(10, 100000))
      ->capture_default_str();
  sub->add_option("--diagnose-seed", cmd->diagnose_seed,
                  tr("Recorded only: no finding of the diagnosis depends on a seed"))
      ->check(whole_in(0, UINT64_MAX))
      ->capture_default_str();
  sub->add_flag("--no-figures", cmd->no_figures, tr("Tables only (needs no gnuplot)"));
  sub->add_flag("--force", cmd->force, tr("Replace an existing report.html, report.pdf and report.docx"));
  sub->callback([cmd, &runner] { runner = [cmd](Io& io) -> int { return run_report(*cmd, io); }; });
}

}  // namespace rwcalc::cli
