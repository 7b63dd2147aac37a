// What the three bag readers share: telling a bag by its first bytes, choosing the Imu topic,
// decoding sensor_msgs/Imu (ROS 1 and CDR), bounds-checked bytes and the chunk decompressors.
#include "bag.hpp"

#include <bzlib.h>
#include <dirent.h>
#include <fcntl.h>
#include <lz4frame.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/sha256.hpp"

namespace rwcalc::detail {

namespace {

// A chunk larger than this once decompressed is refused rather than allocated: writers keep
// chunks near 1 MiB (ROS 1: 768 KiB, MCAP: 4 MiB by default).
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;

constexpr std::string_view kRos1Magic = "#ROSBAG V2.0\n";
constexpr std::string_view kMcapMagic = "\x89MCAP0\r\n";
constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};

std::string topic_list(const std::vector<BagTopic>& topics) {
  std::string s;
  for (const BagTopic& t : topics) {
    if (!s.empty()) s += ", ";
    s += t.messages ? fmt::format("{} ({}, {} messages)", t.name, t.type, t.messages)
                    : fmt::format("{} ({})", t.name, t.type);
  }
  return s.empty() ? std::string(tr("none")) : s;
}

// The 37 doubles after sensor_msgs/Imu's header: orientation (4), its covariance (9), then
// angular_velocity (3) at 13, its covariance, linear_acceleration (3) at 25, its covariance.
constexpr std::size_t kImuDoubles = 37, kGyroAt = 13, kAccelAt = 25;

template <class T>
T load(const char* p, bool swap) {
  T v;
  std::memcpy(&v, p, sizeof v);
  if (swap) {
    auto u = std::bit_cast<std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>>(v);
    u = sizeof(T) == 8 ? static_cast<decltype(u)>(__builtin_bswap64(u))
                       : static_cast<decltype(u)>(__builtin_bswap32(static_cast<std::uint32_t>(u)));
    v = std::bit_cast<T>(u);
  }
  return v;
}

void read_vectors(ImuMessage& m, const char* doubles, bool swap) {
  for (int i = 0; i < 3; ++i) {
    m.values[i] = load<double>(doubles + 8 * (kGyroAt + static_cast<std::size_t>(i)), swap);
    m.values[3 + i] = load<double>(doubles + 8 * (kAccelAt + static_cast<std::size_t>(i)), swap);
  }
}

[[noreturn]] void fail_message(const std::string& file, const Place& place, const std::string& what) {
  throw InputError(file, 0, trf("sensor_msgs/Imu message at {}: {}", place.str(), what));
}

std::int64_t stamp_of(std::int64_t sec, std::uint32_t nsec, const std::string& file, const Place& offset) {
  if (nsec >= 1'000'000'000U) fail_message(file, offset, trf("header.stamp has {} nanoseconds, not below 10^9", nsec));
  return sec * 1'000'000'000 + nsec;
}

}  // namespace

bool is_imu_type(std::string_view type) { return type == "sensor_msgs/Imu" || type == "sensor_msgs/msg/Imu"; }

// header: seq (uint32), stamp (uint32 s, uint32 ns), frame_id (uint32 length, bytes); then the doubles.
ImuMessage decode_ros1_imu(std::string_view b, const std::string& file, const Place& offset) {
  if (b.size() < 16) fail_message(file, offset, trf("{} bytes, too short for a header", b.size()));
  const auto len = load<std::uint32_t>(b.data() + 12, false);
  if (b.size() - 16 < len || b.size() - 16 - len < kImuDoubles * 8)
    fail_message(file, offset, trf("{} bytes, too short for a frame_id of {} bytes and the 37 numbers", b.size(), len));
  ImuMessage m;
  m.stamp_ns =
      stamp_of(load<std::uint32_t>(b.data() + 4, false), load<std::uint32_t>(b.data() + 8, false), file, offset);
  read_vectors(m, b.data() + 16 + len, false);
  return m;
}

// CDR: a 4-byte encapsulation header (its second byte 1: little-endian), then stamp (int32 s,
// uint32 ns), frame_id (uint32 length with the NUL, bytes), and the doubles aligned to 8 bytes
// counted from the end of the encapsulation header.
ImuMessage decode_cdr_imu(std::string_view b, const std::string& file, const Place& offset) {
  if (b.size() < 16) fail_message(file, offset, trf("{} bytes, too short for a header", b.size()));
  if (b[0] != 0 || (b[1] != 0 && b[1] != 1))
    fail_message(file, offset,
                 trf("not plain CDR: encapsulation bytes {:02x} {:02x}", static_cast<unsigned char>(b[0]),
                     static_cast<unsigned char>(b[1])));
  const bool swap = (b[1] == 1) != (std::endian::native == std::endian::little);
  const char* d = b.data() + 4;
  const std::size_t n = b.size() - 4;
  const auto len = load<std::uint32_t>(d + 8, swap);
  const std::size_t at = n - 12 < len ? n : (12 + std::size_t{len} + 7) / 8 * 8;
  if (at > n || n - at < kImuDoubles * 8)
    fail_message(file, offset, trf("{} bytes, too short for a frame_id of {} bytes and the 37 numbers", b.size(), len));
  ImuMessage m;
  m.stamp_ns = stamp_of(load<std::int32_t>(d, swap), load<std::uint32_t>(d + 4, swap), file, offset);
  read_vectors(m, d + at, swap);
  return m;
}

MappedFile::MappedFile(const std::string& path) : path_(path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (fd < 0 || ::fstat(fd, &st) != 0) {
    const int err = errno;
    if (fd >= 0) ::close(fd);
    throw InputError(path, 0, trf("cannot open: {}", std::strerror(err)));
  }
  size_ = static_cast<std::size_t>(st.st_size);
  if (size_ > 0) {
    void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    const int err = errno;
    ::close(fd);
    if (p == MAP_FAILED) throw InputError(path, 0, trf("cannot read: {}", std::strerror(err)));
    data_ = static_cast<const char*>(p);
    ::madvise(p, size_, MADV_SEQUENTIAL);
  } else {
    ::close(fd);
  }
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(const_cast<char*>(data_), size_);
}

void MappedFile::release(std::size_t upto) noexcept {
  const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  upto = std::min(upto, size_) / page * page;
  if (!data_ || upto <= released_) return;
  ::madvise(const_cast<char*>(data_) + released_, upto - released_, MADV_DONTNEED);
  released_ = upto;
}

std::string MappedFile::sha256() const {
  Sha256 h;
  const int fd = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path_, 0, trf("cannot read: {}", std::strerror(errno)));
  std::string buf(std::size_t{1} << 20, '\0');
  for (ssize_t n; (n = ::read(fd, buf.data(), buf.size())) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw InputError(path_, 0, trf("cannot read: {}", std::strerror(err)));
    }
    h.update(std::string_view(buf.data(), static_cast<std::size_t>(n)));
  }
  ::close(fd);
  return h.hex();
}

namespace {

// A ROS 2 bag as `ros2 bag record` leaves it: a directory with metadata.yaml and its storage file.
// Its one .db3 or .mcap file; an error for a bag split into several; "" for any other directory.
// (POSIX directory calls: <filesystem> brings std::quoted into the io layer's unity build, where
// it would take the reader's quoted() calls by argument-dependent lookup.)
std::string storage_of_bag_directory(const std::string& dir) {
  struct stat st {};
  if (::stat((dir + "/metadata.yaml").c_str(), &st) != 0) return "";
  std::vector<std::string> files;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      const std::string_view n = e->d_name;
      if (n.ends_with(".db3") || n.ends_with(".mcap")) files.push_back(dir + "/" + std::string(n));
    }
    ::closedir(d);
  }
  std::sort(files.begin(), files.end());
  if (files.size() == 1) return files.front();
  std::string list;
  for (const auto& f : files) list += (list.empty() ? "" : ", ") + f;
  throw InputError(dir, 0,
                   files.empty() ? std::string(tr("a ROS 2 bag directory without a .db3 or .mcap file"))
                                 : trf("a ROS 2 bag split into {} files ({}): give one of them", files.size(), list));
}

}  // namespace

std::unique_ptr<BagStream> BagStream::open(const std::string& given) {
  if (given == "-") return nullptr;
  struct stat st {};
  std::string path = given;
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    path = storage_of_bag_directory(given);
    if (path.empty() || ::stat(path.c_str(), &st) != 0) return nullptr;
  }
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return nullptr;
  char head[16] = {};
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return nullptr;
  const ssize_t got = ::read(fd, head, sizeof head);
  ::close(fd);
  const std::string_view h(head, got > 0 ? static_cast<std::size_t>(got) : 0);
  if (h.starts_with(kRos1Magic)) return open_ros1_bag(path, given);
  if (h.starts_with(kMcapMagic)) return open_mcap(path, given);
  if (h.starts_with(kSqliteMagic)) return open_ros2_sqlite(path, given);
  return nullptr;
}

void BagStream::select(const std::string& wanted) {
  const std::vector<BagTopic> all = topics();
  std::vector<BagTopic> imu;
  std::copy_if(all.begin(), all.end(), std::back_inserter(imu), [](const BagTopic& t) { return is_imu_type(t.type); });
  if (!wanted.empty()) {
    const auto it = std::find_if(all.begin(), all.end(), [&](const BagTopic& t) { return t.name == wanted; });
    if (it == all.end())
      throw InputError(name_, 0, trf("no topic '{}' in this {}; its topics: {}", wanted, format(), topic_list(all)));
    if (!is_imu_type(it->type))
      throw InputError(name_, 0,
                       trf("topic '{}' holds {}, not sensor_msgs/Imu; the Imu topics: {}", wanted, it->type,
                           topic_list(imu)));
    topic_ = *it;
  } else if (imu.size() == 1) {
    topic_ = imu.front();
  } else if (imu.empty()) {
    throw InputError(name_, 0, trf("no sensor_msgs/Imu topic in this {}; its topics: {}", format(), topic_list(all)));
  } else {
    throw InputError(name_, 0,
                     trf("{} sensor_msgs/Imu topics: choose one with --topic ({})", imu.size(), topic_list(imu)));
  }
  start(topic_);
}

std::string BagStream::sha256() const { return file_.sha256(); }

void BagStream::fail(std::uint64_t offset, const std::string& what) const {
  throw InputError(name_, 0, trf("byte {}: {}", offset, what));
}

template <class T>
T ByteCursor::get(std::string_view what) {
  if (left() < sizeof(T)) fail(what);
  T v;
  std::memcpy(&v, bytes_.data() + pos_, sizeof v);
  pos_ += sizeof v;
  return v;
}
template std::uint8_t ByteCursor::get<std::uint8_t>(std::string_view);
template std::uint16_t ByteCursor::get<std::uint16_t>(std::string_view);
template std::uint32_t ByteCursor::get<std::uint32_t>(std::string_view);
template std::uint64_t ByteCursor::get<std::uint64_t>(std::string_view);

std::string_view ByteCursor::take(std::uint64_t n, std::string_view what) {
  if (left() < n) fail(what);
  const std::string_view s = bytes_.substr(pos_, static_cast<std::size_t>(n));
  pos_ += static_cast<std::size_t>(n);
  return s;
}

std::string Place::str() const {
  if (row) return trf("row {}", at);
  if (chunk == ~std::uint64_t{0}) return trf("byte {}", at);
  return trf("offset {} of the chunk at byte {}", at, chunk);
}

void ByteCursor::fail(std::string_view what) const {
  throw InputError(file_, 0,
                   trf("{} at {}: ends before its {} ({} bytes left)", tr(std::string(record_)), where(), what,
                       left()));
}

std::string decompress_chunk(std::string_view compression, std::string_view data, std::uint64_t size,
                             const std::string& file, std::uint64_t offset) {
  const auto bad = [&](const std::string& why) -> std::string {
    throw InputError(file, 0, trf("chunk at byte {}: {} ({} compression)", offset, why, compression));
  };
  if (size > kMaxChunkBytes)
    bad(trf("states {} bytes uncompressed, more than the {} bytes rwcalc takes", size, kMaxChunkBytes));
  std::string out(static_cast<std::size_t>(size), '\0');
  std::size_t got = 0;
  if (compression == "bz2") {
    auto len = static_cast<unsigned>(size);
    const int r =
        BZ2_bzBuffToBuffDecompress(out.data(), &len, const_cast<char*>(data.data()),
                                   static_cast<unsigned>(std::min<std::size_t>(data.size(), 0xFFFFFFFFU)), 0, 0);
    if (r != BZ_OK) bad(trf("corrupt or larger than stated (bzip2 status {})", r));
    got = len;
  } else if (compression == "zstd") {
    got = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
    if (ZSTD_isError(got)) bad(trf("corrupt or larger than stated ({})", ZSTD_getErrorName(got)));
  } else if (compression == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) bad("no memory");
    std::size_t in = 0;
    std::size_t r = 1;
    while (r != 0 && in < data.size() && got <= out.size()) {
      std::size_t dst = out.size() - got, src = data.size() - in;
      r = LZ4F_decompress(ctx, out.data() + got, &dst, data.data() + in, &src, nullptr);
      if (LZ4F_isError(r) || (dst == 0 && src == 0)) break;
      got += dst, in += src;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (LZ4F_isError(r)) bad(trf("corrupt ({})", LZ4F_getErrorName(r)));
    if (r != 0) bad(tr("the compressed data end early or hold more than stated"));
  } else {
    bad(tr("unknown compression"));
  }
  if (got != size) bad(trf("gives {} bytes, not the {} bytes stated", got, size));
  return out;
}

}  // namespace rwcalc::detail
