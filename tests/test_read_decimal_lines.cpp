// Decimal columns read in bulk: read_decimal gives what std::from_chars gives, bit for bit, on
// hostile spellings and on random short decimals; a line read in bulk gives the values or the
// error the general way gives; long texts read in two halves give every value of one thread; and
// rate samples without a rate are refused before the samples are read.
#include <bit>
#include <charconv>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "io/decimal.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::read_recording_text;
using rwcalc::ReadOptions;
using rwcalc::Recording;

// read_decimal and std::from_chars on the same bytes: the same error, the same end and the same
// bits (a value that does not read leaves the same sentinel in both).
void expect_same_as_from_chars(const std::string& s) {
  double mine = -7.25, theirs = -7.25;
  const auto a = rwcalc::detail::read_decimal(s.data(), s.data() + s.size(), mine);
  const auto b = std::from_chars(s.data(), s.data() + s.size(), theirs);
  EXPECT_EQ(a.ec, b.ec) << '"' << s << '"';
  EXPECT_EQ(a.ptr - s.data(), b.ptr - s.data()) << '"' << s << '"';
  EXPECT_EQ(std::bit_cast<std::uint64_t>(mine), std::bit_cast<std::uint64_t>(theirs)) << '"' << s << '"';
}

TEST(ReadDecimal, HostileSpellingsReadAsFromChars) {
  for (const char* s : {"0",
                        "-0",
                        "-0.000",
                        "0.1",
                        "-0.00666",
                        "1.01565",
                        "000.5",
                        "5.",
                        ".5",
                        "-.5",
                        "-",
                        "--1",
                        "+1",
                        "1e5",
                        "1E-5",
                        "1.5e",
                        "1.5e+",
                        "2.5.5",
                        "1,5",
                        "1.5,2",
                        "1.5\n",
                        "1.5\r\n",
                        "1.5 ",
                        " 1.5",
                        "inf",
                        "-inf",
                        "nan",
                        "infinity",
                        "0x10",
                        "1e400",
                        "-1e400",
                        "1e-400",
                        "9007199254740992",
                        "9007199254740993",
                        "-9007199254740993",
                        "900719925474099.3",
                        "900719925474099.2",
                        "9007199254740992.5",
                        "1234567890123456789",
                        "12345678901234567890",
                        "0.1234567890123456789",
                        "0.123456789012345678",
                        "18446744073709551616",
                        "99999999999999999999.5",
                        "0.000000000000000001",
                        "0.0000000000000000001",
                        "3.14159265358979323846",
                        "1.7976931348623157e308",
                        "1e22",
                        "1e23",
                        "123456.7890123",
                        "7.",
                        "abc",
                        "",
                        "1d5",
                        "1.5f",
                        "٣"}) {
    expect_same_as_from_chars(s);
  }
}

TEST(ReadDecimal, RandomShortDecimalsReadAsFromChars) {
  std::mt19937_64 rng(41);
  const std::string ends[] = {"", ",", "\n", "\r\n", ";", "e", "e7", "E-3", ".", "x", " "};
  for (int i = 0; i < 400000; ++i) {
    std::string s = rng() % 3 == 0 ? "-" : "";
    const auto digits = 1 + rng() % 20;
    const auto point = rng() % (digits + 2);  // beyond the digits: no point
    for (std::uint64_t d = 0; d < digits; ++d) {
      if (d == point && d > 0) s += '.';
      s += static_cast<char>('0' + (d == 0 && rng() % 4 ? 1 + rng() % 9 : rng() % 10));
    }
    s += ends[rng() % std::size(ends)];
    expect_same_as_from_chars(s);
  }
}

// What reading `text` gives: the phase values, or the error's message.
std::string outcome(const std::string& text, const ReadOptions& o, std::vector<double>& values) {
  values.clear();
  try {
    values = read_recording_text(text, "d.csv", o).phase.values;
  } catch (const rwcalc::Error& e) {
    return e.what();
  }
  return "";
}

std::string with_delimiter(std::string s, char d) {
  for (char& c : s)
    if (c == ' ') c = d;
  return s;
}

// Each spelling as the fifth line of a file of columns a, b, c separated by `d`: after a data line
// (read in bulk) and after a comment (the general way). The two reads must agree on the values (bit
// for bit) or on the error.
void expect_bulk_as_general(char d, const std::vector<std::string>& lines, const ReadOptions& o) {
  const auto text = [d](const char* before, const std::string& l) {
    return with_delimiter(fmt::format("a b c\n{}", before), d) + l + "\n" + with_delimiter("7 8 9\n", d);
  };
  for (const std::string& l : lines) {
    std::vector<double> bulk, general;
    const std::string a = outcome(text("1 2 3\n#\n4 5 6\n", l), o, bulk);
    const std::string b = outcome(text("1 2 3\n4 5 6\n#\n", l), o, general);
    EXPECT_EQ(a, b) << '"' << l << '"';
    ASSERT_EQ(bulk.size(), general.size()) << '"' << l << '"';
    for (std::size_t i = 0; i < bulk.size(); ++i)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(bulk[i]), std::bit_cast<std::uint64_t>(general[i])) << '"' << l << '"';
  }
}

const ReadOptions kAngle{.mode = rwcalc::InputMode::Angle, .column = "b", .rate_hz = 100.0};

TEST(ReadDecimalLines, EveryDelimitedSpellingReadsAsTheGeneralWay) {
  const std::vector<std::string> fields = {"1,2,3",
                                           "1, 2,3",
                                           "1,2 ,3",
                                           " 1,2,3",
                                           "1,2,3 ",
                                           "1,+2,3",
                                           "1,2,3\r",
                                           "1,2\r,3",
                                           "1,2;3",
                                           "1,2\t,3",
                                           "1,2,3,4",
                                           "1,2",
                                           "1,,3",
                                           ",2,",
                                           "x,2,y",
                                           "1,2e5,3",
                                           "1,2E-5,3",
                                           "1,.5,3",
                                           "1,5.,3",
                                           "1,-0,3",
                                           "1,inf,3",
                                           "1,nan,3",
                                           "1,1e400,3",
                                           "1,0x10,3",
                                           "1,--2,3",
                                           "1,2.5.5,3",
                                           "#1,2,3",
                                           "",
                                           "\r",
                                           "1,9007199254740993,3",
                                           "1,-,3",
                                           "a b,2,c",
                                           "1,2,c \r",
                                           "1,2,3\t",
                                           "1,12345678901234567890,3",
                                           "1,0.1234567890123456789,3",
                                           "1,2,\"x\"",
                                           "1,2 # c,3",
                                           "b,b,b",
                                           "a,b,c"};
  for (const char d : {',', ';', '\t'}) {
    std::vector<std::string> lines;
    for (const std::string& f : fields) {
      std::string l = f;
      if (d != ',')  // the same spellings with this delimiter, and with a decimal comma
        for (char& c : l)
          if (c == ',') c = d;
      lines.push_back(l);
    }
    if (d != ',') lines.insert(lines.end(), {with_delimiter("1 2,5 3", d), with_delimiter("1 -0,5 3", d)});
    expect_bulk_as_general(d, lines, kAngle);
  }
}

TEST(ReadDecimalLines, EveryBlankSeparatedSpellingReadsAsTheGeneralWay) {
  expect_bulk_as_general(' ',
                         {"1 2 3", "  1   2\t3  ", "1 2 3\r", "1 2 3 \r", "1 2\r 3", "1 2;3", "1 2", "1 2 3 4",
                          "1 +2 3", "# 1 2 3", "1 2e3 3", "1\t2\t3", "\t1 2 3", "1 2,5 3", "1 nan 3", " ", "a b c"},
                         kAngle);
}

// 200 000 lines of three columns, many pieces long, so that stretches are read in two halves: every
// value is the one std::from_chars gives its field, on one thread and on two, for each column and
// for the three read in one pass.
TEST(ReadDecimalLines, LongTextReadInHalvesGivesEveryValue) {
  std::mt19937_64 rng(7);
  std::string text = "# rate_hz: 200\ngx,gy,gz\n";
  std::vector<std::vector<double>> want(3, std::vector<double>{});
  for (int i = 0; i < 200000; ++i) {
    for (int c = 0; c < 3; ++c) {
      const std::string f = fmt::format("{}{}.{:0{}}", rng() % 2 ? "-" : "", rng() % 3, rng() % 100000, 1 + rng() % 5);
      double v = 0;
      std::from_chars(f.data(), f.data() + f.size(), v);
      want[c].push_back(v);
      text += f + (c < 2 ? "," : i % 1000 == 7 ? "\r\n" : "\n");
    }
    if (i % 20011 == 5) text += "# a note\n";
  }
  for (const char* threads : {"1", "2"}) {
    const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
    for (int c = 0; c < 3; ++c) {
      const ReadOptions o{.mode = rwcalc::InputMode::Angle, .column = fmt::format("g{}", "xyz"[c])};
      const Recording r = read_recording_text(text, "long.csv", o);
      EXPECT_EQ(r.phase.values, want[c]) << threads << " threads, column " << c;
      EXPECT_EQ(r.rate_hz, 200.0);
    }
    const rwcalc::test::TempDir dir;
    const std::vector<ReadOptions> columns = {{.column = "gx"}, {.column = "gy"}, {.column = "gz"}};
    std::vector<ReadOptions> angle = columns;
    for (ReadOptions& o : angle) o.mode = rwcalc::InputMode::Angle;
    const std::vector<Recording> recs = rwcalc::read_recordings(dir.write("long.csv", text).string(), angle);
    ASSERT_EQ(recs.size(), 3u);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(recs[c].phase.values, want[c]) << threads << " threads, one pass";
  }
}

// A bad field anywhere in a long text, read in bulk or in a second half: the error names its line,
// as reading line by line does.
TEST(ReadDecimalLines, ABadFieldInALongTextNamesItsLine) {
  for (const std::size_t at : {std::size_t{3}, std::size_t{4099}, std::size_t{51234}, std::size_t{99998}}) {
    std::string text = "# rate_hz: 100\na,b\n";
    for (std::size_t i = 0; i < 100000; ++i) text += i == at ? "0.5,0.x\n" : fmt::format("0.{},{}.25\n", i % 7, i % 3);
    try {
      (void)read_recording_text(text, "bad.csv", {.mode = rwcalc::InputMode::Rate, .column = "b"});
      ADD_FAILURE() << "a bad field was taken at " << at;
    } catch (const rwcalc::InputError& e) {
      EXPECT_EQ(e.line(), at + 3);
      EXPECT_NE(e.message().find("not a number"), std::string::npos) << e.message();
    }
  }
}

// Rate samples without a rate are refused at the first data line: the error comes before a bad
// line further on is read, and a rate_hz line after the first data line does not count.
TEST(ReadDecimalLines, NoRateIsRefusedBeforeTheSamplesAreRead) {
  const ReadOptions rate{.mode = rwcalc::InputMode::Rate};
  for (const std::string text : {"gyro_x_dps\n1\n2\nnot a number\n", "gyro_x_dps\n1\n2\n# rate_hz: 100\n3\n"}) {
    try {
      (void)read_recording_text(text, "r.csv", rate);
      ADD_FAILURE() << text;
    } catch (const rwcalc::InputError& e) {
      EXPECT_NE(e.message().find("no sample rate"), std::string::npos) << e.message();
      EXPECT_NE(e.message().find("metadata line before the data"), std::string::npos) << e.message();
    }
  }
  try {
    (void)read_recording_text("# sampling_frequency: 100\ngyro_x_dps\n1\n2\nx\n", "k.csv", rate);
    ADD_FAILURE() << "a rate key rwcalc does not read was taken";
  } catch (const rwcalc::InputError& e) {
    EXPECT_EQ(e.line(), 1u);  // the key's line, not the bad line 5
    EXPECT_NE(e.message().find("looks like the sample rate"), std::string::npos) << e.message();
  }
  EXPECT_EQ(read_recording_text("# rate_hz: 100\ngyro_x_dps\n1\n2\n", "ok.csv", rate).rate_hz, 100.0);
  EXPECT_EQ(read_recording_text("pulses\n1\n2\n# rate_hz: 100\n3\n", "p.csv").rate_hz, 100.0);  // pulses: unchanged
}

}  // namespace
