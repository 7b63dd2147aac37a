#pragma once
// Bags of robot data (ROS 1 `.bag`, ROS 2 `.db3` and `.mcap`) as the reader sees them: the messages
// of one sensor_msgs/Imu topic, each its stamps and six channels, in the order they were recorded.
// Every byte is untrusted: anything malformed is an InputError naming the file, the byte offset (or
// the row) and what was wrong.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rwcalc::detail {

/// One sensor_msgs/Imu message: header.stamp and the bag's receive time in ns since the epoch, and
/// angular_velocity x, y, z (rad/s) then linear_acceleration x, y, z (m/s²), as ROS defines them.
struct ImuMessage {
  std::int64_t stamp_ns = 0, receive_ns = 0;
  double values[6] = {};
};

/// The columns a bag gives, named as `rostopic echo -p` names them, so that a bag reads exactly as
/// its CSV export: the header stamp, the receive time, then the six channels.
inline constexpr std::string_view kBagStampColumn = "field.header.stamp";
inline constexpr std::string_view kBagReceiveColumn = "%time";
inline constexpr std::string_view kImuFieldColumns[6] = {"field.angular_velocity.x",    "field.angular_velocity.y",
                                                         "field.angular_velocity.z",    "field.linear_acceleration.x",
                                                         "field.linear_acceleration.y", "field.linear_acceleration.z"};

struct BagTopic {
  std::string name, type;
  std::uint64_t messages = 0;  ///< as the bag's index counts them (0: not counted)
  std::uint32_t id = 0;        ///< the connection, channel or topic id(s) are the reader's own
};

/// "sensor_msgs/Imu" (ROS 1) or "sensor_msgs/msg/Imu" (ROS 2).
bool is_imu_type(std::string_view type);

/// Where a record or message is, as errors say it: "byte 123", "offset 45 of the chunk at byte 678"
/// (decompressed chunks), or "row 9" (SQLite storage).
struct Place {
  std::uint64_t at = 0;
  std::uint64_t chunk = ~std::uint64_t{0};
  bool row = false;
  [[nodiscard]] std::string str() const;
};

/// A message's bytes decoded with bounds checks: a short message is an error naming its place.
/// ROS 1 messages are little-endian; CDR (ROS 2) gives its byte order in its first bytes.
ImuMessage decode_ros1_imu(std::string_view bytes, const std::string& file, const Place& place);
ImuMessage decode_cdr_imu(std::string_view bytes, const std::string& file, const Place& place);

/// The file's bytes, mapped read-only; each piece taken is bounds-checked.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  [[nodiscard]] std::string_view bytes() const noexcept { return {data_, size_}; }
  /// The bytes before `upto` are read: their pages leave the process' memory (the file keeps them).
  void release(std::size_t upto) noexcept;
  /// The SHA-256 of the file, read again through read(2) (no mapped page stays in memory).
  [[nodiscard]] std::string sha256() const;

 private:
  std::string path_;
  const char* data_ = nullptr;
  std::size_t size_ = 0, released_ = 0;
};

/// A bag of one of the three formats, its Imu topic chosen. Reading goes message batch by batch.
class BagStream {
 public:
  virtual ~BagStream() = default;
  /// A bag, told by its first bytes, or a ROS 2 bag's directory (metadata.yaml and one .db3 or
  /// .mcap file); null for a file that is none (text, gzip) or cannot be opened (the text reader
  /// then says why).
  static std::unique_ptr<BagStream> open(const std::string& path);
  /// The topic to read: the one named, else the only sensor_msgs/Imu topic. InputError listing the
  /// Imu topics (or all topics when there is none) when that does not decide.
  void select(const std::string& topic);
  /// The next messages of the topic, in the bag's order, replacing `batch`; false (an empty batch)
  /// once all are read.
  virtual bool next(std::vector<ImuMessage>& batch) = 0;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] const BagTopic& topic() const noexcept { return topic_; }
  [[nodiscard]] virtual std::string_view format() const = 0;
  [[nodiscard]] std::size_t size() const noexcept { return file_.bytes().size(); }
  /// Bytes taken so far (for the progress line).
  [[nodiscard]] virtual std::size_t taken() const = 0;
  /// The SHA-256 of the whole file, as `sha256sum` prints it.
  [[nodiscard]] std::string sha256() const;

 protected:
  BagStream(const std::string& path, std::string name) : name_(std::move(name)), file_(path) {}
  [[nodiscard]] virtual std::vector<BagTopic> topics() = 0;
  virtual void start(const BagTopic& topic) = 0;
  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const;
  [[nodiscard]] std::string_view bytes() const noexcept { return file_.bytes(); }
  void release(std::size_t upto) noexcept { file_.release(upto); }

 private:
  std::string name_;
  MappedFile file_;
  BagTopic topic_;
};

/// The three readers (bag_ros1.cpp, bag_mcap.cpp, bag_sqlite.cpp).
std::unique_ptr<BagStream> open_ros1_bag(const std::string& path, const std::string& name);
std::unique_ptr<BagStream> open_mcap(const std::string& path, const std::string& name);
std::unique_ptr<BagStream> open_ros2_sqlite(const std::string& path, const std::string& name);

/// Bounds-checked little-endian reading of a record's bytes; errors name the byte offset in the file.
class ByteCursor {
 public:
  ByteCursor(std::string_view bytes, std::uint64_t base, const std::string& file, std::string_view record)
      : bytes_(bytes), base_(base), file_(file), record_(record) {}
  template <class T>
  T get(std::string_view what);
  std::string_view take(std::uint64_t n, std::string_view what);
  std::string_view string32(std::string_view what) { return take(get<std::uint32_t>(what), what); }
  [[nodiscard]] std::uint64_t offset() const noexcept { return base_ + pos_; }
  [[nodiscard]] std::size_t left() const noexcept { return bytes_.size() - pos_; }
  [[noreturn]] void fail(std::string_view what) const;
  /// The bytes are a decompressed chunk's, which starts at byte `at` of the file: offsets are
  /// then said within the chunk.
  void inside_chunk(std::uint64_t at) noexcept { chunk_ = at; }
  [[nodiscard]] Place place(std::uint64_t at) const noexcept { return {at, chunk_}; }
  [[nodiscard]] std::string where(std::uint64_t at) const { return place(at).str(); }
  [[nodiscard]] std::string where() const { return where(offset()); }
  void seek(std::size_t pos) noexcept { pos_ = std::min(pos, bytes_.size()); }
  [[nodiscard]] std::size_t pos() const noexcept { return pos_; }

 private:
  std::string_view bytes_;
  std::uint64_t base_;
  std::size_t pos_ = 0;
  std::uint64_t chunk_ = ~std::uint64_t{0};
  const std::string& file_;
  std::string_view record_;
};

/// Decompressed chunk bytes: "lz4" (the LZ4 frame format), "zstd", "bz2"; `size` is the size the
/// record states, which the result must have. InputError at `offset` otherwise.
std::string decompress_chunk(std::string_view compression, std::string_view data, std::uint64_t size,
                             const std::string& file, std::uint64_t offset);

}  // namespace rwcalc::detail
