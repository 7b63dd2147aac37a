// Every case of the bad-input corpus (tests/bad_input/MANIFEST.tsv) through the command line:
// `rwcalc analyze FILE OPTIONS` exits with the documented status and prints one error naming the
// file and the line; accepted inputs are either analysed or refused by the analysis with its own
// message (these records are a few samples long) — never a crash, a hang or silence.
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

class CliBadInput : public ::testing::TestWithParam<Case> {};

TEST_P(CliBadInput, AnalyzeExitsWithTheDocumentedStatusNamingFileAndLine) {
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
  std::vector<std::string> args{"analyze", path};
  if (c.options != "-") {
    std::stringstream ss(c.options);
    for (std::string word; ss >> word;) args.push_back(word);
  }
  const auto r = rwcalc::test::run_cli(args);
  if (c.status == 0) {
    // Read without complaint; the analysis either runs or says why it cannot (too short).
    if (r.status == 0) {
      EXPECT_NE(r.out.find("rwcalc analyze"), std::string::npos) << r.out.substr(0, 400);
      EXPECT_TRUE(r.err.empty()) << r.err;
    } else {
      EXPECT_EQ(r.status, 1) << r.err;
      EXPECT_EQ(r.err.rfind("rwcalc: error: ", 0), 0u) << r.err;
      EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    }
    return;
  }
  EXPECT_EQ(r.status, c.status) << r.err;
  EXPECT_TRUE(r.out.empty()) << "nothing is printed on standard output for a refused input";
  const std::string where = c.line ? path + ":" + std::to_string(c.line) + ": " : path + ": ";
  EXPECT_EQ(r.err.rfind("rwcalc: error: " + where, 0), 0u) << r.err;
  EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line of diagnosis: " << r.err;
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string n;
  for (char ch : info.param.file) n += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Corpus, CliBadInput, ::testing::ValuesIn(load_manifest()), case_name);

}  // namespace
