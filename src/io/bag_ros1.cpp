// ROS 1 bags, format 2.0: records (a header of `name=value` fields, then data) of which chunks
// (uncompressed, bz2 or lz4) hold the connections and messages; the index after `index_pos` lists
// the connections and counts their messages. The chunks are read in file order.
#include <cstring>
#include <map>
#include <set>

#include <fmt/format.h>

#include "bag.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::detail {

namespace {

enum Ros1Op : std::uint8_t {
  kMessage = 0x02,
  kBagHeader = 0x03,
  kIndex = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07
};

// One record: its header fields and its data.
struct Ros1Record {
  std::vector<std::pair<std::string_view, std::string_view>> fields;
  std::string_view data;
  std::uint64_t at = 0;  // where the record starts (in the file or the chunk)
  std::uint8_t op = 0;
};

class Ros1Records {
 public:
  Ros1Records(std::string_view bytes, std::uint64_t base, const std::string& file, std::uint64_t chunk_at)
      : file_(file), cur_(bytes, base, file, N_("ROS 1 bag record")) {
    if (chunk_at != ~std::uint64_t{0}) cur_.inside_chunk(chunk_at);
  }
  bool next(Ros1Record& r) {
    if (cur_.left() == 0) return false;
    r.at = cur_.offset();
    ByteCursor head(cur_.string32(tr("header length")), cur_.offset(), file(), "");
    r.fields.clear();
    while (head.left() > 0) {
      const std::string_view f = cur_take_field(head);
      const auto eq = f.find('=');
      if (eq == std::string_view::npos) fail(r.at, tr("a header field without '='"));
      r.fields.emplace_back(f.substr(0, eq), f.substr(eq + 1));
    }
    r.data = cur_.string32(tr("data"));
    const std::string_view op = field(r, "op");
    if (op.size() != 1) fail(r.at, trf("field 'op' has {} bytes, not 1", op.size()));
    r.op = static_cast<std::uint8_t>(op[0]);
    return true;
  }
  [[nodiscard]] std::string_view field(const Ros1Record& r, std::string_view name) const {
    for (const auto& [k, v] : r.fields)
      if (k == name) return v;
    fail(r.at, trf("no header field '{}'", name));
  }
  template <class T>
  T number(const Ros1Record& r, std::string_view name) const {
    const std::string_view v = field(r, name);
    if (v.size() != sizeof(T)) fail(r.at, trf("field '{}' has {} bytes, not {}", name, v.size(), sizeof(T)));
    T x;
    std::memcpy(&x, v.data(), sizeof x);
    return x;
  }
  [[noreturn]] void fail(std::uint64_t at, const std::string& what) const {
    throw InputError(file(), 0, trf("ROS 1 bag record at {}: {}", cur_.where(at), what));
  }
  [[nodiscard]] const ByteCursor& cursor() const noexcept { return cur_; }

 private:
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  std::string_view cur_take_field(ByteCursor& head) const {
    std::uint32_t n = 0;
    const std::string_view len = head.left() >= 4 ? head.take(4, "") : std::string_view{};
    if (len.size() != 4) fail(head.offset(), tr("a header field's length is cut off"));
    std::memcpy(&n, len.data(), 4);
    if (head.left() < n) fail(head.offset(), trf("a header field of {} bytes runs past the header", n));
    return head.take(n, "");
  }

  const std::string& file_;
  ByteCursor cur_;
};

class Ros1Bag final : public BagStream {
 public:
  Ros1Bag(const std::string& path, const std::string& name) : BagStream(path, name) {
    Ros1Records recs(bytes().substr(13), 13, this->name(), ~std::uint64_t{0});
    Ros1Record r;
    if (!recs.next(r) || r.op != kBagHeader) fail(13, tr("the first record is not the bag header"));
    index_pos_ = recs.number<std::uint64_t>(r, "index_pos");
    pos_ = recs.cursor().offset();
    if (index_pos_ == 0 || index_pos_ < pos_ || index_pos_ > size())
      fail(13, trf("the bag header's index_pos {} is not within the file ({} bytes): the bag was not closed; "
                   "`rosbag reindex` repairs it",
                   index_pos_, size()));
  }
  [[nodiscard]] std::string_view format() const override { return tr("ROS 1 bag"); }
  [[nodiscard]] std::size_t taken() const override { return pos_; }
  bool next(std::vector<ImuMessage>& batch) override;

 protected:
  std::vector<BagTopic> topics() override;
  void start(const BagTopic& topic) override { wanted_ = connections_[topic.name]; }

 private:
  void read_chunk(const Ros1Records& outer, const Ros1Record& chunk, std::vector<ImuMessage>& batch);
  void take_message(const Ros1Records& recs, const Ros1Record& r, std::vector<ImuMessage>& batch);

  std::uint64_t index_pos_ = 0, pos_ = 0;
  std::map<std::string, std::set<std::uint32_t>> connections_;  // by topic
  std::set<std::uint32_t> wanted_;
};

// The index: connection records (topic, type) and chunk infos (messages per connection).
std::vector<BagTopic> Ros1Bag::topics() {
  Ros1Records recs(bytes().substr(index_pos_), index_pos_, name(), ~std::uint64_t{0});
  std::map<std::uint32_t, std::uint64_t> counts;
  std::map<std::string, BagTopic> by_topic;
  std::map<std::uint32_t, std::string> topic_of;
  for (Ros1Record r; recs.next(r);) {
    if (r.op == kConnection) {
      const auto conn = recs.number<std::uint32_t>(r, "conn");
      const std::string topic(recs.field(r, "topic"));
      std::string type;
      ByteCursor c(r.data, recs.cursor().offset() - r.data.size(), name(), N_("ROS 1 connection record"));
      while (c.left() > 0) {
        const std::string_view f = c.string32(tr("connection header field"));
        if (f.starts_with("type=")) type = f.substr(5);
      }
      connections_[topic].insert(conn);
      topic_of[conn] = topic;
      BagTopic& t = by_topic[topic];
      t.name = topic;
      if (!type.empty()) t.type = type;
    } else if (r.op == kChunkInfo) {
      ByteCursor c(r.data, 0, name(), N_("chunk info record"));
      while (c.left() > 0) {
        const auto conn = c.get<std::uint32_t>(tr("connection id"));
        counts[conn] += c.get<std::uint32_t>(tr("message count"));
      }
    }
  }
  for (const auto& [conn, n] : counts)
    if (topic_of.count(conn)) by_topic[topic_of[conn]].messages += n;
  std::vector<BagTopic> out;
  out.reserve(by_topic.size());
  for (auto& [topic, t] : by_topic) out.push_back(std::move(t));
  return out;
}

bool Ros1Bag::next(std::vector<ImuMessage>& batch) {
  batch.clear();
  while (batch.empty() && pos_ < index_pos_) {
    Ros1Records recs(bytes().substr(pos_, index_pos_ - pos_), pos_, name(), ~std::uint64_t{0});
    Ros1Record r;
    recs.next(r);
    pos_ = recs.cursor().offset();
    if (r.op == kChunk)
      read_chunk(recs, r, batch);
    else if (r.op == kMessage)
      take_message(recs, r, batch);
  }
  release(pos_);
  return !batch.empty();
}

void Ros1Bag::read_chunk(const Ros1Records& outer, const Ros1Record& chunk, std::vector<ImuMessage>& batch) {
  const std::string_view compression = outer.field(chunk, "compression");
  const auto size = outer.number<std::uint32_t>(chunk, "size");
  const std::uint64_t data_at = outer.cursor().offset() - chunk.data.size();
  std::string plain;
  std::string_view records = chunk.data;
  if (compression != "none") {
    plain = decompress_chunk(compression, chunk.data, size, name(), chunk.at);
    records = plain;
  } else if (size != chunk.data.size()) {
    outer.fail(chunk.at, trf("an uncompressed chunk of {} bytes states {}", chunk.data.size(), size));
  }
  Ros1Records recs(records, compression == "none" ? data_at : 0, name(),
                   compression == "none" ? ~std::uint64_t{0} : chunk.at);
  for (Ros1Record r; recs.next(r);)
    if (r.op == kMessage) take_message(recs, r, batch);
}

void Ros1Bag::take_message(const Ros1Records& recs, const Ros1Record& r, std::vector<ImuMessage>& batch) {
  if (!wanted_.count(recs.number<std::uint32_t>(r, "conn"))) return;
  const auto t = recs.number<std::uint64_t>(r, "time");  // uint32 seconds, then uint32 nanoseconds
  const auto sec = static_cast<std::uint32_t>(t), nsec = static_cast<std::uint32_t>(t >> 32);
  if (nsec >= 1'000'000'000U) recs.fail(r.at, trf("receive time with {} nanoseconds, not below 10^9", nsec));
  ImuMessage m = decode_ros1_imu(r.data, name(), recs.cursor().place(r.at));
  m.receive_ns = static_cast<std::int64_t>(sec) * 1'000'000'000 + nsec;
  batch.push_back(m);
}

}  // namespace

std::unique_ptr<BagStream> open_ros1_bag(const std::string& path, const std::string& name) {
  return std::make_unique<Ros1Bag>(path, name);
}

}  // namespace rwcalc::detail
