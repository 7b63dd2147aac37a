// ROS bags and ROS CSV exports: a ROS 1 bag (uncompressed, bz2, lz4), a ROS 2 SQLite bag and MCAP
// files (uncompressed, zstd, lz4; with and without a summary) of one simulated IMU give the same
// channels and noise file as its `rostopic echo -p` CSV; the topic choice and its errors; every
// malformed byte an InputError naming the file and where; the CSV forms of ROS tools end to end.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "bag_writer.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace rwcalc::test {
namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

constexpr double kRate = 200;
constexpr std::string_view kColumns[] = {"field.angular_velocity.x",    "field.angular_velocity.y",
                                         "field.angular_velocity.z",    "field.linear_acceleration.x",
                                         "field.linear_acceleration.y", "field.linear_acceleration.z"};
constexpr std::size_t kMessages = 6000;  // 30 s

const std::vector<ImuSample>& imu() {
  static const std::vector<ImuSample> samples = simulated_imu(kMessages, kRate);
  return samples;
}

std::vector<BagTopicSpec> one_imu_and_text() {
  std::vector<ImuSample> text(imu().begin(), imu().begin() + 100);
  return {{"/imu/data", imu(), true}, {"/status", text, false}};
}

// Every number of `b` within 1e-9 relative of `a`'s, every string and key equal, except the paths
// (and the column names, unless `names`).
void expect_same(const nlohmann::json& a, const nlohmann::json& b, const std::string& where, bool names = true) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    EXPECT_LE(std::abs(x - y), 1e-9 * std::max(std::abs(x), std::abs(y))) << where << ": " << x << " vs " << y;
  } else if (a.is_object() && b.is_object()) {
    ASSERT_EQ(a.size(), b.size()) << where;
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (it.key() == "file" || it.key() == "source" || it.key() == "notes" || it.key() == "sha256" ||
          it.key() == "file_bytes" || (!names && (it.key() == "column" || it.key() == "time_column")))
        continue;
      ASSERT_TRUE(b.contains(it.key())) << where << "." << it.key();
      expect_same(it.value(), b[it.key()], where + "." + it.key(), names);
    }
  } else if (a.is_array() && b.is_array()) {
    ASSERT_EQ(a.size(), b.size()) << where;
    for (std::size_t i = 0; i < a.size(); ++i) expect_same(a[i], b[i], fmt::format("{}[{}]", where, i), names);
  } else {
    EXPECT_EQ(a, b) << where;
  }
}

// The noise file without its comment lines (they name the input file).
std::string yaml_values(const std::filesystem::path& p) {
  std::istringstream in(slurp(p));
  std::string out;
  for (std::string line; std::getline(in, line);)
    if (!line.starts_with("#")) out += line.substr(0, line.find(" #")) + "\n";
  return out;
}

struct ImuRun {
  nlohmann::json channels;
  std::string yaml, err;
};

ImuRun run_imu(const TempDir& dir, const std::filesystem::path& file, std::vector<std::string> extra = {}) {
  const auto yaml = dir.path() / (file.filename().string() + ".yaml");
  std::vector<std::string> args{"imu", file.string(), "--json", "--kalibr", yaml.string(), "--force"};
  args.insert(args.end(), extra.begin(), extra.end());
  const CliResult r = run_cli(args);
  EXPECT_EQ(r.status, 0) << file << ": " << r.err;
  if (r.status != 0) return {};
  return {nlohmann::json::parse(r.out)["channels"], yaml_values(yaml), r.err};
}

TEST(Bag, EveryFormatGivesTheChannelsAndNoiseFileOfItsCsv) {
  TempDir dir;
  const auto csv = dir.write("imu.csv", rostopic_csv(imu()));
  const ImuRun want = run_imu(dir, csv);
  ASSERT_EQ(want.channels.size(), 6U);
  std::vector<std::filesystem::path> bags;
  for (const std::string c : {"none", "bz2", "lz4"}) {
    bags.push_back(dir.path() / fmt::format("imu_{}.bag", c));
    write_ros1_bag(bags.back(), one_imu_and_text(), c, 700);
  }
  bags.push_back(dir.path() / "imu.db3");
  write_ros2_db3(bags.back(), one_imu_and_text());
  for (const std::string c : {"", "zstd", "lz4"}) {
    bags.push_back(dir.path() / fmt::format("imu_{}.mcap", c.empty() ? "plain" : c));
    write_mcap(bags.back(), one_imu_and_text(), c, 700);
  }
  bags.push_back(dir.path() / "imu_no_summary.mcap");
  write_mcap(bags.back(), one_imu_and_text(), "zstd", 700, false);
  for (const auto& bag : bags) {
    SCOPED_TRACE(bag.filename().string());
    const ImuRun got = run_imu(dir, bag);
    expect_same(want.channels, got.channels, "channels");
    EXPECT_EQ(want.yaml, got.yaml);
    EXPECT_TRUE(has(got.err, "topic '/imu/data' (sensor_msgs/")) << got.err;
    EXPECT_TRUE(has(got.err, "time from 'field.header.stamp'")) << got.err;
    EXPECT_TRUE(has(got.err, "channels from the column names")) << got.err;
  }
}

// Bags written by ROS's own writer (python3-rosbag: tests/bags/make_ros1_bags.py) read as the
// formula they were written from, at the stamps' 200 Hz.
TEST(Bag, BagsOfRosbagsOwnWriterReadAsTheirFormula) {
  std::string csv = "field.header.stamp";
  for (const std::string_view f : kColumns) csv += fmt::format(",{}", f);
  csv += "\n";
  for (int k = 0; k < 120; ++k) {
    csv += fmt::format("{}", 1'700'000'000'000'000'000LL + k * 5'000'000LL);
    for (int a = 0; a < 3; ++a) csv += fmt::format(",{}", 1e-3 * std::sin(0.1 * k + a));
    for (int a = 0; a < 3; ++a) csv += fmt::format(",{}", 1e-2 * std::cos(0.07 * k + a) + (a == 2 ? 9.80665 : 0.0));
    csv += "\n";
  }
  for (const std::string c : {"bz2", "lz4"}) {
    const auto bag = source_path("tests/bags/rosbag_" + c + ".bag").string();
    for (const std::string_view column : kColumns) {
      ReadOptions o;
      o.column = column;
      const Recording got = read_recording(bag, o), want = read_recording_text(csv, "formula.csv", o);
      EXPECT_EQ(got.samples, 120U);
      EXPECT_EQ(got.rate_hz, 200.0);
      EXPECT_EQ(got.rate_unit, want.rate_unit);
      ASSERT_EQ(got.phase.values.size(), want.phase.values.size());
      EXPECT_NEAR(got.phase.rate_offset, want.phase.rate_offset, 1e-12 * std::abs(want.phase.rate_offset));
      for (std::size_t i = 0; i < want.phase.values.size(); ++i)
        EXPECT_NEAR(got.phase.values[i], want.phase.values[i], 1e-9 * std::abs(want.phase.values.back()) + 1e-12)
            << c << " " << column << " " << i;
    }
    EXPECT_EQ(run_cli({"imu", bag, "--topic", "/status"}).status, 2);
  }
}

TEST(Bag, ReceiveTimeIsTheBagsOwnAndReadsAsTheCsvsPercentTime) {
  TempDir dir;
  const auto csv = dir.write("imu.csv", rostopic_csv(imu()));
  const auto bag = dir.path() / "imu.bag";
  write_ros1_bag(bag, one_imu_and_text());
  const auto mcap = dir.path() / "imu.mcap";
  write_mcap(mcap, one_imu_and_text(), "lz4");
  const ImuRun want = run_imu(dir, csv, {"--time", "receive"});
  // The receive times lag the stamps by 0.1..0.3 ms: jitter of up to 4 % of the 5-ms period.
  EXPECT_TRUE(has(want.err, "jitter")) << want.err;
  EXPECT_FALSE(has(run_imu(dir, csv).err, "jitter"));
  for (const auto& f : {bag, mcap}) {
    const ImuRun got = run_imu(dir, f, {"--time", "receive"});
    expect_same(want.channels, got.channels, "channels");
    EXPECT_TRUE(has(got.err, "jitter")) << got.err;
  }
  const ImuRun named = run_imu(dir, csv, {"--time-column", "%time"});
  expect_same(want.channels, named.channels, "channels");
}

TEST(Bag, TheTopicIsTheOnlyImuTopicOrTheOneNamed) {
  TempDir dir;
  auto topics = one_imu_and_text();
  topics.push_back({"/imu/raw", imu(), true});
  const auto bag = dir.path() / "two.bag";
  write_ros1_bag(bag, topics);
  const auto db3 = dir.path() / "two.db3";
  write_ros2_db3(db3, topics);
  for (const auto& f : {bag, db3}) {
    auto r = run_cli({"imu", f.string()});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(has(r.err, f.string()) && has(r.err, "2 sensor_msgs/Imu topics: choose one with --topic") &&
                has(r.err, "/imu/data") && has(r.err, "/imu/raw"))
        << r.err;
    r = run_cli({"imu", f.string(), "--topic", "/status"});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(has(r.err, "topic '/status' holds std_msgs/")) << r.err;
    r = run_cli({"imu", f.string(), "--topic", "/missing"});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(has(r.err, "no topic '/missing'") && has(r.err, "/status")) << r.err;
    r = run_cli({"imu", f.string(), "--topic", "/imu/raw", "--json"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(has(r.err, "topic '/imu/raw'")) << r.err;
  }
  const auto none = dir.path() / "none.mcap";
  write_mcap(none, {{"/status", imu(), false}});
  const auto r = run_cli({"imu", none.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "no sensor_msgs/Imu topic in this MCAP file; its topics: /status")) << r.err;
}

TEST(Bag, ARos2BagDirectoryReadsAsItsStorageFile) {
  TempDir dir;
  const auto bag = dir.path() / "rosbag2_2026_12_02";
  std::filesystem::create_directory(bag);
  dir.write("rosbag2_2026_12_02/metadata.yaml", "rosbag2_bagfile_information:\n  version: 5\n");
  write_mcap(bag / "rosbag2_2026_12_02_0.mcap", one_imu_and_text(), "zstd");
  auto r = run_cli({"imu", bag.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["channels"].size(), 6U);
  write_mcap(bag / "rosbag2_2026_12_02_1.mcap", one_imu_and_text(), "zstd");
  r = run_cli({"imu", bag.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "a ROS 2 bag split into 2 files")) << r.err;
}

TEST(Bag, AnalyzeReadsOneChannelOfABag) {
  TempDir dir;
  const auto bag = dir.path() / "imu.bag";
  write_ros1_bag(bag, one_imu_and_text(), "lz4");
  const auto r = run_cli({"analyze", bag.string(), "--column", "field.angular_velocity.z", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["input"]["unit"], "rad/s");
  EXPECT_DOUBLE_EQ(j["rate_hz"].get<double>(), kRate);
}

// Reading `bytes` as the file gives a recording or an InputError naming the file; nothing else.
void expect_read_or_input_error(const TempDir& dir, const std::string& name, const std::string& bytes,
                                std::size_t& errors) {
  const auto f = dir.write(name, bytes);
  ReadOptions o;
  o.column = "field.angular_velocity.x";
  try {
    (void)read_recording(f.string(), o);
  } catch (const InputError& e) {
    ++errors;
    EXPECT_EQ(e.file(), f.string());
  } catch (const std::exception& e) {
    ADD_FAILURE() << name << ": " << typeid(e).name() << ": " << e.what();
  }
}

TEST(Bag, EveryTruncationOrFlippedByteIsAnInputErrorOrAReading) {
  TempDir dir;
  const std::vector<ImuSample> few(imu().begin(), imu().begin() + 300);
  const std::vector<BagTopicSpec> topics{{"/imu", few, true}};
  std::vector<std::pair<std::string, std::filesystem::path>> files;
  for (const std::string c : {"none", "bz2", "lz4"}) {
    files.emplace_back(c, dir.path() / (c + ".bag"));
    write_ros1_bag(files.back().second, topics, c, 100);
  }
  for (const std::string c : {"", "zstd", "lz4"}) {
    files.emplace_back("mcap" + c, dir.path() / ("m" + c + ".mcap"));
    write_mcap(files.back().second, topics, c, 100);
  }
  for (const auto& [name, path] : files) {
    const std::string bytes = slurp(path);
    std::size_t errors = 0, tries = 0;
    const std::size_t step = std::max<std::size_t>(1, bytes.size() / 150);
    for (std::size_t cut = 20; cut < bytes.size(); cut += step, ++tries)
      expect_read_or_input_error(dir, "cut_" + name, bytes.substr(0, cut), errors);
    for (std::size_t at = 13; at < bytes.size(); at += step, ++tries) {
      std::string flipped = bytes;
      flipped[at] = static_cast<char>(flipped[at] ^ 0xA5);
      expect_read_or_input_error(dir, "flip_" + name, flipped, errors);
    }
    EXPECT_GT(errors, tries / 2) << name;  // most cuts and many flips are errors
  }
}

TEST(Bag, ErrorsNameTheFileThePlaceAndWhatWasWrong) {
  TempDir dir;
  const std::vector<ImuSample> few(imu().begin(), imu().begin() + 300);
  const auto bag = dir.path() / "a.bag";
  write_ros1_bag(bag, {{"/imu", few, true}}, "bz2", 100);
  std::string bytes = slurp(bag);
  // A bag that was not closed has no index.
  std::string open_bag = bytes;
  const auto at = open_bag.find("index_pos=") + 10;
  std::fill_n(open_bag.begin() + static_cast<std::ptrdiff_t>(at), 8, '\0');
  auto r = run_cli({"imu", dir.write("open.bag", open_bag).string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "open.bag") && has(r.err, "byte 13") && has(r.err, "rosbag reindex")) << r.err;
  // Corrupt compressed data: the chunk named by its offset.
  std::string corrupt = bytes;
  const auto chunk = corrupt.find("compression=bz2");
  corrupt[chunk + 60] = static_cast<char>(corrupt[chunk + 60] ^ 0xFF);
  r = run_cli({"imu", dir.write("corrupt.bag", corrupt).string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "corrupt.bag") && has(r.err, "chunk at byte") && has(r.err, "bz2")) << r.err;
  // A record cut off in the middle.
  r = run_cli({"imu", dir.write("cut.bag", bytes.substr(0, 4096 + 13 + 200)).string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "cut.bag") && has(r.err, "byte")) << r.err;
  // A CDR message too short for an Imu.
  const auto db3 = dir.path() / "short.db3";
  write_ros2_db3(db3, {{"/imu", few, true}});
  {
    std::string sql = slurp(db3);
    (void)sql;
  }
  const auto mcap = dir.path() / "short.mcap";
  write_mcap(mcap, {{"/imu", few, true}});
  std::string m = slurp(mcap);
  const auto imu_at = m.find("imu_link");  // in the first message: its length field 4 bytes before
  m[imu_at - 4] = static_cast<char>(0x7F);
  r = run_cli({"imu", dir.write("short.mcap", m).string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "short.mcap") && has(r.err, "sensor_msgs/Imu message at byte") &&
              has(r.err, "too short for a frame_id"))
      << r.err;
  // Not a rosbag2 database.
  r = run_cli({"imu", dir.write("empty.db3", "SQLite format 3").string()});
  EXPECT_NE(r.status, 0);
}

// ---- CSV exports of ROS tools ----

TEST(RosCsv, RostopicEchoFindsItsSixChannelsAndPrefersTheHeaderStamp) {
  TempDir dir;
  const auto f = dir.write("echo.csv", rostopic_csv(imu()));
  const auto r = run_cli({"imu", f.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["channels"].size(), 6U);
  EXPECT_EQ(j["channels"][0]["column"], "field.angular_velocity.x");
  EXPECT_EQ(j["channels"][5]["column"], "field.linear_acceleration.z");
  EXPECT_DOUBLE_EQ(j["rate_hz"].get<double>(), kRate);
  EXPECT_TRUE(has(r.err, "time from 'field.header.stamp' (the sensor's stamp), not '%time'")) << r.err;
  EXPECT_TRUE(has(r.err, "rate unit rad/s from the column name 'field.angular_velocity.x'")) << r.err;
  EXPECT_TRUE(has(r.err, "rate unit m/s^2 from the column name 'field.linear_acceleration.x'")) << r.err;
  // Overridable: the columns given are read, and only those.
  const auto one = run_cli({"imu", f.string(), "--gyro", "field.angular_velocity.z", "--json"});
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_EQ(nlohmann::json::parse(one.out)["channels"].size(), 1U);
  EXPECT_FALSE(has(one.err, "channels from the column names"));
}

TEST(RosCsv, PlotJugglerTimeAndSlashedFieldNames) {
  TempDir dir;
  std::string s =
      "__time,/imu/angular_velocity/x,/imu/angular_velocity/y,/imu/angular_velocity/z,"
      "/imu/linear_acceleration/x,/imu/linear_acceleration/y,/imu/linear_acceleration/z\n";
  for (std::size_t k = 0; k < imu().size(); ++k) {
    const ImuSample& m = imu()[k];
    s += fmt::format("{:.6f},{},{},{},{},{},{}\n", 1.7e9 + static_cast<double>(k) / kRate, m.gyro[0], m.gyro[1],
                     m.gyro[2], m.accel[0], m.accel[1], m.accel[2]);
  }
  const auto r = run_cli({"imu", dir.write("pj.csv", s).string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["channels"].size(), 6U);
  EXPECT_EQ(j["channels"][3]["sensor"], "accelerometer");
  EXPECT_DOUBLE_EQ(j["rate_hz"].get<double>(), kRate);
}

TEST(RosCsv, Ros2SecAndNanosecAreOneStamp) {
  TempDir dir;
  std::string s =
      "header.stamp.sec,header.stamp.nanosec,header.frame_id,angular_velocity.x,angular_velocity.y,"
      "angular_velocity.z,linear_acceleration.x,linear_acceleration.y,linear_acceleration.z\n";
  for (const ImuSample& m : imu())
    s += fmt::format("{},{},imu_link,{},{},{},{},{},{}\n", m.stamp_ns / 1'000'000'000, m.stamp_ns % 1'000'000'000,
                     m.gyro[0], m.gyro[1], m.gyro[2], m.accel[0], m.accel[1], m.accel[2]);
  const auto f = dir.write("ros2.csv", s);
  const auto r = run_cli({"imu", f.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["channels"].size(), 6U);
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(r.out)["rate_hz"].get<double>(), kRate);
  EXPECT_TRUE(has(r.err, "time from 'header.stamp.sec' and 'header.stamp.nanosec'")) << r.err;
  // The same channels as the bag's (same values, the same stamps in ns).
  const auto bag = dir.path() / "imu.db3";
  write_ros2_db3(bag, one_imu_and_text());
  const auto b = run_cli({"imu", bag.string(), "--json"});
  ASSERT_EQ(b.status, 0) << b.err;
  expect_same(nlohmann::json::parse(r.out)["channels"], nlohmann::json::parse(b.out)["channels"], "channels", false);
}

TEST(RosCsv, UnitSuffixesFindAllSixChannelsWithRate) {
  TempDir dir;
  std::string s = "gyro_x_dps,gyro_y_dps,gyro_z_dps,acc_x_g,acc_y_g,acc_z_g\n";
  for (const ImuSample& m : imu())
    s += fmt::format("{},{},{},{},{},{}\n", m.gyro[0] * 57.3, m.gyro[1] * 57.3, m.gyro[2] * 57.3, m.accel[0] / 9.8,
                     m.accel[1] / 9.8, m.accel[2] / 9.8);
  const auto r = run_cli({"imu", dir.write("imu.csv", s).string(), "--rate", "100", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["channels"].size(), 6U);
  EXPECT_EQ(j["channels"][0]["sensor"], "gyro");
  EXPECT_EQ(j["channels"][5]["sensor"], "accelerometer");
  EXPECT_TRUE(has(r.err,
                  "channels from the column names: gyro gyro_x_dps, gyro_y_dps, gyro_z_dps; accelerometer "
                  "acc_x_g, acc_y_g, acc_z_g"))
      << r.err;
}

TEST(RosCsv, TimeColumnChoosesAmongTimeColumnsOnEveryReadingCommand) {
  TempDir dir;
  // Two time columns that disagree by far more than the tolerance: refused unless one is chosen.
  std::string s = "time_s,t_ms,gyro_dps\n";
  for (std::size_t k = 0; k < 3000; ++k)
    s += fmt::format("{:.3f},{:.3f},{}\n", static_cast<double>(k) / 100, 5000.0 + static_cast<double>(k) * 10,
                     imu()[k].gyro[0]);
  const auto f = dir.write("two_times.csv", s).string();
  EXPECT_EQ(run_cli({"analyze", f, "--json"}).status, 2);
  for (const std::string cmd : {"analyze", "allan"}) {
    const auto r = run_cli({cmd, f, "--time-column", "t_ms", "--json"});
    EXPECT_EQ(r.status, 0) << cmd << ": " << r.err;
  }
  const auto bad = run_cli({"analyze", f, "--time-column", "nope"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(has(bad.err, "no column named 'nope' (--time-column)")) << bad.err;
  const auto both = run_cli({"analyze", f, "--time-column", "t_ms", "--time", "receive"});
  EXPECT_EQ(both.status, 2);
  EXPECT_TRUE(has(both.err, "give --time or --time-column, not both")) << both.err;
}

TEST(RosCsv, ErrorsNameTheColumnAndSayWhatImuAccepts) {
  TempDir dir;
  std::string s = "time_s,gyro_x_dps,stuck_dps,gx\n";
  for (std::size_t k = 0; k < 3000; ++k)
    s += fmt::format("{:.2f},{},0.5,{}\n", static_cast<double>(k) / 100, imu()[k].gyro[0], imu()[k].gyro[1]);
  const auto f = dir.write("imu.csv", s).string();
  auto r = run_cli({"imu", f, "--gyro", "gyro_x_dps,stuck_dps"});
  EXPECT_NE(r.status, 0);
  EXPECT_TRUE(has(r.err, "column 'stuck_dps'")) << r.err;
  r = run_cli({"imu", f, "--gyro", "gx"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "--gyro-unit") && !has(r.err, "--input rate")) << r.err;
}

}  // namespace
}  // namespace rwcalc::test
