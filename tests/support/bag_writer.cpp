// Writers of the three bag formats for the tests, from the formats' specifications: ROS 1 bag
// format 2.0, rosbag2's SQLite schema with CDR messages, and MCAP with chunks and a summary.
#include "bag_writer.hpp"

#include <bzlib.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>

namespace rwcalc::test {

namespace {

template <class T>
void put(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

void put_doubles(std::string& s, const ImuSample& m) {
  const double orientation[4] = {0, 0, 0, 1};
  for (double v : orientation) put(s, v);
  for (int i = 0; i < 9; ++i) put(s, 0.0);
  for (double v : m.gyro) put(s, v);
  for (int i = 0; i < 9; ++i) put(s, 0.0);
  for (double v : m.accel) put(s, v);
  for (int i = 0; i < 9; ++i) put(s, 0.0);
}

constexpr const char* kFrame = "imu_link";

std::string ros1_imu(const ImuSample& m, std::uint32_t seq) {
  std::string s;
  put(s, seq);
  put(s, static_cast<std::uint32_t>(m.stamp_ns / 1'000'000'000));
  put(s, static_cast<std::uint32_t>(m.stamp_ns % 1'000'000'000));
  put(s, static_cast<std::uint32_t>(std::strlen(kFrame)));
  s += kFrame;
  put_doubles(s, m);
  return s;
}

std::string ros1_string(const std::string& text) {
  std::string s;
  put(s, static_cast<std::uint32_t>(text.size()));
  return s + text;
}

std::string cdr_imu(const ImuSample& m) {
  std::string s("\x00\x01\x00\x00", 4);
  std::string d;
  put(d, static_cast<std::int32_t>(m.stamp_ns / 1'000'000'000));
  put(d, static_cast<std::uint32_t>(m.stamp_ns % 1'000'000'000));
  put(d, static_cast<std::uint32_t>(std::strlen(kFrame) + 1));
  d += kFrame;
  d += '\0';
  while (d.size() % 8) d += '\0';
  put_doubles(d, m);
  return s + d;
}

std::string cdr_string(const std::string& text) {
  std::string s("\x00\x01\x00\x00", 4);
  put(s, static_cast<std::uint32_t>(text.size() + 1));
  return s + text + '\0';
}

// ROS 1: a record is its header (fields of u32 length + "name=value") and data, each length-prefixed.
std::string field(const std::string& name, const std::string& value) {
  std::string s;
  put(s, static_cast<std::uint32_t>(name.size() + 1 + value.size()));
  return s + name + "=" + value;
}
template <class T>
std::string field_of(const std::string& name, T v) {
  std::string b;
  put(b, v);
  return field(name, b);
}
std::string record(const std::string& header, const std::string& data) {
  std::string s;
  put(s, static_cast<std::uint32_t>(header.size()));
  s += header;
  put(s, static_cast<std::uint32_t>(data.size()));
  return s + data;
}
std::string op(std::uint8_t o) { return field("op", std::string(1, static_cast<char>(o))); }

std::string compress(const std::string& how, const std::string& plain) {
  if (how == "none" || how.empty()) return plain;
  if (how == "bz2") {
    std::string out(plain.size() + plain.size() / 100 + 600, '\0');
    auto len = static_cast<unsigned>(out.size());
    if (BZ2_bzBuffToBuffCompress(out.data(), &len, const_cast<char*>(plain.data()), static_cast<unsigned>(plain.size()),
                                 9, 0, 0) != BZ_OK)
      throw std::runtime_error("bz2");
    out.resize(len);
    return out;
  }
  if (how == "lz4") {
    std::string out(LZ4F_compressFrameBound(plain.size(), nullptr), '\0');
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), plain.data(), plain.size(), nullptr);
    if (LZ4F_isError(n)) throw std::runtime_error("lz4");
    out.resize(n);
    return out;
  }
  if (how == "zstd") {
    std::string out(ZSTD_compressBound(plain.size()), '\0');
    const std::size_t n = ZSTD_compress(out.data(), out.size(), plain.data(), plain.size(), 3);
    if (ZSTD_isError(n)) throw std::runtime_error("zstd");
    out.resize(n);
    return out;
  }
  throw std::runtime_error("compression " + how);
}

void write_file(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The messages of all topics in receive-time order: (receive time, topic index, message index).
std::vector<std::tuple<std::int64_t, std::size_t, std::size_t>> interleaved(const std::vector<BagTopicSpec>& topics) {
  std::vector<std::tuple<std::int64_t, std::size_t, std::size_t>> all;
  for (std::size_t t = 0; t < topics.size(); ++t)
    for (std::size_t i = 0; i < topics[t].messages.size(); ++i)
      all.emplace_back(topics[t].messages[i].receive_ns, t, i);
  std::stable_sort(all.begin(), all.end());
  return all;
}

std::string type_of(const BagTopicSpec& t, bool ros2) {
  return t.imu ? (ros2 ? "sensor_msgs/msg/Imu" : "sensor_msgs/Imu")
               : (ros2 ? "std_msgs/msg/String" : "std_msgs/String");
}

}  // namespace

std::vector<ImuSample> simulated_imu(std::size_t n, double rate_hz, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> z;
  std::uniform_real_distribution<double> lag(1e5, 3e5);
  std::vector<ImuSample> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    ImuSample& m = out[k];
    m.stamp_ns = 1'700'000'000'000'000'000 + static_cast<std::int64_t>(static_cast<double>(k) * 1e9 / rate_hz);
    m.receive_ns = m.stamp_ns + static_cast<std::int64_t>(lag(rng));
    for (double& g : m.gyro) g = 1e-3 * z(rng) + 2e-4;
    for (double& a : m.accel) a = 2e-2 * z(rng);
    m.accel[2] += 9.80665;
  }
  return out;
}

void write_ros1_bag(const std::filesystem::path& path, const std::vector<BagTopicSpec>& topics,
                    const std::string& compression, std::size_t per_chunk) {
  std::vector<std::string> conns;  // each topic's connection record
  for (std::size_t t = 0; t < topics.size(); ++t)
    conns.push_back(record(op(7) + field_of("conn", static_cast<std::uint32_t>(t)) + field("topic", topics[t].name),
                           field("topic", topics[t].name) + field("type", type_of(topics[t], false)) +
                               field("md5sum", "6a62c6daae103f4ff57a132d6f95cec2") + field("message_definition", "")));
  std::string body;  // after the bag header record
  std::string infos;
  const auto all = interleaved(topics);
  const std::size_t header_bytes = 13 + 4096;  // the magic and the padded bag header record
  std::uint32_t chunks = 0;
  for (std::size_t from = 0; from < all.size(); from += per_chunk) {
    std::string plain;
    std::map<std::uint32_t, std::uint32_t> counts;
    for (const auto& c : conns) plain += c;
    for (std::size_t k = from; k < std::min(all.size(), from + per_chunk); ++k) {
      const auto& [t_ns, t, i] = all[k];
      const ImuSample& m = topics[t].messages[i];
      const std::uint64_t time = static_cast<std::uint64_t>(m.receive_ns / 1'000'000'000) |
                                 (static_cast<std::uint64_t>(m.receive_ns % 1'000'000'000) << 32);
      plain += record(op(2) + field_of("conn", static_cast<std::uint32_t>(t)) + field_of("time", time),
                      topics[t].imu ? ros1_imu(m, static_cast<std::uint32_t>(i)) : ros1_string("text"));
      ++counts[static_cast<std::uint32_t>(t)];
    }
    const std::uint64_t chunk_pos = header_bytes + body.size();
    body +=
        record(op(5) + field("compression", compression) + field_of("size", static_cast<std::uint32_t>(plain.size())),
               compress(compression, plain));
    std::string data;
    for (const auto& [c, n] : counts) put(data, c), put(data, n);
    infos += record(op(6) + field_of("ver", std::uint32_t{1}) + field_of("chunk_pos", chunk_pos) +
                        field_of("start_time", std::uint64_t{0}) + field_of("end_time", std::uint64_t{0}) +
                        field_of("count", static_cast<std::uint32_t>(counts.size())),
                    data);
    ++chunks;
  }
  // The bag header record is padded to 4096 bytes; the index (connections, chunk infos) follows the chunks.
  const std::uint64_t index_pos = header_bytes + body.size();
  const std::string head = op(3) + field_of("index_pos", index_pos) +
                           field_of("conn_count", static_cast<std::uint32_t>(topics.size())) +
                           field_of("chunk_count", chunks);
  const std::string bag_header = record(head, std::string(4096 - 8 - head.size(), ' '));
  std::string all_bytes = "#ROSBAG V2.0\n" + bag_header + body;
  for (const auto& c : conns) all_bytes += c;
  write_file(path, all_bytes + infos);
}

void write_ros2_db3(const std::filesystem::path& path, const std::vector<BagTopicSpec>& topics) {
  std::filesystem::remove(path);
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw std::runtime_error("sqlite open");
  sqlite3_exec(db,
               "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
               "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
               "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
               "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
               "data BLOB NOT NULL);"
               "BEGIN;",
               nullptr, nullptr, nullptr);
  for (std::size_t t = 0; t < topics.size(); ++t)
    sqlite3_exec(db,
                 fmt::format("INSERT INTO topics VALUES({}, '{}', '{}', 'cdr', '')", t + 1, topics[t].name,
                             type_of(topics[t], true))
                     .c_str(),
                 nullptr, nullptr, nullptr);
  sqlite3_stmt* s = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", -1, &s, nullptr);
  for (const auto& [t_ns, t, i] : interleaved(topics)) {
    const ImuSample& m = topics[t].messages[i];
    const std::string data = topics[t].imu ? cdr_imu(m) : cdr_string("text");
    sqlite3_bind_int64(s, 1, static_cast<sqlite3_int64>(t + 1));
    sqlite3_bind_int64(s, 2, m.receive_ns);
    sqlite3_bind_blob(s, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    sqlite3_step(s);
    sqlite3_reset(s);
  }
  sqlite3_finalize(s);
  sqlite3_exec(db, "COMMIT;", nullptr, nullptr, nullptr);
  sqlite3_close(db);
}

namespace {

std::string mcap_record(std::uint8_t op, const std::string& body) {
  std::string s(1, static_cast<char>(op));
  put(s, static_cast<std::uint64_t>(body.size()));
  return s + body;
}
std::string mcap_string(const std::string& v) {
  std::string s;
  put(s, static_cast<std::uint32_t>(v.size()));
  return s + v;
}

}  // namespace

void write_mcap(const std::filesystem::path& path, const std::vector<BagTopicSpec>& topics,
                const std::string& compression, std::size_t per_chunk, bool summary) {
  const std::string magic("\x89MCAP0\r\n", 8);
  std::string out = magic + mcap_record(0x01, mcap_string("ros2") + mcap_string("rwcalc-test"));
  std::string defs;  // schemas and channels
  for (std::size_t t = 0; t < topics.size(); ++t) {
    std::string schema;
    put(schema, static_cast<std::uint16_t>(t + 1));
    schema += mcap_string(type_of(topics[t], true)) + mcap_string("ros2msg") + mcap_string("");
    std::string channel;
    put(channel, static_cast<std::uint16_t>(t));
    put(channel, static_cast<std::uint16_t>(t + 1));
    channel += mcap_string(topics[t].name) + mcap_string("cdr");
    put(channel, std::uint32_t{0});  // no metadata
    defs += mcap_record(0x03, schema) + mcap_record(0x04, channel);
  }
  const auto all = interleaved(topics);
  std::map<std::uint16_t, std::uint64_t> counts;
  for (std::size_t from = 0; from < all.size(); from += per_chunk) {
    std::string plain = from == 0 ? defs : "";
    for (std::size_t k = from; k < std::min(all.size(), from + per_chunk); ++k) {
      const auto& [t_ns, t, i] = all[k];
      const ImuSample& m = topics[t].messages[i];
      std::string msg;
      put(msg, static_cast<std::uint16_t>(t));
      put(msg, static_cast<std::uint32_t>(i));
      put(msg, static_cast<std::uint64_t>(m.receive_ns));
      put(msg, static_cast<std::uint64_t>(m.stamp_ns));
      msg += topics[t].imu ? cdr_imu(m) : cdr_string("text");
      plain += mcap_record(0x05, msg);
      ++counts[static_cast<std::uint16_t>(t)];
    }
    const std::string packed = compress(compression, plain);
    std::string chunk;
    put(chunk, std::uint64_t{0});
    put(chunk, std::uint64_t{0});
    put(chunk, static_cast<std::uint64_t>(plain.size()));
    put(chunk, std::uint32_t{0});
    chunk += mcap_string(compression);
    put(chunk, static_cast<std::uint64_t>(packed.size()));
    out += mcap_record(0x06, chunk + packed);
  }
  out += mcap_record(0x0F, std::string(4, '\0'));
  const std::uint64_t summary_start = summary ? out.size() : 0;
  if (summary) {
    std::string stats;
    std::uint64_t total = 0;
    for (const auto& [c, n] : counts) total += n;
    put(stats, total);
    put(stats, static_cast<std::uint16_t>(topics.size()));
    put(stats, static_cast<std::uint32_t>(topics.size()));
    put(stats, std::uint32_t{0});
    put(stats, std::uint32_t{0});
    put(stats, std::uint32_t{0});
    put(stats, std::uint64_t{0});
    put(stats, std::uint64_t{0});
    std::string map;
    for (const auto& [c, n] : counts) put(map, c), put(map, n);
    put(stats, static_cast<std::uint32_t>(map.size()));
    out += defs + mcap_record(0x0B, stats + map);
  }
  std::string footer;
  put(footer, summary_start);
  put(footer, std::uint64_t{0});
  put(footer, std::uint32_t{0});
  out += mcap_record(0x02, footer) + magic;
  write_file(path, out);
}

std::string rostopic_csv(const std::vector<ImuSample>& samples) {
  std::string s =
      "%time,field.header.seq,field.header.stamp,field.header.frame_id,field.orientation.x,"
      "field.orientation.y,field.orientation.z,field.orientation.w,field.angular_velocity.x,"
      "field.angular_velocity.y,field.angular_velocity.z,field.linear_acceleration.x,"
      "field.linear_acceleration.y,field.linear_acceleration.z\n";
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const ImuSample& m = samples[i];
    s += fmt::format("{},{},{},{},0.0,0.0,0.0,1.0,{},{},{},{},{},{}\n", m.receive_ns, i, m.stamp_ns, kFrame, m.gyro[0],
                     m.gyro[1], m.gyro[2], m.accel[0], m.accel[1], m.accel[2]);
  }
  return s;
}

}  // namespace rwcalc::test
