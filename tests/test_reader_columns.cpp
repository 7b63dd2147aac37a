// The reader never chooses silently between readings of a file: metadata keys in another case or
// with '=' are the known keys; time columns in ms, us or ns are read in their unit; two columns that
// could both be the samples, two time columns that disagree, or a key that looks like the sample
// rate when nothing else gives it are errors that say why and what to do.
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::InputError;
using rwcalc::read_recording_text;
using rwcalc::ReadOptions;

// The message of the InputError reading `text` throws ("" when it is accepted), with its line.
std::pair<std::string, std::size_t> error_of(const std::string& text, const ReadOptions& o = {}) {
  try {
    (void)read_recording_text(text, "mem.txt", o);
  } catch (const InputError& e) {
    return {e.message(), e.line()};
  }
  return {"", 0};
}

TEST(ReaderMetadataKeys, RateInAnyCaseWithColonOrEqualsSign) {
  for (const std::string line :
       {"# RATE_HZ: 100", "# rate_hz = 100", "# Rate-Hz=100", "#rate_hz :100", "# rate_Hz: 100,0"}) {
    const auto r = read_recording_text(line + "\npulses\n1\n2\n3\n", "mem.txt");
    EXPECT_EQ(r.rate_hz, 100.0) << line;
    EXPECT_EQ(r.rate_source, rwcalc::RateSource::Metadata) << line;
    EXPECT_EQ(r.metadata.count("rate_hz"), 1u) << line;  // kept under the key's own spelling
    EXPECT_EQ(r.metadata.size(), 1u) << line;
  }
}

TEST(ReaderMetadataKeys, ScaleTemperatureAndSerialInOtherSpellings) {
  const auto r =
      read_recording_text("# SCALE_ARCSEC_PER_PULSE = 2\n# Temperature_C: -5\n# Serial = 0417\npulses\n1\n2\n", "m");
  EXPECT_EQ(r.phase.arcsec_per_count, 2.0);
  ASSERT_TRUE(r.temperature_c);
  EXPECT_EQ(*r.temperature_c, -5.0);
  EXPECT_EQ(r.metadata.at("serial"), "0417");
  EXPECT_EQ(r.metadata.at("temperature_c"), "-5");
}

TEST(ReaderMetadataKeys, TwoSpellingsOfOneKeyMustAgree) {
  const auto [msg, line] = error_of("# rate_hz: 100\n# RATE_HZ = 200\npulses\n1\n2\n");
  EXPECT_NE(msg.find("metadata rate_hz given twice with different values ('100' and '200')"), std::string::npos) << msg;
  EXPECT_EQ(line, 2u);
  EXPECT_EQ(read_recording_text("# rate_hz: 100\n# Rate_Hz = 100\npulses\n1\n2\n", "m").rate_hz, 100.0);
}

TEST(ReaderMetadataKeys, OtherKeysAreKeptAsWrittenAndIdentificationKeysCanonical) {
  const auto r = read_recording_text(
      "# Bench_ID = B-12\n# Operator = Fomin\n# Test-Date: 2021-05-01\n# GL-2D bench run: static\npulses\n1\n2\n",
      "m");
  EXPECT_EQ(r.metadata.at("Bench_ID"), "B-12");
  EXPECT_EQ(r.metadata.at("operator"), "Fomin");  // an identification key, under its own spelling
  EXPECT_EQ(r.metadata.at("test_date"), "2021-05-01");
  EXPECT_EQ(r.metadata.count("GL-2D bench run"), 0u);
}

TEST(ReaderMetadataKeys, AKeyThatLooksLikeTheRateIsRefusedOnlyWhenNothingElseGivesTheRate) {
  for (const std::string key : {"sample_rate", "Sampling_Frequency", "fs", "rate", "freq_hz", "ODR"}) {
    const auto [msg, line] = error_of("# x: 1\n# " + key + ": 100\npulses\n1\n2\n");
    EXPECT_NE(msg.find("metadata '" + key + "' looks like the sample rate"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rate_hz"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--rate"), std::string::npos) << msg;
    EXPECT_EQ(line, 2u) << key;
  }
  ReadOptions o;
  o.rate_hz = 100;
  EXPECT_EQ(read_recording_text("# sample_rate: 100\npulses\n1\n2\n", "m", o).rate_hz, 100.0);
  EXPECT_EQ(read_recording_text("# sample_rate: 100\n# rate_hz: 50\npulses\n1\n2\n", "m").rate_hz, 50.0);
  EXPECT_EQ(read_recording_text("# sample_rate: 100\ntime_s,pulses\n0,1\n0.01,2\n", "m").rate_hz, 100.0);
  // Keys about other rates are not the sample rate.
  EXPECT_EQ(read_recording_text("# earth_rate_deg_per_h: 15\npulses\n1\n2\n", "m").rate_hz, 400.0);
}

TEST(ReaderMetadataKeys, AKeyThatLooksLikeThePulseWeightIsRefusedOnlyWhenNothingElseGivesIt) {
  const auto [msg, line] = error_of("# scale_factor: 1.5\npulses\n1\n2\n");
  EXPECT_NE(msg.find("metadata 'scale_factor' looks like the pulse weight"), std::string::npos) << msg;
  EXPECT_EQ(line, 1u);
  ReadOptions o;
  o.scale_arcsec = 1.5;
  EXPECT_EQ(read_recording_text("# scale_factor: 1.5\npulses\n1\n2\n", "m", o).phase.arcsec_per_count, 1.5);
  o = {};
  o.mode = rwcalc::InputMode::Rate;  // no pulse weight in rate input
  o.rate_hz = 100.0;
  EXPECT_NO_THROW((void)read_recording_text("# scale_factor: 1.5\nrate\n1\n2\n", "m", o));
}

TEST(ReaderTimeColumns, EveryUnitIsReadInItsUnit) {
  const std::vector<std::pair<std::string, double>> units{{"time_s", 1},    {"Time_MS", 1e3}, {"t_ms", 1e3},
                                                          {"time_us", 1e6}, {"t_us", 1e6},    {"time_ns", 1e9},
                                                          {"t_ns", 1e9}};
  for (const auto& [name, per_s] : units) {
    std::string text = name + ",pulses\n";
    for (int k = 0; k < 50; ++k) text += fmt::format("{},{}\n", k * 0.004 * per_s, k % 3);
    const auto r = read_recording_text(text, "m");
    EXPECT_EQ(r.rate_hz, 250.0) << name;
    EXPECT_EQ(r.rate_source, rwcalc::RateSource::TimeColumn) << name;
    EXPECT_EQ(r.time_column.value_or(""), name);
    // A gap is named by its stamps as written (in the column's unit) and the time missing in seconds.
    const auto [msg, line] = error_of(name + ",pulses\n0,1\n" +
                                      fmt::format("{},1\n{},1\n{},1\n", 0.004 * per_s, 0.008 * per_s, 0.016 * per_s));
    const std::string unit = r.time_unit;
    EXPECT_EQ(unit, name.substr(name.find('_') + 1) == "MS" ? "ms" : name.substr(name.find('_') + 1)) << name;
    EXPECT_NE(msg.find(fmt::format("gap in the time column: {} {} at line 4, then {} {}: 0.004 s missing",
                                   0.008 * per_s, unit, 0.016 * per_s, unit)),
              std::string::npos)
        << name << ": " << msg;
    EXPECT_EQ(line, 5u) << name;
  }
}

TEST(ReaderTimeColumns, TwoTimeColumnsAreUsedOnlyWhenTheyAgree) {
  const auto r = read_recording_text("time_s,time_ms,pulses\n0,0,1\n0.0025,2.5,0\n0.005,5,1\n", "m");
  EXPECT_EQ(r.rate_hz, 400.0);
  const auto [msg, line] = error_of("time_ms,pulses,time_s\n0,1,0\n2.5,0,0.0025\n5,1,0.0075\n7.5,1,0.0075\n");
  EXPECT_NE(msg.find("the time columns 'time_ms' and 'time_s' disagree: 5 ms and 0.0075 s"), std::string::npos) << msg;
  EXPECT_NE(msg.find("remove one of them"), std::string::npos) << msg;
  EXPECT_EQ(line, 4u);
}

TEST(ReaderTimeColumns, TwoTimeColumnsAreComparedOverALongText) {
  // More than 2 MB, read in many pieces: the disagreement near the end is found and named.
  std::string text = "time_s,pulses,time_us\n";
  const int n = 120000;
  for (int k = 0; k < n; ++k)
    text += fmt::format("{:.4f},{},{}\n", k * 0.0025, k % 2, k == n - 10 ? k * 2500 + 100 : k * 2500);
  ASSERT_GT(text.size(), std::size_t{2} << 20);
  const auto [msg, line] = error_of(text, ReadOptions{});
  EXPECT_NE(msg.find("the time columns 'time_s' and 'time_us' disagree"), std::string::npos) << msg;
  EXPECT_EQ(line, static_cast<std::size_t>(n - 10 + 2));
}

TEST(ReaderColumns, TwoCandidateSampleColumnsAreAnErrorInEveryMode) {
  const std::vector<std::pair<rwcalc::InputMode, std::string>> cases{{rwcalc::InputMode::Pulses, "pulse,count"},
                                                                     {rwcalc::InputMode::Counter, "counter,counts"},
                                                                     {rwcalc::InputMode::Angle, "angle,phase"},
                                                                     {rwcalc::InputMode::Rate, "gyro,rate"}};
  for (const auto& [mode, header] : cases) {
    ReadOptions o;
    o.mode = mode;
    o.rate_hz = 400.0;
    const auto [msg, line] = error_of(header + "\n1,2\n3,4\n", o);
    EXPECT_NE(msg.find("could each hold the"), std::string::npos) << header << ": " << msg;
    EXPECT_NE(msg.find("choose one with --column"), std::string::npos) << msg;
    EXPECT_EQ(line, 1u);
    o.column = "2";
    EXPECT_EQ(read_recording_text(header + "\n1,2\n3,4\n", "m", o).samples, 2u) << header;
  }
}

TEST(ReaderColumns, ATimeColumnChosenAsTheSamplesLeavesTheOtherAsTheTime) {
  ReadOptions o;
  o.mode = rwcalc::InputMode::Angle;
  o.column = "time_ms";
  const auto r = read_recording_text("time_s,time_ms\n0,0\n0.01,10\n0.02,20\n", "m", o);
  EXPECT_EQ(r.column_name, "time_ms");
  EXPECT_EQ(r.time_column.value_or(""), "time_s");
  EXPECT_EQ(r.rate_hz, 100.0);
}

TEST(ReaderCli, UpperCaseRateKeyGivesTheAnalysisItsRate) {
  const rwcalc::test::TempDir tmp;
  std::string text = "# RATE_HZ: 100\npulses\n";
  unsigned x = 12345;
  for (int k = 0; k < 40000; ++k) {
    x = x * 1103515245u + 12345u;
    text += std::to_string((x >> 16) % 3) + "\n";
  }
  const auto path = tmp.write("upper.txt", text).string();
  const auto r = rwcalc::test::run_exe({"analyze", path});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("40000 samples at 100 Hz (tau0 = 10 ms)"), std::string::npos) << r.out.substr(0, 800);
}

}  // namespace
