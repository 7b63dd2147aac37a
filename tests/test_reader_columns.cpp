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
      "# Bench_ID = B-12\n# Operator = Fomin\n# Test-Date: 2021-05-01\n# GL-2D bench run: static\npulses\n1\n2\n", "m");
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

// imu reads its columns in one pass over the text (several passes, one per thread, for a regular
// file). Each recording must be exactly the one read_recording gives for that column alone, and an
// error the one a pass over the columns in order meets first, whatever the number of threads.
const char* kMixedColumns =
    "# rate_hz: 50\r\n"
    "# serial: A-7\r\n"
    "time_s,pulses,gyro_x_dps,acc_y_g,temperature_c\r\n"
    "0.00,12,0.5,-1.01,20.5\r\n"
    "0.02,-3, 0.25 ,-1.02,20.5\r\n"
    "\r\n"
    "0.04,7,1e-3,-0.99,20.6\r\n"
    "# a note inside the data\r\n"
    "0.06,0,-0.75,-1.00,20.6\r\n"
    "0.08,5,+0.5,-1.03,20.7\r\n";

ReadOptions column(const std::string& name) {
  ReadOptions o;
  o.column = name;
  o.column_not_time = true;
  return o;
}

void expect_same_recording(const rwcalc::Recording& a, const rwcalc::Recording& b) {
  EXPECT_EQ(a.column_name, b.column_name);
  EXPECT_EQ(a.column_index, b.column_index);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.phase.counts, b.phase.counts);
  EXPECT_EQ(a.phase.values, b.phase.values);
  EXPECT_EQ(a.phase.rate_offset, b.phase.rate_offset);
  EXPECT_EQ(a.phase.kind, b.phase.kind);
  EXPECT_EQ(a.rate_hz, b.rate_hz);
  EXPECT_EQ(a.rate_source, b.rate_source);
  EXPECT_EQ(a.metadata, b.metadata);
  EXPECT_EQ(a.temperature_c, b.temperature_c);
  EXPECT_EQ(a.time_column, b.time_column);
  EXPECT_EQ(a.mode, b.mode);
  EXPECT_EQ(a.notes, b.notes);
  EXPECT_EQ(a.warnings, b.warnings);
  EXPECT_EQ(a.line_runs, b.line_runs);
  EXPECT_EQ(a.sha256, b.sha256);
  EXPECT_EQ(a.file_bytes, b.file_bytes);
}

TEST(ReaderOnePass, EveryColumnIsTheRecordingReadAlone) {
  const rwcalc::test::TempDir tmp;
  const std::string path = tmp.write("imu.csv", kMixedColumns).string();
  const std::vector<ReadOptions> columns = {column("gyro_x_dps"), column("pulses"), column("acc_y_g")};
  for (const char* threads : {"1", "2", "3"}) {
    const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
    const std::vector<rwcalc::Recording> all = rwcalc::read_recordings(path, columns);
    ASSERT_EQ(all.size(), columns.size());
    for (std::size_t i = 0; i < columns.size(); ++i) {
      SCOPED_TRACE(fmt::format("{} threads, column {}", threads, columns[i].column));
      expect_same_recording(all[i], rwcalc::read_recording(path, columns[i]));
    }
    EXPECT_EQ(all[1].phase.counts, (std::vector<std::int64_t>{0, 12, 9, 16, 16, 21}));
    EXPECT_EQ(all[1].line_runs.size(), 3u);  // the blank line and the comment start new runs
  }
}

TEST(ReaderOnePass, TheEarliestLinesErrorWhateverTheThreads) {
  const rwcalc::test::TempDir tmp;
  // acc_y_g is bad at line 5, gyro_x_dps at line 7; on line 8 both are.
  const std::string path =
      tmp.write("bad.csv",
                "time_s,gyro_x_dps,acc_y_g\n0,1,2\n0.01,1,2\n0.02,1,2\n0.03,1,x\n0.04,1,2\n0.05,y,2\n0.06,z,w\n")
          .string();
  const auto first_error = [&](const std::vector<ReadOptions>& columns) -> std::pair<std::size_t, std::string> {
    try {
      (void)rwcalc::read_recordings(path, columns);
    } catch (const InputError& e) {
      return {e.line(), e.message()};
    }
    return {0, ""};
  };
  for (const char* threads : {"1", "2"}) {
    const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
    const auto e = first_error({column("gyro_x_dps"), column("acc_y_g")});
    EXPECT_EQ(e.first, 5u) << threads;
    EXPECT_NE(e.second.find("acc_y_g"), std::string::npos) << e.second;
    EXPECT_EQ(e.second, error_of(fmt::format("time_s,gyro_x_dps,acc_y_g\n0,1,2\n0.01,1,2\n0.02,1,2\n0.03,1,x\n"),
                                 column("acc_y_g"))
                            .first);
  }
  const std::string same_line = tmp.write("both.csv", "a,b,c\n1,2,3\n1,2,3\nx,y,3\n").string();
  for (const char* threads : {"1", "2"}) {
    const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
    try {
      (void)rwcalc::read_recordings(same_line, std::vector{column("b"), column("a")});
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), 4u);
      EXPECT_NE(e.message().find("'b'"), std::string::npos) << e.message();  // the first column given
    }
  }
}

}  // namespace
