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

#include "bad_input_corpus.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::test::bad_input_case_name;
using rwcalc::test::BadInputCase;
using rwcalc::test::load_bad_input_manifest;

// The input options of a manifest row, written as on the command line.
rwcalc::ReadOptions parse_options(const std::string& text) {
  rwcalc::ReadOptions o;
  if (text == "-") return o;
  std::stringstream ss(text);
  std::string key, value;
  while (ss >> key >> value) {
    if (key == "--input")
      o.mode = rwcalc::parse_input_mode(value);
    else if (key == "--rate")
      o.rate_hz = std::stod(value);
    else if (key == "--scale")
      o.scale_arcsec = std::stod(value);
    else if (key == "--column")
      o.column = value;
    else if (key == "--counter-bits")
      o.counter_bits = std::stoi(value);
    else if (key == "--angle-unit")
      o.angle_unit = rwcalc::parse_angle_unit(value);
    else if (key == "--rate-unit")
      o.rate_unit = rwcalc::parse_rate_unit(value);
    else if (key == "--time-tolerance")
      o.time_tolerance = std::stod(value);
    else if (key == "--time-column")
      o.time_column = value;
    else if (key == "--topic")
      o.topic = value;
    else
      throw std::runtime_error("MANIFEST.tsv: unknown option " + key);
  }
  return o;
}

class BadInput : public ::testing::TestWithParam<BadInputCase> {};

TEST_P(BadInput, GivesItsDocumentedStatusAndMessage) {
  const BadInputCase& c = GetParam();
  const rwcalc::test::TempDir tmp;
  const auto staged = rwcalc::test::stage_bad_input(c, tmp);
  if (!staged) GTEST_SKIP() << "running as root: permissions do not stop reading";
  const std::string& path = *staged;
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

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(load_bad_input_manifest()), bad_input_case_name);

TEST(BadInputCorpus, ManifestListsEveryCommittedFile) {
  const auto cases = load_bad_input_manifest();
  EXPECT_GE(cases.size(), 40u);
  for (const auto& entry : std::filesystem::directory_iterator(rwcalc::test::source_path("tests/bad_input"))) {
    const auto name = entry.path().filename().string();
    if (name == "MANIFEST.tsv") continue;
    EXPECT_TRUE(std::any_of(cases.begin(), cases.end(), [&](const BadInputCase& c) { return c.file == name; }))
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
