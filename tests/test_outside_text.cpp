// Outside text (file, directory and column names, option values, identification) reaching a program
// that reads it as data, or shown in Russian: the file URL Chromium prints, the Kalibr YAML file
// PyYAML loads, the names as typed among decimal commas, the keys of the IMU figure.
// The PDF test skips with a message when no chromium is installed, the YAML test when python3 has
// no yaml module (scripts/install-deps.sh installs python3-yaml).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "rwcalc/encode.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using rwcalc::test::run_cli;
using rwcalc::test::slurp;
using rwcalc::test::TempDir;

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// The marks of rwcalc::as_typed (U+FDD0, U+FDD1): never in an output.
bool holds_typed_marks(const std::string& text) { return has(text, "\xEF\xB7\x90") || has(text, "\xEF\xB7\x91"); }

/// A static IMU of white noise at 100 Hz: a time column, two gyro columns (°/s) and an
/// accelerometer column (g), named as given (header cells, no delimiter in them).
std::string imu_text(const std::vector<std::string>& names, int samples = 3000) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> z;
  std::string s = "time_s";
  for (const auto& n : names) s += "," + n;
  s += "\n";
  for (int k = 0; k < samples; ++k)
    s += fmt::format("{:.2f},{:.6f},{:.6f},{:.7f}\n", k / 100.0, 0.1 + 0.05 * z(rng), 0.05 * z(rng), 0.002 * z(rng));
  return s;
}

/// `rwcalc imu` of those columns with the noise file: gyro columns 2 and 3, accelerometer 4.
std::vector<std::string> imu_kalibr_args(const fs::path& file, const fs::path& yaml, const std::string& rostopic) {
  return {"imu", file.string(),  "--gyro", "2,3",      "--gyro-unit", "deg/s",      "--accel",
          "4",   "--accel-unit", "g",      "--kalibr", yaml.string(), "--rostopic", rostopic};
}

bool python_yaml() { return std::system("python3 -c 'import yaml' >/dev/null 2>&1") == 0; }

/// Every YAML file loaded by PyYAML (yaml.safe_load), as JSON: one object per file, or the text
/// of the loader's error.
std::vector<nlohmann::json> load_with_pyyaml(const std::vector<fs::path>& files, const TempDir& dir) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& f : files) list.push_back(f.string());
  const auto in = dir.write("files.json", list.dump());
  const auto py = dir.write("load.py",
                            "import json, sys, yaml\n"
                            "out = []\n"
                            "for name in json.load(open(sys.argv[1])):\n"
                            "    try:\n"
                            "        out.append(yaml.safe_load(open(name, encoding='utf-8')))\n"
                            "    except Exception as e:\n"
                            "        out.append('PyYAML: ' + str(e))\n"
                            "json.dump(out, open(sys.argv[2], 'w'), ensure_ascii=True)\n");
  const auto result = dir.path() / "loaded.json";
  const auto cmd = fmt::format("python3 '{}' '{}' '{}'", py.string(), in.string(), result.string());
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const auto loaded = nlohmann::json::parse(slurp(result), nullptr, false);
  return loaded.is_array() ? loaded.get<std::vector<nlohmann::json>>() : std::vector<nlohmann::json>{};
}

/// Random text of the kinds a YAML writer gets wrong: YAML's own characters, C0 and C1 controls,
/// NEL, the separators, noncharacters, the byte-order mark, bidirectional controls, letters of
/// several scripts, code points beyond U+FFFF, and bytes that are not UTF-8 (surrogates encoded,
/// overlong, stray, truncated) — each only where `invalid_ok`.
class HostileText {
 public:
  explicit HostileText(std::uint64_t seed) : rng_(seed) {}

  std::string next(bool invalid_ok, bool controls_ok, std::size_t max_pieces = 12) {
    static const std::vector<std::string> kPieces = {"\"",
                                                     "\\",
                                                     "'",
                                                     "#",
                                                     ": ",
                                                     "- ",
                                                     "? ",
                                                     "&a",
                                                     "*b",
                                                     "!!str ",
                                                     "%",
                                                     "@",
                                                     "`",
                                                     "{",
                                                     "}",
                                                     "[",
                                                     "]",
                                                     ",",
                                                     "|",
                                                     ">",
                                                     " ",
                                                     "  ",
                                                     "~",
                                                     "null",
                                                     "yes",
                                                     "1.5",
                                                     "0x1F",
                                                     ".inf",
                                                     "=",
                                                     "/imu0",
                                                     "\xC2\x85",  // NEL
                                                     "\xE2\x80\xA8",
                                                     "\xE2\x80\xA9",  // line and paragraph separators
                                                     "\xEF\xBF\xBE",
                                                     "\xEF\xBF\xBF",
                                                     "\xEF\xB7\x90",  // U+FFFE, U+FFFF, U+FDD0
                                                     "\xF0\x9F\xBF\xBE",
                                                     "\xF4\x8F\xBF\xBF",  // U+1FFFE, U+10FFFF
                                                     "\xEF\xBB\xBF",
                                                     "\xE2\x80\xAE",
                                                     "\xE2\x81\xA6",  // BOM, RLO, LRI
                                                     "\xC2\x80",
                                                     "\xC2\x9B",
                                                     "\xC2\x9F",
                                                     "\xC2\xA0",  // C1 controls, no-break space
                                                     "Ж",
                                                     "τ",
                                                     "°/√h",
                                                     "中文",
                                                     "\xF0\x9F\x98\x80"};  // letters, an emoji
    static const std::vector<std::string> kControls = {"\t", "\x01", "\x1b[31m", "\x7f", "\n", "\r"};
    static const std::vector<std::string> kInvalid = {"\xED\xA0\x80", "\xED\xBF\xBF", "\xC0\xAF", "\x80",
                                                      "\xFF",         "\xFE",         "\xE2\x82", "\xF4\x90\x80\x80"};
    std::string s;
    const std::size_t n = std::uniform_int_distribution<std::size_t>(1, max_pieces)(rng_);
    for (std::size_t i = 0; i < n; ++i) {
      const int kind = std::uniform_int_distribution<int>(0, 9)(rng_);
      if (kind == 0 && invalid_ok)
        s += pick(kInvalid);
      else if (kind == 1 && controls_ok)
        s += pick(kControls);
      else if (kind == 2)
        s += static_cast<char>(std::uniform_int_distribution<int>('a', 'z')(rng_));
      else
        s += pick(kPieces);
    }
    return s;
  }

 private:
  const std::string& pick(const std::vector<std::string>& v) {
    return v[std::uniform_int_distribution<std::size_t>(0, v.size() - 1)(rng_)];
  }
  std::mt19937_64 rng_;
};

/// A header cell made of `text`: no delimiter, blank, line end or comment sign in it, and a
/// letter first so that it never reads as a number or a time column.
std::string column_name(std::string text) {
  std::erase_if(text, [](char c) { return c == ',' || c == ';' || c == '\t' || c == ' ' || c == '\n' || c == '\r'; });
  return "c" + text;
}

/// A file name made of `text`: no '/', at most 200 bytes.
std::string file_name(std::string text) {
  std::erase(text, '/');
  return text.substr(0, 200) + ".csv";
}

}  // namespace

// ---- file URLs: the page Chromium prints is the report ------------------------------------------

TEST(FileUrl, EveryByteButTheUnreservedIsPercentEncoded) {
  EXPECT_EQ(rwcalc::file_url("/tmp/out/report.html"), "file:///tmp/out/report.html");
  EXPECT_EQ(rwcalc::file_url("/a#b/c?d/e%41f/g h/r~_-.html"), "file:///a%23b/c%3Fd/e%2541f/g%20h/r~_-.html");
  EXPECT_EQ(rwcalc::file_url("/x\xff\xfe;y&z=1+2"), "file:///x%FF%FE%3By%26z%3D1%2B2");
  EXPECT_EQ(rwcalc::file_url("/Ж"), "file:///%D0%96");
}

TEST(ReportPdf, AnOutputDirectoryWithUrlCharactersPrintsThatReport) {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) GTEST_SKIP() << "no chromium in PATH";
  TempDir dir;
  // Before the URL was encoded, Chromium opened the directory before '#' (its listing went into
  // the PDF), a file named before '?', or nothing for '%41'.
  const std::vector<std::string> names = {"a#b", "c?d", "e%41f", "g h\xff;j&k=1%"};
  fs::create_directory(dir.path() / "a");                         // what "a#b/…" reached
  std::ofstream(dir.path() / "c") << "what \"c?d/…\" reached\n";  // what "c?d/…" reached
  for (std::size_t i = 0; i < names.size(); ++i) {
    const fs::path parent = dir.path() / names[i];
    fs::create_directories(parent);
    const auto out = parent / "sub";
    const std::string title = fmt::format("rwcalc url check {}", i);
    const auto r = run_cli(
        {"report", "--pdf", "--no-figures", "--title", title, "-o", out.string(), rwcalc::test::gl2d_runs().front()});
    ASSERT_EQ(r.status, 0) << names[i] << ": " << r.err;
    const std::string pdf = slurp(out / "report.pdf");
    ASSERT_TRUE(pdf.starts_with("%PDF-")) << names[i];
    // Chromium puts the page's <title> into the PDF's document information.
    EXPECT_TRUE(has(pdf, "/Title (" + title + ")")) << names[i] << ": the PDF is of another page";
  }
}

// ---- the Kalibr YAML file --------------------------------------------------------------------------

TEST(YamlQuoted, EscapesWhatYamlForbidsOrFoldsAndRefusesBytesThatAreNotUtf8) {
  using rwcalc::yaml_quoted;
  EXPECT_EQ(yaml_quoted("/imu0"), "\"/imu0\"");
  EXPECT_EQ(yaml_quoted("a\"b\\c#d: e"), "\"a\\\"b\\\\c#d: e\"");
  EXPECT_EQ(yaml_quoted("\t\n\r\x01\x7f"), "\"\\t\\n\\r\\x01\\x7f\"");
  EXPECT_EQ(yaml_quoted("\xC2\x85\xC2\x9B"), "\"\\x85\\x9b\"");  // NEL, CSI
  EXPECT_EQ(yaml_quoted("\xE2\x80\xA8\xEF\xBB\xBF\xE2\x80\xAE"), "\"\\u2028\\ufeff\\u202e\"");
  EXPECT_EQ(yaml_quoted("\xEF\xBF\xBE\xEF\xB7\x90\xF4\x8F\xBF\xBF"), "\"\\ufffe\\ufdd0\\U0010ffff\"");
  EXPECT_EQ(yaml_quoted("Ж τ \xF0\x9F\x98\x80"), "\"Ж τ \xF0\x9F\x98\x80\"");  // text is kept
  EXPECT_EQ(yaml_quoted("\xED\xA0\x80"), std::nullopt);                        // a surrogate
  EXPECT_EQ(yaml_quoted("a\xFF"), std::nullopt);
}

// Every Kalibr file rwcalc writes, for any rostopic, column name or file name, loads with PyYAML
// to exactly the expected keys and values; a rostopic that is not UTF-8 is exit status 2 naming
// --rostopic with nothing written.
TEST(KalibrFile, LoadsWithPyYamlToExactlyTheValuesForAnyNames) {
  if (!python_yaml()) GTEST_SKIP() << "python3 has no yaml module (install python3-yaml)";
  TempDir dir;
  const auto plain = dir.write("plain.csv", imu_text({"gx", "gy", "ax"}));
  ASSERT_EQ(run_cli(imu_kalibr_args(plain, dir.path() / "plain.yaml", "/imu0")).status, 0);
  const auto base = load_with_pyyaml({dir.path() / "plain.yaml"}, dir).at(0);
  ASSERT_TRUE(base.is_object()) << base;
  ASSERT_EQ(base.size(), 6u) << base;  // rostopic, update_rate and the two keys of each kind

  HostileText text(20240611);
  struct Case {
    std::string rostopic;
    fs::path yaml;
  };
  std::vector<Case> written;
  for (int i = 0; i < 60; ++i) {
    const std::string rostopic = text.next(i % 4 == 0, true);
    const std::vector<std::string> names = {column_name(text.next(true, false)), column_name(text.next(true, false)),
                                            column_name(text.next(true, false))};
    const fs::path sub = dir.path() / fmt::format("case{}", i);
    fs::create_directory(sub);
    const fs::path data = sub / file_name(text.next(true, true, 6));
    std::ofstream(data, std::ios::binary) << imu_text(names);
    const fs::path yaml = sub / "imu.yaml";
    const auto r = run_cli(imu_kalibr_args(data, yaml, rostopic));
    if (!rwcalc::valid_utf8(rostopic)) {
      EXPECT_EQ(r.status, 2) << i << ": " << r.err;
      EXPECT_TRUE(has(r.err, "--rostopic")) << r.err;
      EXPECT_FALSE(fs::exists(yaml)) << i;
      continue;
    }
    ASSERT_EQ(r.status, 0) << i << ": " << r.err;
    written.push_back({rostopic, yaml});
  }
  ASSERT_GT(written.size(), 30u);
  std::vector<fs::path> files;
  for (const auto& c : written) files.push_back(c.yaml);
  const auto loaded = load_with_pyyaml(files, dir);
  ASSERT_EQ(loaded.size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    nlohmann::json want = base;
    want["rostopic"] = written[i].rostopic;
    EXPECT_EQ(loaded[i], want) << written[i].yaml << "\n" << slurp(written[i].yaml);
  }
}

// ---- Russian: decimal commas only in the numbers rwcalc prints ----------------------------------

TEST(RussianText, NamesIdentificationAndLaboratoryKeepTheirDecimalPoints) {
  TempDir dir;
  const auto run = dir.path() / "run 1.5 (v2.5).csv.gz";
  fs::copy_file(rwcalc::test::gl2d_runs().front(), run);
  const std::vector<std::string> id = {"--serial", "SN 12.5", "--operator", "Op 3.7", "--conditions", "T 20.5"};
  const auto analyze = run_cli(rwcalc::test::concat({"analyze", "--lang", "ru", run.string()}, id));
  ASSERT_EQ(analyze.status, 0) << analyze.err;
  for (const char* typed : {"run 1.5 (v2.5).csv.gz", "SN 12.5", "Op 3.7", "T 20.5"})
    EXPECT_TRUE(has(analyze.out, typed)) << typed << "\n" << analyze.out;
  EXPECT_TRUE(has(analyze.out, "2,5 мс")) << analyze.out;  // τ0 = 2.5 ms: rwcalc's own number
  const auto batch = run_cli({"batch", "--lang", "ru", run.string()});
  ASSERT_EQ(batch.status, 0) << batch.err;
  EXPECT_TRUE(has(batch.out, "run 1.5 (v2.5).csv.gz")) << batch.out;
  const auto out = dir.path() / "report 3.5";
  const auto report =
      run_cli(rwcalc::test::concat({"report", "--lang", "ru", "--no-figures", "--lab", "Lab 2.5", "--gyro", "G 4.5",
                                    "--title", "Title 6.5", "-o", out.string(), run.string()},
                                   id));
  ASSERT_EQ(report.status, 0) << report.err;
  EXPECT_TRUE(has(report.out, "report 3.5")) << report.out;
  const std::string html = slurp(out / "report.html");
  for (const char* typed : {"run 1.5 (v2.5).csv.gz", "SN 12.5", "Op 3.7", "T 20.5", "Lab 2.5", "G 4.5", "Title 6.5"})
    EXPECT_TRUE(has(html, typed)) << typed;
  EXPECT_TRUE(has(html, "55,75")) << "rwcalc's latitude keeps its decimal comma";
  // An input error names the file as typed.
  const auto bad = dir.write("bad 7.5.csv", "# rate_hz: 100\npulses,x\n1,2\n3\n");
  const auto e = run_cli({"analyze", "--lang", "ru", "--column", "pulses", bad.string()});
  EXPECT_EQ(e.status, 2);
  EXPECT_TRUE(has(e.err, "bad 7.5.csv:4: ")) << e.err;
  for (const auto* r : {&analyze, &batch, &report, &e}) EXPECT_FALSE(holds_typed_marks(r->out + r->err));
  EXPECT_FALSE(holds_typed_marks(html));
}

TEST(RussianText, ImuTablesReportAndFigureKeepColumnAndFileNames) {
  TempDir dir;
  const auto file = dir.write("imu 2.5.csv", imu_text({"(1.5)", "gy", "ax"}));
  const auto report = dir.path() / "rep";
  const auto script = dir.path() / "imu.gp";
  const auto r = run_cli({"imu", "--lang", "ru", file.string(), "--gyro", "2,3", "--gyro-unit", "deg/s", "--accel", "4",
                          "--accel-unit", "g", "--report", report.string(), "--plot-script", script.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "imu 2.5.csv")) << r.out;
  EXPECT_TRUE(has(r.out, "(1.5)")) << r.out;
  EXPECT_TRUE(has(slurp(script), "'(1.5)")) << slurp(script);
  for (const char* name : {"index.html", "imu.txt", "imu.yaml", "imu.json"})
    EXPECT_FALSE(holds_typed_marks(slurp(report / name))) << name;
  EXPECT_FALSE(holds_typed_marks(r.out + r.err + slurp(script)));
}

// ---- figure keys -----------------------------------------------------------------------------------

TEST(ImuFigure, KeysAndTitlesKeepTheWholeColumnName) {
  TempDir dir;
  const auto file = dir.write("imu.csv", imu_text({"gyro/x", "gyro/y", "accel/z"}));
  const auto script = dir.path() / "imu.gp";
  const auto r = run_cli({"imu", file.string(), "--gyro", "2,3", "--gyro-unit", "deg/s", "--accel", "4", "--accel-unit",
                          "g", "--plot-script", script.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string gp = slurp(script);
  for (const char* key : {"t 'gyro/x", "t 'gyro/y", "t 'accel/z"}) EXPECT_TRUE(has(gp, key)) << key << "\n" << gp;
  // One channel through analyze: its figure's title names the column whole.
  const auto one = dir.path() / "one.gp";
  const auto a = run_cli({"analyze", file.string(), "--column", "accel/z", "--rate-unit", "g", "--input", "rate",
                          "--plot-script", one.string()});
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_TRUE(has(slurp(one), "accel/z")) << slurp(one);
}
