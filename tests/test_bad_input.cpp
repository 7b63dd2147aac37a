// The bad-input corpus (tests/bad_input/MANIFEST.tsv): every case gives its documented exit status
// and a message naming the file, the line and the offending text. Cases named "@…" are made here
// (paths that cannot be committed, and lines of megabytes).
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

struct Case {
  std::string file, options;
  int status = 0;
  std::string fragment;
  std::size_t line = 0;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.file << " [" << c.options << "]"; }

std::vector<Case> load_manifest() {
  std::vector<Case> cases;
  std::ifstream in(rwcalc::test::source_path("tests/bad_input/MANIFEST.tsv"));
  std::string row;
  while (std::getline(in, row)) {
    if (row.empty() || row[0] == '#') continue;
    std::vector<std::string> f;
    std::stringstream ss(row);
    for (std::string cell; std::getline(ss, cell, '\t');) f.push_back(cell);
    if (f.size() != 5) throw std::runtime_error("MANIFEST.tsv: bad row: " + row);
    cases.push_back({f[0], f[1], std::stoi(f[2]), f[3], static_cast<std::size_t>(std::stoul(f[4]))});
  }
  return cases;
}

// The input options of a manifest row, written as on the command line.
rwcalc::ReadOptions parse_options(const std::string& text) {
  rwcalc::ReadOptions o;
  if (text == "-") return o;
  std::stringstream ss(text);
  std::string key, value;
  while (ss >> key >> value) {
    if (key == "--input") o.mode = rwcalc::parse_input_mode(value);
    else if (key == "--rate") o.rate_hz = std::stod(value);
    else if (key == "--scale") o.scale_arcsec = std::stod(value);
    else if (key == "--column") o.column = value;
    else if (key == "--counter-bits") o.counter_bits = std::stoi(value);
    else if (key == "--angle-unit") o.angle_unit = rwcalc::parse_angle_unit(value);
    else if (key == "--rate-unit") o.rate_unit = rwcalc::parse_rate_unit(value);
    else if (key == "--time-tolerance") o.time_tolerance = std::stod(value);
    else throw std::runtime_error("MANIFEST.tsv: unknown option " + key);
  }
  return o;
}

class BadInput : public ::testing::TestWithParam<Case> {};

TEST_P(BadInput, GivesItsDocumentedStatusAndMessage) {
  const Case& c = GetParam();
  rwcalc::test::TempDir tmp;
  std::string path;
  constexpr std::size_t kHuge = 5u << 20;  // a 5 MB line
  if (c.file == "@missing") {
    path = (tmp.path() / "no-such-recording.csv").string();
  } else if (c.file == "@directory") {
    path = tmp.path().string();
  } else if (c.file == "@unreadable") {
    if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions do not stop reading";
    path = tmp.write("locked.csv", "1\n2\n").string();
    ::chmod(path.c_str(), 0);
  } else if (c.file == "@huge_digit_line") {
    path = tmp.write("digits.csv", "pulses\n1\n" + std::string(kHuge, '7') + "\n2\n").string();
  } else if (c.file == "@huge_float_line") {
    path = tmp.write("float.csv", "rate\n0.5\n1" + std::string(kHuge, '0') + ".5\n2\n").string();
  } else if (c.file == "@huge_text_line") {
    path = tmp.write("text.csv", "pulses\n1\n" + std::string(kHuge, 'x') + "\n2\n").string();
  } else if (c.file == "@huge_header_line") {
    path = tmp.write("header.csv", std::string(kHuge, 'h') + "\n").string();
  } else {
    path = rwcalc::test::source_path("tests/bad_input/" + c.file).string();
  }
  const auto options = parse_options(c.options);
  if (c.status == 0) {
    const auto r = rwcalc::read_recording(path, options);
    EXPECT_EQ("samples=" + std::to_string(r.samples), c.fragment);
    return;
  }
  try {
    (void)rwcalc::read_recording(path, options);
    FAIL() << c.file << " was accepted";
  } catch (const rwcalc::InputError& e) {
    EXPECT_EQ(static_cast<int>(e.code()), c.status);
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), c.line) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(c.fragment), std::string::npos) << what;
    const std::string prefix = c.line ? path + ":" + std::to_string(c.line) + ": " : path + ": ";
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
    EXPECT_LT(what.size(), path.size() + 400) << "messages quote at most ~40 characters of the input";
  }
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string n;
  for (char ch : info.param.file) n += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(load_manifest()), case_name);

TEST(BadInputCorpus, ManifestListsEveryCommittedFile) {
  const auto cases = load_manifest();
  EXPECT_GE(cases.size(), 40u);
  for (const auto& entry : std::filesystem::directory_iterator(rwcalc::test::source_path("tests/bad_input"))) {
    const auto name = entry.path().filename().string();
    if (name == "MANIFEST.tsv") continue;
    EXPECT_TRUE(std::any_of(cases.begin(), cases.end(), [&](const Case& c) { return c.file == name; }))
        << name << " is not in MANIFEST.tsv";
  }
}

TEST(BadInputCorpus, InMemoryTextGivesTheSameErrorsAsFiles) {
  try {
    (void)rwcalc::read_recording_text("pulses\n3\n1\nabc\n2\n", "mem.txt");
    FAIL();
  } catch (const rwcalc::InputError& e) {
    EXPECT_EQ(e.line(), 4u);
    EXPECT_STREQ(e.what(), "mem.txt:4: not a number in column 'pulses': 'abc'");
  }
  EXPECT_THROW((void)rwcalc::read_recording_text("", "empty"), rwcalc::InputError);
  EXPECT_THROW((void)rwcalc::read_recording("", {}), rwcalc::InputError);
}

}  // namespace
