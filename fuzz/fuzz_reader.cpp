// libFuzzer target: the recording reader over every input mode and option, then the Allan engine
// and the outlier detector on whatever the reader accepts.
//
// Input layout: 4 option bytes, then the file bytes.
//   byte 0: bits 0-1 input mode (pulses, counter, angle, rate), bits 2-3 angle unit, bits 4-5 rate
//           unit, bit 6 gzip-compress the body before reading, bit 7 give --rate
//   byte 1: counter bits (1 + byte % 64)
//   byte 2: bits 0-2 column choice (0: default; 1-4: index "1".."4"; 5: "rate"; 6: "time_s";
//           7: "gyro"), bit 3 give --scale, bits 4-7 --rate choice
//   byte 3: time tolerance (byte / 512, within the CLI's 0..0.5)
// A body that starts with the gzip magic bytes is also inflated by the reader itself, so corrupt
// and truncated gzip reach it both ways. A body that starts as a ROS bag does (ROS 1, MCAP, SQLite)
// is written to a file and read as one (bags are read from files only), its column one of the Imu
// channels or times by bits 0-2 of byte 2, the unit from the channel's name.
//
// The contract checked: the reader either returns a recording or throws rwcalc::InputError /
// UsageError; a returned recording has at least two samples, a positive finite rate, and finite
// phase; the Allan result of an accepted record is finite; outlier positions are in range.
#include <zlib.h>

#include <unistd.h>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "rwcalc/allan.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/outliers.hpp"
#include "rwcalc/reader.hpp"

namespace {

std::string gzip(std::string_view body) {
  z_stream z{};
  if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) std::abort();
  std::string out(deflateBound(&z, body.size()) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(body.data()));
  z.avail_in = static_cast<uInt>(body.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  if (deflate(&z, Z_FINISH) != Z_STREAM_END) std::abort();
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_reader: contract broken: %s\n", what);
    std::abort();
  }
}

bool is_bag(std::string_view body) {
  return body.starts_with("#ROSBAG V2.0\n") || body.starts_with("\x89MCAP0\r\n") ||
         body.starts_with(std::string_view("SQLite format 3\0", 16));
}

// A bag's bytes read from a temporary file: a recording, or nothing after an InputError or UsageError.
bool read_bag(std::string_view body, std::uint8_t b2, rwcalc::Recording& rec) {
  char path[] = "/tmp/fuzz_reader_bag.XXXXXX";
  const int fd = ::mkstemp(path);
  if (fd < 0) std::abort();
  if (::write(fd, body.data(), body.size()) != static_cast<ssize_t>(body.size())) std::abort();
  ::close(fd);
  rwcalc::ReadOptions o;
  static const char* const kBagColumns[] = {"field.angular_velocity.x",
                                            "field.angular_velocity.y",
                                            "field.angular_velocity.z",
                                            "field.linear_acceleration.x",
                                            "field.linear_acceleration.y",
                                            "field.linear_acceleration.z",
                                            "%time",
                                            "1"};
  o.column = kBagColumns[b2 & 7];
  if (b2 & 8) o.time_column = "%time";
  bool ok = true;
  try {
    rec = rwcalc::read_recording(path, o);
  } catch (const rwcalc::InputError&) {
    ok = false;
  } catch (const rwcalc::UsageError&) {
    ok = false;
  }
  ::unlink(path);
  return ok;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  const std::uint8_t b0 = data[0], b1 = data[1], b2 = data[2], b3 = data[3];
  std::string_view body(reinterpret_cast<const char*>(data + 4), size - 4);

  rwcalc::ReadOptions o;
  o.mode = static_cast<rwcalc::InputMode>(b0 & 3);
  o.angle_unit = static_cast<rwcalc::AngleUnit>((b0 >> 2) & 3);
  o.rate_unit = static_cast<rwcalc::RateUnit>((b0 >> 4) & 3);
  o.counter_bits = 1 + b1 % 64;
  static const char* const kColumns[] = {"", "1", "2", "3", "4", "rate", "time_s", "gyro"};
  o.column = kColumns[b2 & 7];
  if (b2 & 8) o.scale_arcsec = 0.92;
  if (b0 & 0x80) {
    static const double kRates[] = {400, 100, 1, 0.5, 1e6, 1e-3, 200, 250, 3, 10, 1000, 40, 4e5, 7, 1e9, 1e-9};
    o.rate_hz = kRates[b2 >> 4];
  }
  o.time_tolerance = b3 / 512.0;

  std::string compressed;
  if (b0 & 0x40) {
    compressed = gzip(body);
    body = compressed;
  }

  rwcalc::Recording rec;
  if (is_bag(body) && !read_bag(body, b2, rec)) return 0;
  try {
    if (!is_bag(body)) rec = rwcalc::read_recording_text(body, "fuzz.txt", o);
  } catch (const rwcalc::InputError&) {
    return 0;
  } catch (const rwcalc::UsageError&) {
    return 0;
  }

  check(rec.samples >= 2, "fewer than two samples accepted");
  check(std::isfinite(rec.rate_hz) && rec.rate_hz > 0, "sample rate not positive and finite");
  check(rec.phase.points() >= 2, "phase series too short");
  for (std::size_t i = 0; i < rec.phase.points(); ++i) check(std::isfinite(rec.phase.at(i)), "non-finite phase");
  check(rec.line_of_sample(0) >= 1, "first sample has no line");

  rwcalc::AllanOptions ao;
  try {
    const rwcalc::AllanResult a = rwcalc::compute_allan(rec.phase, ao);
    for (const auto& p : a.points) {
      check(std::isfinite(p.var) && p.var >= 0, "Allan variance not finite and non-negative");
      check(std::isfinite(p.dev_low) && std::isfinite(p.dev_high), "Allan bounds not finite");
    }
  } catch (const rwcalc::AnalysisError&) {
    // A record the engine declines (e.g. too short for any τ) is reported, not a crash.
  }

  const auto rates = rec.rates();
  for (double r : rates) check(std::isfinite(r), "non-finite rate sample");
  const auto outliers = rwcalc::find_outliers(rec);
  for (const auto& out : outliers) {
    check(out.index < rates.size(), "outlier index out of range");
    check(out.line >= 1, "outlier without a line");
  }
  return 0;
}
