// The JSON rwcalc reads (saved results for `report`, JSON lines for `merge`, class tables for
// --limits, models for `simulate --from`), end to end through the built executable: every JSON
// rwcalc writes is read back; any crafted value (out of range, wrong type, outside its domain,
// missing, truncated, repeated) is an input error (exit 2) naming the file and the line; a run
// given twice to merge is refused (or, identical, dropped with --dedupe); a file name that is
// not UTF-8 is written to JSON with U+FFFD, not fatal.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "rwcalc/printable.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::CliResult;
using rwcalc::test::run_exe;
using rwcalc::test::slurp;
using rwcalc::test::TempDir;

namespace {

/// Outputs of rwcalc made once: two short simulated recordings and what analyze, batch and
/// diagnose write for them.
class JsonInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    for (const auto& [name, seed] : {std::pair{"run_p20C.csv", "1"}, std::pair{"run_m10C.csv", "2"}}) {
      const auto path = (dir_->path() / name).string();
      // A dithered read-out: the fit describes the record, so its verdict carries every probability
      // that the saved-result checks below are about (a rejected fit's verdict has none).
      const auto r = run_exe({"simulate", "-o", path, "--duration", "1800", "--rate", "100", "--arw", "0.001",
                              "--bias-instability", "0.006", "--seed", seed, "--white-readout"});
      ASSERT_EQ(r.status, 0) << r.err;
      records_.push_back(path);
    }
    analysis_ = produce("analysis.json", {"analyze", records_[0], "--json"});
    batch_ = produce("batch.json", {"batch", records_[0], records_[1], "--json"});
    lines_ = produce("lines.jsonl", {"batch", records_[0], records_[1], "--jsonl"});
    merged_ = produce("merged.json", {"merge", lines_, "--json"});
    merged_lines_ = produce("merged.jsonl", {"merge", lines_, "--jsonl"});
    diagnosis_ = produce("diagnosis.json", {"diagnose", records_[0], "--json", "--runs", "10", "--seed", "3"});
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
    records_.clear();
  }

  /// Runs rwcalc and saves its standard output under `name`.
  static std::string produce(const std::string& name, const std::vector<std::string>& args) {
    const auto r = run_exe(args);
    EXPECT_EQ(r.status, 0) << r.err;
    return dir_->write(name, r.out).string();
  }

  static CliResult report(const std::vector<std::string>& files) {
    std::vector<std::string> args{"report"};
    args.insert(args.end(), files.begin(), files.end());
    for (const char* a : {"-o", "", "--no-figures", "--force"}) args.emplace_back(a);
    args[args.size() - 3] = (dir_->path() / "report").string();
    return run_exe(args);
  }

  static inline TempDir* dir_ = nullptr;
  static inline std::vector<std::string> records_;
  static inline std::string analysis_, batch_, lines_, merged_, merged_lines_, diagnosis_;
};

/// `j` with the value at `pointer` written as `text` (any JSON text, valid or not), pretty-printed
/// as rwcalc writes it; `line` receives the line of that value.
std::string with_value(json j, const std::string& pointer, const std::string& text, std::size_t& line) {
  const std::string marker = "\"@@value@@\"";
  j[json::json_pointer(pointer)] = "@@value@@";
  std::string s = j.dump(2);
  const auto at = s.find(marker);
  line = 1 + static_cast<std::size_t>(std::count(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  return s.replace(at, marker.size(), text);
}

json read_json(const std::string& path) { return json::parse(slurp(path)); }

std::vector<json> read_lines(const std::string& path) {
  std::vector<json> out;
  std::istringstream in(slurp(path));
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) out.push_back(json::parse(l));
  return out;
}

std::string join_lines(const std::vector<json>& lines) {
  std::string s;
  for (const auto& l : lines) s += l.dump() + "\n";
  return s;
}

/// Exit 2 and a message "FILE:LINE: …" containing every fragment.
void expect_input_error(const CliResult& r, const std::string& file, std::size_t line,
                        const std::vector<std::string>& fragments) {
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  // Messages spell out control characters and invalid bytes (printable.hpp), file names included.
  EXPECT_NE(r.err.find(fmt::format("{}:{}: ", rwcalc::printable(file), line)), std::string::npos)
      << "expected " << rwcalc::printable(file) << ":" << line << " in: " << r.err;
  for (const auto& f : fragments) EXPECT_NE(r.err.find(f), std::string::npos) << "expected '" << f << "' in: " << r.err;
}

}  // namespace

// ---- every JSON rwcalc writes is read back by report ---------------------------------------------

TEST_F(JsonInput, ReportReadsEveryResultRwcalcWrites) {
  // analyze --json, batch --json, batch --jsonl, merge --json, merge --jsonl, diagnose --json
  // (whose "runs" is the size of its ensemble, not a list of runs), the diagnosis with its run.
  for (const auto& files : std::vector<std::vector<std::string>>{
           {analysis_}, {batch_}, {lines_}, {merged_}, {merged_lines_}, {analysis_, diagnosis_}}) {
    const auto r = report(files);
    EXPECT_EQ(r.status, 0) << files.back() << ": " << r.err;
    EXPECT_NE(r.out.find("report written to"), std::string::npos) << r.out;
  }
  const auto html = slurp(dir_->path() / "report" / "report.html");
  EXPECT_NE(html.find("id=\"run1-diagnosis\""), std::string::npos);
}

// ---- saved results of report: each kind of value, crafted ----------------------------------------

TEST_F(JsonInput, ReportRefusesCraftedValuesNamingFileLineAndKey) {
  struct Case {
    const char* pointer;
    const char* text;
    const char* path;  ///< the key path the message names
    const char* what;
  };
  const std::vector<Case> cases{
      {"/fit/N/value", "1e400", "fit.N.value", "beyond the range of a double"},
      {"/fit/N/value", "\"0.001\"", "fit.N.value", "must be a number, got string"},
      {"/fit/B/sigma", "-1", "fit.B.sigma", "must be a number >= 0"},
      {"/fit/B/resolved", "1", "fit.B.resolved", "must be true or false"},
      {"/source", "5", "source", "must be a string, got 5"},
      {"/temperature_c", "\"warm\"", "temperature_c", "got string"},
      {"/temperature_c", "-300", "temperature_c", "a temperature"},
      {"/fit", "3", "fit", "must be an object, got 3"},
      {"/verdict/classes", "\"1 2 3\"", "verdict.classes", "must be an array, got string"},
      {"/verdict/classes/1", "2.7", "verdict.classes[1]", "an integer"},
      {"/verdict/class", "1e300", "verdict.class", "an integer"},
      {"/verdict/class", "7", "verdict.class", "not among the verdict's \"classes\""},
      {"/verdict/p_class", "1.5", "verdict.p_class", "a probability in [0, 1]"},
      {"/verdict/B/p_meets/0", "1e308", "verdict.B.p_meets[0]", "a probability in [0, 1]"},
      {"/verdict/B/limits/0", "0", "verdict.B.limits[0]", "must be a positive number"},
      {"/verdict/N/p_meets", "[0.5]", "verdict.N.p_meets", "must hold 3 values"},
      {"/allan/points/0/tau_s", "null", "allan.points[0].tau_s", "must be a number, got null"},
      {"/allan/points/2", "[[[[\"nested\"]]]]", "allan.points[2]", "must be an object, got array"},
      {"/outliers/count", "-2", "outliers.count", "an integer"},
  };
  const json analysis = read_json(analysis_);
  for (const auto& c : cases) {
    std::size_t line = 0;
    const auto file = dir_->write("crafted.json", with_value(analysis, c.pointer, c.text, line)).string();
    SCOPED_TRACE(std::string(c.pointer) + " = " + c.text);
    expect_input_error(report({file}), file, line, {fmt::format("\"{}\"", c.path), c.what});
  }
  // The same in a batch file: the path runs through "runs[1]".
  std::size_t line = 0;
  const auto file =
      dir_->write("crafted.json", with_value(read_json(batch_), "/runs/1/fit/B/value", "\"big\"", line)).string();
  expect_input_error(report({file}), file, line, {"\"runs[1].fit.B.value\" must be a number"});
}

TEST_F(JsonInput, ReportRefusesInputIdentificationAndSegmentsOfTheWrongType) {
  // The report shows the input's identification and file, and the segments of a record read with
  // --gaps segments: a value of another type used to be shown as "—", as if the key were absent.
  struct Case {
    const char* pointer;
    const char* text;
    const char* what;
  };
  const std::vector<Case> cases{
      {"/input/identification/serial", "12345", "\"input.identification.serial\" must be a string, got 12345"},
      {"/input/identification/operator", "[\"A\"]", "\"input.identification.operator\" must be a string, got array"},
      {"/input/identification/test_date", "{}", "\"input.identification.test_date\" must be a string, got object"},
      {"/input/identification/conditions", "true", "\"input.identification.conditions\" must be a string"},
      {"/input/identification", "\"SN 7\"", "\"input.identification\" must be an object, got string"},
      {"/input/sha256", "7", "\"input.sha256\" must be a string, got 7"},
      {"/input/file_bytes", "-1", "\"input.file_bytes\" must be an integer"},
      {"/input", "[]", "\"input\" must be an object, got array"},
      {"/segments/count", "\"two\"", "\"segments.count\" must be an integer"},
      {"/segments/durations_s", "[1, -1]", "\"segments.durations_s[1]\" must be a number >= 0"},
      {"/segments/gaps", "{}", "\"segments.gaps\" must be an array, got object"},
  };
  for (const auto& c : cases) {
    std::size_t line = 0;
    const auto file = dir_->write("id.json", with_value(read_json(analysis_), c.pointer, c.text, line)).string();
    SCOPED_TRACE(std::string(c.pointer) + " = " + c.text);
    expect_input_error(report({file}), file, line, {c.what});
  }
  // A string, or null for "not given", is shown or left out as before.
  json a = read_json(analysis_);
  a["input"]["identification"]["serial"] = "SN 0042";
  a["input"]["identification"]["operator"] = nullptr;
  const auto file = dir_->write("id.json", a.dump(2)).string();
  const auto r = report({file});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(dir_->path() / "report" / "report.html").find("SN 0042"), std::string::npos);
}

TEST_F(JsonInput, ReportRefusesMissingKeysTruncatedAndNonObjectDocuments) {
  json a = read_json(analysis_);
  a.erase("allan");
  auto file = dir_->write("no-allan.json", a.dump(2)).string();
  expect_input_error(report({file}), file, 1, {"lacks the key \"allan\""});
  a = read_json(analysis_);
  a["verdict"].erase("classes");
  a["verdict"]["B"] = "B";
  std::size_t line = 0;
  file = dir_->write("b.json", with_value(a, "/verdict/B", "\"B\"", line)).string();
  expect_input_error(report({file}), file, line, {"\"verdict.B\" must be an object, got string"});
  // Truncated: cut in the middle of the file.
  const auto text = slurp(analysis_);
  const auto cut = text.substr(0, text.size() / 2);
  file = dir_->write("cut.json", cut).string();
  expect_input_error(report({file}), file, static_cast<std::size_t>(std::count(cut.begin(), cut.end(), '\n')) + 1,
                     {"not valid JSON"});
  file = dir_->write("array.json", "[1, 2]\n").string();
  expect_input_error(report({file}), file, 1, {"must be a JSON object"});
  // Nesting far deeper than any result of rwcalc.
  file = dir_->write("deep.json", "{\"allan\":\n" + std::string(100000, '[') + "\n").string();
  expect_input_error(report({file}), file, 2, {"nested deeper than"});
  // A key given twice would let the second silently replace the first.
  file = dir_->write("twice.json", "{\"allan\": {},\n\"allan\": {}}\n").string();
  expect_input_error(report({file}), file, 2, {"\"allan\" is given twice"});
}

// ---- JSON lines of merge --------------------------------------------------------------------------

TEST_F(JsonInput, MergeRefusesCraftedLinesNamingFileAndLine) {
  const auto lines = read_lines(lines_);
  ASSERT_EQ(lines.size(), 2u);
  struct Case {
    const char* pointer;
    json value;
    const char* what;
  };
  const std::vector<Case> cases{
      {"/verdict/p_meets/0", 1e308, "\"verdict.p_meets[0]\" must be a probability in [0, 1], got 1e+308"},
      {"/verdict/B/p_meets/1", -0.5, "\"verdict.B.p_meets[1]\" must be a probability"},
      {"/verdict/class_B", 2.7, "\"verdict.class_B\" must be an integer"},
      {"/verdict/classes", "123", "\"verdict.classes\" must be an array, got string"},
      {"/verdict/N", 4, "\"verdict.N\" must be an object, got 4"},
      {"/source", 17, "\"source\" must be a string, got 17"},
      {"/temperature_c", json::array(), "\"temperature_c\" must be a number"},
      {"/fit/N/resolved", "yes", "must be true or false, got string"},
      {"/outliers/count", 1.5, "\"outliers.count\" must be an integer"},
  };
  for (const auto& c : cases) {
    auto crafted = lines;
    crafted[1][json::json_pointer(c.pointer)] = c.value;
    const auto file = dir_->write("crafted.jsonl", join_lines(crafted)).string();
    SCOPED_TRACE(c.pointer);
    expect_input_error(run_exe({"merge", file}), file, 2, {c.what});
  }
  // Keys merge combines must be there.
  for (const char* pointer : {"/verdict/p_meets", "/verdict/B", "/verdict/class_strict", "/temperature_c", "/source"}) {
    auto crafted = lines;
    const json::json_pointer p(pointer);
    crafted[0][p.parent_pointer()].erase(p.back());
    const auto file = dir_->write("missing.jsonl", join_lines(crafted)).string();
    SCOPED_TRACE(pointer);
    expect_input_error(run_exe({"merge", file}), file, 1, {fmt::format("lacks the key \"{}\"", p.back())});
  }
  // 1e400 cannot be written by nlohmann: put it in the text.
  std::string text = join_lines(lines);
  const auto at = text.rfind("\"p_class\":");
  text.replace(at, text.find(',', at) - at, "\"p_class\":1e400");
  auto file = dir_->write("huge.jsonl", text).string();
  expect_input_error(run_exe({"merge", file}), file, 2, {"1e400 is beyond the range of a double"});
  // A line that is not an object, a truncated line, garbage.
  for (const char* bad : {"[1, 2, 3]", "42", "\"run\"", "null"}) {
    file = dir_->write("bad.jsonl", lines[0].dump() + "\n\n" + bad + "\n").string();
    expect_input_error(run_exe({"merge", file}), file, 3, {"not an analyze object"});
  }
  const auto first = lines[0].dump();
  file = dir_->write("cut.jsonl", first + "\n" + first.substr(0, first.size() / 2) + "\n").string();
  expect_input_error(run_exe({"merge", file}), file, 2, {"not valid JSON"});
  file = dir_->write("deep.jsonl", first + "\n" + std::string(5000, '{') + "\n").string();
  expect_input_error(run_exe({"merge", file}), file, 2, {"not valid JSON"});
  file = dir_->write("deeparr.jsonl", first + "\n" + std::string(5000, '[') + "\n").string();
  expect_input_error(run_exe({"merge", file}), file, 2, {"nested deeper than"});
}

TEST_F(JsonInput, MergeErrorsNameTheFileAndLineOfTheRun) {
  // Runs judged against different class tables: the line that differs.
  auto lines = read_lines(lines_);
  lines[1]["verdict"]["B"]["limits"][0] = 0.004;
  const auto a = dir_->write("a.jsonl", lines[0].dump() + "\n").string();
  const auto b = dir_->write("b.jsonl", std::string(1, '\n').append(lines[1].dump()).append("\n")).string();
  expect_input_error(run_exe({"merge", a, b}), b, 2,
                     {"another class table (\"verdict.B.limits\")", fmt::format("{}:1", a)});
}

TEST_F(JsonInput, MergeRefusesARunGivenTwiceAndDedupeKeepsOneOfIdenticalLines) {
  const auto lines = read_lines(lines_);
  const auto once = run_exe({"merge", lines_, "--json"});
  ASSERT_EQ(once.status, 0) << once.err;
  // A re-queued job appended its line again, to the same file or to another.
  const auto again = dir_->write("again.jsonl", join_lines({lines[0], lines[1], lines[0]})).string();
  const auto source = lines[0]["source"].get<std::string>();
  expect_input_error(run_exe({"merge", again}), again, 3, {source, fmt::format("already given at {}:1", again)});
  const auto other = dir_->write("other.jsonl", lines[1].dump() + "\n").string();
  expect_input_error(run_exe({"merge", lines_, other}), other, 1, {fmt::format("already given at {}:2", lines_)});
  // --dedupe: the identical repeat is dropped and the verdict is that of each run once.
  const auto deduped = run_exe({"merge", again, "--dedupe", "--json"});
  ASSERT_EQ(deduped.status, 0) << deduped.err;
  EXPECT_EQ(json::parse(deduped.out)["overall"], json::parse(once.out)["overall"]);
  EXPECT_EQ(json::parse(deduped.out)["runs"].size(), 2u);
  // Two lines of the same run that differ are refused with --dedupe too.
  auto changed = lines[0];
  changed["fit"]["N"]["value"] = 0.5;
  const auto differ = dir_->write("differ.jsonl", join_lines({lines[0], lines[1], changed})).string();
  for (bool dedupe : {false, true}) {
    std::vector<std::string> args{"merge", differ};
    if (dedupe) args.emplace_back("--dedupe");
    expect_input_error(run_exe(args), differ, 3, {source, fmt::format("{}:1", differ)});
  }
}

// ---- class tables (--limits) ------------------------------------------------------------------------

TEST_F(JsonInput, ClassTableValuesAreCheckedNamingFileLineAndKey) {
  const json good = {{"name", "lab"},
                     {"classes",
                      {{{"class", 1}, {"B_deg_per_h", 0.005}, {"N_deg_per_sqrt_h", 0.001}},
                       {{"class", 2}, {"B_deg_per_h", 0.008}, {"N_deg_per_sqrt_h", 0.0015}}}}};
  const auto ok = dir_->write("limits.json", good.dump(2)).string();
  EXPECT_EQ(run_exe({"analyze", records_[0], "--limits", ok}).status, 0);
  struct Case {
    const char* pointer;
    const char* text;
    const char* what;
  };
  for (const auto& c : std::vector<Case>{
           {"/classes/1/class", "2.7", "\"classes[1].class\" must be an integer"},
           {"/classes/1/class", "1e300", "\"classes[1].class\" must be an integer"},
           {"/classes/1/class", "\"2\"", "\"classes[1].class\" must be an integer"},
           {"/classes/0/B_deg_per_h", "1e400", "beyond the range of a double"},
           {"/classes/0/B_deg_per_h", "-0.005", "\"classes[0].B_deg_per_h\" must be a positive number"},
           {"/classes/0/N_deg_per_sqrt_h", "\"small\"", "\"classes[0].N_deg_per_sqrt_h\" must be a number"},
           {"/classes/0/position_error_km_h", "-1", "\"classes[0].position_error_km_h\" must be a number >= 0"},
           {"/classes/0", "7", "\"classes[0]\" must be an object"},
           {"/classes", "{}", "\"classes\" must be an array"},
           {"/name", "3", "\"name\" must be a string"},
       }) {
    std::size_t line = 0;
    const auto file = dir_->write("bad-limits.json", with_value(good, c.pointer, c.text, line)).string();
    SCOPED_TRACE(std::string(c.pointer) + " = " + c.text);
    expect_input_error(run_exe({"analyze", records_[0], "--limits", file}), file, line, {c.what});
  }
  json missing = good;
  missing["classes"][1].erase("N_deg_per_sqrt_h");
  const auto file = dir_->write("missing-limits.json", missing.dump(2)).string();
  std::size_t object_line = 0;
  (void)with_value(good, "/classes/1", "{}", object_line);
  expect_input_error(run_exe({"analyze", records_[0], "--limits", file}), file, object_line,
                     {"\"classes[1]\" lacks the key \"N_deg_per_sqrt_h\""});
}

// ---- simulate --from ------------------------------------------------------------------------------

TEST_F(JsonInput, SimulateFromChecksEveryValueNamingTheLine) {
  struct Case {
    const char* pointer;
    const char* text;
    const char* what;
  };
  const auto sim = (dir_->path() / "sim.csv").string();
  // An analysis: its settings and fitted coefficients.
  for (const auto& c : std::vector<Case>{
           {"/rate_hz", "1e400", "\"rate_hz\": the number 1e400"},
           {"/rate_hz", "\"fast\"", "\"rate_hz\" must be a number, got string"},  // was silently ignored
           {"/duration_s", "-5", "\"duration_s\" must be a positive number"},
           {"/temperature_c", "1e300", "\"temperature_c\" must be a temperature"},
           {"/fit/N/value", "[]", "\"fit.N.value\" must be a number, got array"},
           {"/fit", "\"none\"", "\"fit\" must be an object, got string"},
       }) {
    std::size_t line = 0;
    const auto file = dir_->write("model.json", with_value(read_json(analysis_), c.pointer, c.text, line)).string();
    SCOPED_TRACE(std::string(c.pointer) + " = " + c.text);
    expect_input_error(run_exe({"simulate", "--from", file, "-o", sim, "--force"}), file, line, {c.what});
  }
  // A model object.
  const json model = {{"arw_deg_per_sqrt_h", 0.001},
                      {"readout", "white"},
                      {"sinusoids", {{{"frequency_hz", 0.01}, {"amplitude_deg_per_h", 0.1}}}}};
  for (const auto& c : std::vector<Case>{
           {"/readout", "5", "\"readout\" must be a string, got 5"},
           {"/readout", "\"loud\"", "\"readout\" must be \"counting\" or \"white\""},
           {"/sinusoids/0/frequency_hz", "\"a\"", "\"sinusoids[0].frequency_hz\" must be a number"},
           {"/sinusoids", "{}", "\"sinusoids\" must be an array, got object"},
           {"/terms", "[{\"effect\": 3}]", "\"terms[0].effect\" must be a string"},
       }) {
    std::size_t line = 0;
    const auto file = dir_->write("model.json", with_value(model, c.pointer, c.text, line)).string();
    SCOPED_TRACE(std::string(c.pointer) + " = " + c.text);
    expect_input_error(run_exe({"simulate", "--from", file, "-o", sim, "--force"}), file, line, {c.what});
  }
}

TEST_F(JsonInput, SimulateFromRefusesDocumentsThatHoldNoGyroModel) {
  // Any JSON object used to pass and give a noise-free record with exit status 0. Now a document
  // must be an analysis of a gyro with its fitted coefficients, a diagnosis, or a noise model.
  const auto sim = dir_->path() / "never.csv";
  const auto refused = [&](const std::string& file, const std::string& where, const std::vector<std::string>& what) {
    const auto r = run_exe({"simulate", "--from", file, "-o", sim.string()});
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("rwcalc: error: " + where), std::string::npos) << "expected " << where << " in: " << r.err;
    for (const auto& w : what) EXPECT_NE(r.err.find(w), std::string::npos) << "expected '" << w << "' in: " << r.err;
    EXPECT_FALSE(fs::exists(sim)) << file;
  };
  // Nothing of a model: an empty object, a class table, the output of imu, a simulation's truth.
  const auto empty = dir_->write("empty.json", "{}\n").string();
  refused(empty, empty + ":1: ", {"holds no model", "\"fit\"", "\"extended_model\"", "arw_deg_per_sqrt_h"});
  const auto table = dir_->write("classes.json", R"({"name": "lab", "classes": [{"class": 1, "B_deg_per_h": 0.005,
                                                 "N_deg_per_sqrt_h": 0.001}]})")
                         .string();
  refused(table, table + ":1: ", {"holds no model", "\"classes\""});
  const auto rec = records_[0];
  const auto imu = produce("imu.json", {"imu", rec, "--gyro", "pulses", "--json"});
  refused(imu, imu + ":1: ", {"holds no model", "\"channels\""});
  const auto truth = dir_->path() / "truth.json";
  ASSERT_EQ(run_exe({"simulate", "-o", (dir_->path() / "t.csv").string(), "--duration", "60", "--truth", truth.string(),
                     "--force"})
                .status,
            0);
  refused(truth.string(), truth.string() + ":1: ", {"holds no model", "\"model\""});
  // An analysis whose fit lacks a coefficient, and one of an accelerometer.
  json a = read_json(analysis_);
  a["fit"].erase("N");
  const auto no_n = dir_->write("no-n.json", a.dump(2)).string();
  refused(no_n, no_n + ":", {"\"fit\" lacks the key \"N\""});
  std::size_t line = 0;
  const auto accel =
      dir_->write("accel.json", with_value(read_json(analysis_), "/sensor", "\"accelerometer\"", line)).string();
  refused(accel, fmt::format("{}:{}: ", accel, line), {"\"sensor\" is \"accelerometer\"", "gyro"});
  // What simulate --from is for still works: an analysis, a diagnosis.
  for (const auto& from : {analysis_, diagnosis_}) {
    const auto r = run_exe({"simulate", "--from", from, "-o", sim.string(), "--duration", "60", "--force"});
    EXPECT_EQ(r.status, 0) << from << ": " << r.err;
  }
}

// ---- a file name that is not UTF-8 ---------------------------------------------------------------

TEST_F(JsonInput, FileNameThatIsNotUtf8IsWrittenWithReplacementCharacters) {
  TempDir dir;
  const auto name = (dir.path() / "run_\xff\xfe_p20C.csv").string();
  fs::copy_file(records_[0], name);
  const std::string replaced = "run_\xEF\xBF\xBD\xEF\xBF\xBD_p20C.csv";  // U+FFFD for each invalid byte
  for (const auto& args : std::vector<std::vector<std::string>>{{"analyze", name, "--json"},
                                                                {"batch", name, records_[1], "--json"},
                                                                {"batch", name, "--jsonl"},
                                                                {"allan", name, "--json"},
                                                                {"diagnose", name, "--json", "--runs", "10"}}) {
    const auto r = run_exe(args);
    ASSERT_EQ(r.status, 0) << args[0] << ": " << r.err;
    EXPECT_NE(r.out.find(replaced), std::string::npos) << args[0];
    const bool lines = args.back() == "--jsonl";
    EXPECT_TRUE(json::accept(lines ? r.out.substr(0, r.out.find('\n')) : r.out)) << args[0];
  }
  // What was written is read back: merge and report.
  const auto lines = dir.write("lines.jsonl", run_exe({"batch", name, records_[1], "--jsonl"}).out).string();
  const auto merged = run_exe({"merge", lines});
  EXPECT_EQ(merged.status, 0) << merged.err;
  EXPECT_EQ(report({lines}).status, 0);
  // A saved result whose own name is not UTF-8.
  const auto saved = (dir.path() / "result_\xff.json").string();
  fs::copy_file(analysis_, saved);
  EXPECT_EQ(report({saved}).status, 0);
  const auto bad = (dir.path() / "bad_\xff.json").string();
  std::ofstream(bad) << "{\"allan\": 1e400}";
  expect_input_error(report({bad}), bad, 1, {"beyond the range"});
}
