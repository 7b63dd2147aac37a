// The reader: every accepted format variant, through read_recording_text and through files
// (plain, gzip, standard input), and the conversions of each input mode.
#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/units.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::AngleUnit;
using rwcalc::InputMode;
using rwcalc::PhaseKind;
using rwcalc::RateSource;
using rwcalc::RateUnit;
using rwcalc::read_recording;
using rwcalc::read_recording_text;
using rwcalc::ReadOptions;
using rwcalc::Recording;
using rwcalc::test::TempDir;

std::string gzip(const std::string& text) {
  z_stream zs{};
  EXPECT_EQ(deflateInit2(&zs, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&zs, text.size()) + 64, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  zs.avail_in = static_cast<uInt>(text.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

std::vector<std::int64_t> cumulative(const std::vector<std::int64_t>& c) {
  std::vector<std::int64_t> out{0};
  for (auto v : c) out.push_back(out.back() + v);
  return out;
}

const std::vector<std::int64_t> kPulses{3, -1, 0, 2, 7, 1};

// The same six pulses in every layout must give the same exact counts.
void expect_pulses(const Recording& r) {
  EXPECT_EQ(r.samples, kPulses.size());
  EXPECT_EQ(r.phase.counts, cumulative(kPulses));
  EXPECT_TRUE(r.phase.values.empty());
  EXPECT_EQ(r.phase.kind, PhaseKind::Gyro);
}

TEST(Reader, SingleColumnPulsesWithDefaults) {
  const auto r = read_recording_text("3\n-1\n0\n2\n7\n1\n", "p.txt");
  expect_pulses(r);
  EXPECT_DOUBLE_EQ(r.rate_hz, 400.0);
  EXPECT_EQ(r.rate_source, RateSource::Default);
  EXPECT_DOUBLE_EQ(r.phase.tau0_s, 0.0025);
  EXPECT_DOUBLE_EQ(r.phase.arcsec_per_count, 0.92);
  EXPECT_EQ(r.column_name, "column 1");
  EXPECT_FALSE(r.time_column.has_value());
  EXPECT_EQ(r.source, "p.txt");
  // Rate of sample 0: 3 pulses × 0.92″ / 2.5 ms = 1104 ″/s = °/h.
  EXPECT_DOUBLE_EQ(r.rates().at(0), 3 * 0.92 / 0.0025);
}

TEST(Reader, NoFinalNewlineAndHeaderRow) { expect_pulses(read_recording_text("pulses\n3\n-1\n0\n2\n7\n1", "p.txt")); }

TEST(Reader, EveryDelimiterGivesTheSameSamples) {
  for (const char* text : {"time_s,pulses\n0,3\n0.0025,-1\n0.005,0\n0.0075,2\n0.01,7\n0.0125,1\n",
                           "time_s;pulses\n0;3\n0.0025;-1\n0.005;0\n0.0075;2\n0.01;7\n0.0125;1\n",
                           "time_s\tpulses\n0\t3\n0.0025\t-1\n0.005\t0\n0.0075\t2\n0.01\t7\n0.0125\t1\n",
                           "time_s pulses\n 0   3\n0.0025 -1\n0.005\t0\n0.0075  2  \n0.01 7\n0.0125 1\n",
                           "0, 3\n0.0025 ,-1\n0.005,0\n0.0075,2\n0.01,7\n0.0125,1\n"}) {
    SCOPED_TRACE(text);
    const auto r = read_recording_text(text, "d.txt");
    expect_pulses(r);
    EXPECT_EQ(r.rate_source, RateSource::TimeColumn);
    EXPECT_DOUBLE_EQ(r.rate_hz, 400.0);
  }
}

TEST(Reader, RussianLocaleSpreadsheetExportWithDecimalComma) {
  const auto r = read_recording_text("время;pulses\n0,0000;3\n0,0025;-1\n0,0050;0\n0,0075;2\n0,0100;7\n0,0125;1\n",
                                     "ru.csv", {.column = "2"});
  expect_pulses(r);
  EXPECT_DOUBLE_EQ(r.rate_hz, 400.0);  // 1-based index given; no time column by name, so default
  // With the standard name the time column is used and checked.
  const auto t =
      read_recording_text("time_s;pulses\n0,0000;3\n0,0025;-1\n0,0050;0\n0,0075;2\n0,0100;7\n0,0125;1\n", "ru.csv");
  expect_pulses(t);
  EXPECT_EQ(t.rate_source, RateSource::TimeColumn);
  // Decimal comma in rate samples, tab- and blank-separated.
  ReadOptions rate{.mode = InputMode::Rate, .rate_hz = 400.0, .rate_unit = RateUnit::DegPerHour};
  const auto a = read_recording_text("0,0025\t1,5\n0,005\t-2,25\n0,0075\t4\n", "tab.csv", rate);
  const auto b = read_recording_text("0,0025 1,5\n0,005 -2,25\n0,0075 4\n", "blank.csv", rate);
  const auto c = read_recording_text("0.0025,1.5\n0.005,-2.25\n0.0075,4\n", "point.csv", rate);
  EXPECT_EQ(a.phase.values, c.phase.values);
  EXPECT_EQ(b.phase.values, c.phase.values);
  EXPECT_DOUBLE_EQ(c.rates()[1], -2.25);
}

TEST(Reader, CrlfBomAndClassicMacLineEnds) {
  expect_pulses(read_recording_text("\xEF\xBB\xBFpulses\r\n3\r\n-1\r\n0\r\n2\r\n7\r\n1\r\n", "w.txt"));
  expect_pulses(
      read_recording_text("# made on Windows\r\ntime_s,pulses\r\n0,3\r\n0.0025,-1\r\n0.005,0\r\n"
                          "0.0075,2\r\n0.01,7\r\n0.0125,1\r\n",
                          "w.txt"));
  expect_pulses(read_recording_text("pulses\r3\r-1\r0\r2\r7\r1\r", "mac.txt"));
}

TEST(Reader, TimePulsesTemperatureColumns) {
  const auto r = read_recording_text(
      "time_s,pulses,temperature_c\n10,3,20\n10.0025,-1,21\n10.005,0,22\n"
      "10.0075,2,23\n10.01,7,24\n10.0125,1,25\n",
      "t.csv");
  expect_pulses(r);
  ASSERT_TRUE(r.temperature_c.has_value());
  EXPECT_DOUBLE_EQ(*r.temperature_c, 22.5);
  EXPECT_EQ(r.time_column, "time_s");
  // Headerless three-column layout means the same.
  const auto h =
      read_recording_text("10,3,20\n10.0025,-1,21\n10.005,0,22\n10.0075,2,23\n10.01,7,24\n10.0125,1,25\n", "t.csv");
  expect_pulses(h);
  EXPECT_DOUBLE_EQ(*h.temperature_c, 22.5);
}

TEST(Reader, MetadataLinesAndPrecedence) {
  const std::string text =
      "# GL-2D bench run: static, north axis\n"
      "# rate_hz: 200\n# scale_arcsec_per_pulse: 0,9\n# temperature_c: 21.5\n# serial: 0417\n"
      "# operator: Fomin\n# operator: Bolotnov\npulses\n3\n-1\n0\n2\n7\n1\n";
  const auto r = read_recording_text(text, "m.txt");
  expect_pulses(r);
  EXPECT_DOUBLE_EQ(r.rate_hz, 200.0);
  EXPECT_EQ(r.rate_source, RateSource::Metadata);
  EXPECT_DOUBLE_EQ(r.phase.arcsec_per_count, 0.9);
  EXPECT_DOUBLE_EQ(*r.temperature_c, 21.5);
  EXPECT_EQ(r.metadata.at("serial"), "0417");
  EXPECT_EQ(r.metadata.at("operator"), "Fomin; Bolotnov");  // repeated keys: nothing dropped
  EXPECT_EQ(r.metadata.count("GL-2D bench run"), 0u);       // prose comments are not metadata
  const auto o = read_recording_text(text, "m.txt", {.rate_hz = 400.0, .scale_arcsec = 1.0});
  EXPECT_DOUBLE_EQ(o.rate_hz, 400.0);
  EXPECT_EQ(o.rate_source, RateSource::Option);
  EXPECT_DOUBLE_EQ(o.phase.arcsec_per_count, 1.0);
}

TEST(Reader, RateOptionAndTimeColumnThatAgree) {
  const auto r = read_recording_text("t,pulses\n0,1\n0.01,2\n0.02,3\n", "t.csv", {.rate_hz = 100.0});
  EXPECT_EQ(r.rate_source, RateSource::Option);
  EXPECT_EQ(r.time_column, "t");
  // Time stamps printed with jitter inside the tolerance are accepted; the rate is estimated.
  const auto j = read_recording_text("0.000,1\n0.01001,2\n0.01999,3\n0.030,4\n", "j.csv");
  EXPECT_DOUBLE_EQ(j.rate_hz, 100.0);
}

TEST(Reader, ColumnByNameAndByIndex) {
  const std::string text = "gyro_x_dps,gyro_y_dps,gyro_z_dps\n0.1,0.2,0.3\n0.4,0.5,0.6\n0.7,0.8,0.9\n";
  ReadOptions o{.mode = InputMode::Rate, .column = "gyro_y_dps", .rate_hz = 100.0, .rate_unit = RateUnit::DegPerSecond};
  const auto byname = read_recording_text(text, "imu.csv", o);
  o.column = "2";
  const auto byindex = read_recording_text(text, "imu.csv", o);
  EXPECT_EQ(byname.column_name, "gyro_y_dps");
  EXPECT_EQ(byindex.column_name, "gyro_y_dps");
  EXPECT_EQ(byname.phase.values, byindex.phase.values);
  EXPECT_NEAR(byname.rates()[1], 0.5 * 3600, 1e-9);
  // Case-insensitive names.
  o.column = "GYRO_Z_DPS";
  EXPECT_NEAR(read_recording_text(text, "imu.csv", o).rates()[2], 0.9 * 3600, 1e-9);
}

TEST(Reader, BlankLinesAndCommentsInsideTheDataKeepLineNumbers) {
  const auto r = read_recording_text("# head\npulses\n3\n-1\n\n# pause\n0\n2\n   \n7\n1\n", "b.txt");
  expect_pulses(r);
  EXPECT_EQ(r.line_of_sample(0), 3u);
  EXPECT_EQ(r.line_of_sample(1), 4u);
  EXPECT_EQ(r.line_of_sample(2), 7u);
  EXPECT_EQ(r.line_of_sample(3), 8u);
  EXPECT_EQ(r.line_of_sample(4), 10u);
  EXPECT_EQ(r.line_of_sample(5), 11u);
  EXPECT_EQ(r.line_of_sample(6), 0u);
  EXPECT_EQ(r.line_of_rate(2), 7u);
}

TEST(Reader, NumberSpellingsGiveIdenticalValues) {
  // The fast path (plain decimals) and the careful path (exponents, '+', long mantissas) must agree
  // to the bit with std::from_chars.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  std::string plain, exotic;
  std::vector<double> expect;
  for (int i = 0; i < 2000; ++i) {
    const double v = u(rng) * std::pow(10.0, static_cast<int>(rng() % 9) - 4);
    plain += fmt::format("{:.17g}\n", v);
    exotic += fmt::format("{:+.16e}\n", v);
    expect.push_back(v);
    plain += fmt::format("{:.6f}\n", v);
    exotic += fmt::format("{:+.16e}\n", std::stod(fmt::format("{:.6f}", v)));
    expect.push_back(std::stod(fmt::format("{:.6f}", v)));
  }
  const ReadOptions o{.mode = InputMode::Angle, .rate_hz = 400.0};
  const auto a = read_recording_text(plain, "plain.txt", o);
  const auto b = read_recording_text(exotic, "exotic.txt", o);
  ASSERT_EQ(a.phase.values.size(), expect.size());
  for (std::size_t i = 0; i < expect.size(); ++i) {
    ASSERT_EQ(a.phase.values[i], expect[i]) << i;
    ASSERT_EQ(b.phase.values[i], expect[i]) << i;
  }
  // "+3" and "3" are the same pulse count.
  expect_pulses(read_recording_text("+3\n-1\n+0\n2\n+7\n1\n", "plus.txt"));
}

TEST(Reader, CounterModeUnwrapsAndCountsWraps) {
  // 8-bit counter: 250 → 254 → 3 (wrap: +5) → 10 → 9 (backwards: taken as a wrap, +255).
  const auto r = read_recording_text("250\n254\n3\n10\n9\n", "c.txt", {.mode = InputMode::Counter, .counter_bits = 8});
  EXPECT_EQ(r.phase.counts, (std::vector<std::int64_t>{0, 4, 9, 16, 271}));
  EXPECT_EQ(r.counter_wraps, 2u);
  EXPECT_EQ(r.samples, 5u);
  EXPECT_EQ(r.line_of_rate(0), 2u);  // increment 0 ends at the second reading
  // 64-bit counter printed unsigned across the wrap point.
  const auto w = read_recording_text("18446744073709551614\n18446744073709551615\n0\n2\n", "c64.txt",
                                     {.mode = InputMode::Counter, .counter_bits = 64});
  EXPECT_EQ(w.phase.counts, (std::vector<std::int64_t>{0, 1, 2, 4}));
  // Signed readings of a 16-bit counter are the same residues.
  const auto s = read_recording_text("-2\n-1\n0\n1\n", "c16.txt", {.mode = InputMode::Counter, .counter_bits = 16});
  EXPECT_EQ(s.phase.counts, (std::vector<std::int64_t>{0, 1, 2, 3}));
}

TEST(Reader, PulsesNearTwoToTheSixtyTwoStayExact) {
  const std::int64_t big = std::int64_t{1} << 62;
  const auto r = read_recording_text(fmt::format("{}\n3\n-1\n0\n2\n7\n1\n", big), "big.txt");
  ASSERT_EQ(r.phase.counts.size(), 8u);
  EXPECT_EQ(r.phase.counts[1], big);
  for (std::size_t i = 0; i < kPulses.size(); ++i)
    EXPECT_EQ(r.phase.diff(i + 2, i + 1), static_cast<double>(kPulses[i]) * 0.92);
  // Up to Σ|c| = 2^63 − 1 is accepted; one more count is refused (second differences could wrap).
  const std::int64_t max = std::numeric_limits<std::int64_t>::max();
  const auto m = read_recording_text(fmt::format("{}\n-1\n", max - 1), "max.txt");
  EXPECT_EQ(m.phase.counts.back(), max - 2);
  EXPECT_THROW((void)read_recording_text(fmt::format("{}\n-2\n", max - 1), "over.txt"), rwcalc::InputError);
}

TEST(Reader, AngleUnitsConvertToArcsecondsOrClockSeconds) {
  const std::string text = "1\n2\n4\n";
  auto a =
      read_recording_text(text, "a", {.mode = InputMode::Angle, .rate_hz = 400.0, .angle_unit = AngleUnit::Arcsec});
  EXPECT_EQ(a.phase.values, (std::vector<double>{1, 2, 4}));
  EXPECT_EQ(a.phase.kind, PhaseKind::Gyro);
  auto d = read_recording_text(text, "a", {.mode = InputMode::Angle, .rate_hz = 400.0, .angle_unit = AngleUnit::Deg});
  EXPECT_EQ(d.phase.values, (std::vector<double>{3600, 7200, 14400}));
  auto r = read_recording_text(text, "a", {.mode = InputMode::Angle, .rate_hz = 400.0, .angle_unit = AngleUnit::Rad});
  EXPECT_DOUBLE_EQ(r.phase.values[2], 4 * 180.0 * 3600.0 / M_PI);
  auto s = read_recording_text(text, "a", {.mode = InputMode::Angle, .rate_hz = 1.0, .angle_unit = AngleUnit::Second});
  EXPECT_EQ(s.phase.values, (std::vector<double>{1, 2, 4}));
  EXPECT_EQ(s.phase.kind, PhaseKind::Clock);
  EXPECT_EQ(s.phase.deviation_unit(), "1");
  EXPECT_EQ(s.rates(), (std::vector<double>{1, 2}));
}

TEST(Reader, RateInputIsIntegratedToPhaseAsSp1065) {
  // NBS14 frequency data (τ0 = 1 s): x_0 = 0, x_j = Σ_{i<j} y_i.
  const std::vector<double> y{892, 809, 823, 798, 671, 644, 883, 903, 677};
  std::string text;
  for (double v : y) text += fmt::format("{}\n", v);
  const auto c = read_recording_text(text, "nbs14.txt",
                                     {.mode = InputMode::Rate, .rate_hz = 1.0, .rate_unit = RateUnit::Unitless});
  ASSERT_EQ(c.phase.values.size(), y.size() + 1);
  // The mean rate is kept apart (PhaseSeries::rate_offset); the phase adds it back.
  double x = 0;
  EXPECT_EQ(c.phase.at(0), 0.0);
  for (std::size_t i = 0; i < y.size(); ++i) {
    x += y[i];
    EXPECT_NEAR(c.phase.at(i + 1), x, 1e-9 * x);
  }
  EXPECT_NEAR(c.phase.rate_offset, 7100.0 / 9.0, 1e-9);
  EXPECT_EQ(c.phase.kind, PhaseKind::Clock);
  // Gyro units: deg/s and rad/s become ″/s (= °/h).
  const auto ds = read_recording_text("0.5\n-0.25\n", "g",
                                      {.mode = InputMode::Rate, .rate_hz = 400.0, .rate_unit = RateUnit::DegPerSecond});
  EXPECT_DOUBLE_EQ(ds.rates()[0], 1800.0);
  EXPECT_DOUBLE_EQ(ds.rates()[1], -900.0);
  const auto rs = read_recording_text("1e-5\n2e-5\n", "g",
                                      {.mode = InputMode::Rate, .rate_hz = 400.0, .rate_unit = RateUnit::RadPerSecond});
  EXPECT_NEAR(rs.rates()[1], 2e-5 * rwcalc::units::arcsec_per_rad, 1e-9);
}

TEST(Reader, FilesGzipAndStandardInput) {
  TempDir tmp;
  const std::string text = "# rate_hz: 400\ntime_s,pulses\n0,3\n0.0025,-1\n0.005,0\n0.0075,2\n0.01,7\n0.0125,1\n";
  const auto plain = tmp.write("run.csv", text);
  const auto gz = tmp.write("run.csv.gz", gzip(text));
  const auto noext = tmp.write("run.dat", gzip(text));  // detected by content, not by name
  const auto multi = tmp.write("multi.gz", gzip(text.substr(0, 40)) + gzip(text.substr(40)));
  for (const auto& p : {plain, gz, noext, multi}) {
    SCOPED_TRACE(p);
    const auto r = read_recording(p.string());
    expect_pulses(r);
    EXPECT_EQ(r.source, p.string());
  }
  expect_pulses(read_recording_text(gzip(text), "mem.gz"));

  // "-" reads standard input: point fd 0 at the file for the call, then restore it.
  for (const auto& p : {plain, gz}) {
    const int saved = ::dup(STDIN_FILENO);
    const int fd = ::open(p.c_str(), O_RDONLY);
    ASSERT_GE(fd, 0);
    ::dup2(fd, STDIN_FILENO);
    ::close(fd);
    Recording r;
    try {
      r = read_recording("-");
    } catch (...) {
      ::dup2(saved, STDIN_FILENO);
      ::close(saved);
      throw;
    }
    ::dup2(saved, STDIN_FILENO);
    ::close(saved);
    expect_pulses(r);
    EXPECT_EQ(r.source, "-");
  }
}

TEST(Reader, LargeRecordThroughTheFastPathMatchesTheCarefulPath) {
  // 200 000 lines: plain lines take the fast path; the same values spelled with '+' and spaces
  // go through the careful path. Both must give identical counts.
  std::mt19937_64 rng(11);
  std::string fast = "time_s,pulses\n", careful = "time_s , pulses\n";
  std::vector<std::int64_t> c;
  for (int i = 0; i < 200000; ++i) {
    const auto v = static_cast<std::int64_t>(rng() % 21) - 10;
    c.push_back(v);
    fast += fmt::format("{:.4f},{}\n", i * 0.0025, v);
    careful += fmt::format(" {:.6e} ,\t{:+d} \n", i * 0.0025, v);
  }
  const auto a = read_recording_text(fast, "fast.csv");
  ASSERT_NO_THROW((void)read_recording_text(fast, "fast.csv"));
  EXPECT_EQ(a.phase.counts, cumulative(c));
  EXPECT_DOUBLE_EQ(a.rate_hz, 400.0);
  // Tabs after a comma are mixed delimiters; spaces are fine.
  EXPECT_THROW((void)read_recording_text(careful, "careful.csv"), rwcalc::InputError);
  std::string spaced = careful;
  for (char& ch : spaced)
    if (ch == '\t') ch = ' ';
  EXPECT_EQ(read_recording_text(spaced, "careful.csv").phase.counts, a.phase.counts);
}

TEST(Reader, ParseNamesAndUsageErrors) {
  EXPECT_EQ(rwcalc::parse_input_mode("counter"), InputMode::Counter);
  EXPECT_EQ(rwcalc::parse_angle_unit("s"), AngleUnit::Second);
  EXPECT_EQ(rwcalc::parse_rate_unit("1"), RateUnit::Unitless);
  EXPECT_THROW(rwcalc::parse_input_mode("volts"), rwcalc::UsageError);
  EXPECT_THROW(rwcalc::parse_angle_unit("grad"), rwcalc::UsageError);
  EXPECT_THROW(rwcalc::parse_rate_unit("rpm"), rwcalc::UsageError);
  EXPECT_THROW((void)read_recording_text("1\n2\n", "x", {.rate_hz = -5.0}), rwcalc::UsageError);
  EXPECT_THROW((void)read_recording_text("1\n2\n", "x", {.counter_bits = 65}), rwcalc::UsageError);
  for (auto m : {InputMode::Pulses, InputMode::Counter, InputMode::Angle, InputMode::Rate})
    EXPECT_EQ(rwcalc::parse_input_mode(rwcalc::to_string(m)), m);
}

}  // namespace
