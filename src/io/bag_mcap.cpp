// MCAP files (ROS 2's default storage, also ROS 1 messages): records of an opcode, a length and a
// body; chunks (uncompressed, zstd or lz4) hold schemas, channels and messages. The topics come from
// the summary section after the data (or, without one, from a scan of the whole file).
#include <map>
#include <set>

#include <fmt/format.h>

#include "bag.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::detail {

namespace {

enum McapOp : std::uint8_t {
  kMcapFooter = 0x02,
  kMcapSchema = 0x03,
  kMcapChannel = 0x04,
  kMcapMessage = 0x05,
  kMcapChunk = 0x06,
  kMcapStatistics = 0x0B,
  kMcapDataEnd = 0x0F
};
constexpr std::size_t kMcapMagicBytes = 8, kFooterBytes = 1 + 8 + 8 + 8 + 4;

struct McapRecord {
  std::uint8_t op = 0;
  std::string_view body;
  std::uint64_t at = 0;
};

struct McapChannel {
  std::string topic, encoding;
  std::uint16_t schema = 0;
};

class McapFile final : public BagStream {
 public:
  McapFile(const std::string& path, const std::string& name) : BagStream(path, name) {
    if (size() < 2 * kMcapMagicBytes + kFooterBytes) fail(0, tr("an MCAP file too short for its footer"));
    pos_ = kMcapMagicBytes;
  }
  [[nodiscard]] std::string_view format() const override { return tr("MCAP file"); }
  [[nodiscard]] std::size_t taken() const override { return pos_; }
  bool next(std::vector<ImuMessage>& batch) override;

 protected:
  std::vector<BagTopic> topics() override;
  void start(const BagTopic& topic) override {
    for (const auto& [id, c] : channels_)
      if (c.topic == topic.name) wanted_[id] = c.encoding == "ros1";
  }

 private:
  static bool next_record(ByteCursor& c, McapRecord& r) {
    if (c.left() == 0) return false;
    r.at = c.offset();
    r.op = c.get<std::uint8_t>(tr("opcode"));
    r.body = c.take(c.get<std::uint64_t>(tr("length")), tr("body"));
    return true;
  }
  void definition(const McapRecord& r, const ByteCursor& where);
  void scan_summary(std::map<std::uint16_t, std::uint64_t>& counts);
  void scan_all();
  void read_records(std::string_view bytes, std::uint64_t base, std::uint64_t chunk, std::vector<ImuMessage>* batch);
  void take_message(const McapRecord& r, const ByteCursor& where, std::vector<ImuMessage>& batch);

  std::size_t pos_ = 0;
  std::map<std::uint16_t, std::string> schemas_;  // their names: the message types
  std::map<std::uint16_t, McapChannel> channels_;
  std::map<std::uint16_t, bool> wanted_;  // the topic's channels: ROS 1 encoded (else CDR)
  bool data_end_ = false;
};

// A schema or channel record, wherever it is (summary, data, chunk).
void McapFile::definition(const McapRecord& r, const ByteCursor& where) {
  ByteCursor c(r.body, where.place(r.at).at, name(),
               r.op == kMcapSchema ? N_("MCAP schema record") : N_("MCAP channel record"));
  if (r.op == kMcapSchema) {
    const auto id = c.get<std::uint16_t>(tr("id"));
    schemas_[id] = std::string(c.string32(tr("name")));
  } else {
    const auto id = c.get<std::uint16_t>(tr("id"));
    McapChannel ch;
    ch.schema = c.get<std::uint16_t>(tr("schema id"));
    ch.topic = c.string32(tr("topic"));
    ch.encoding = c.string32(tr("message encoding"));
    channels_[id] = std::move(ch);
  }
}

// The summary section: schemas, channels, and the statistics' message count per channel.
void McapFile::scan_summary(std::map<std::uint16_t, std::uint64_t>& counts) {
  const std::uint64_t footer_at = size() - kMcapMagicBytes - kFooterBytes;
  ByteCursor f(bytes().substr(footer_at, kFooterBytes), footer_at, name(), N_("MCAP footer"));
  if (f.get<std::uint8_t>(tr("opcode")) != kMcapFooter || f.get<std::uint64_t>(tr("length")) != kFooterBytes - 9)
    fail(footer_at, tr("no MCAP footer before the closing magic bytes: the file is cut off or not MCAP"));
  const auto summary = f.get<std::uint64_t>(tr("summary start"));
  if (summary == 0) return scan_all();
  if (summary < kMcapMagicBytes || summary > footer_at)
    fail(footer_at, trf("the footer's summary start {} is outside the file's data", summary));
  ByteCursor c(bytes().substr(summary, footer_at - summary), summary, name(), N_("MCAP summary record"));
  for (McapRecord r; next_record(c, r);) {
    if (r.op == kMcapSchema || r.op == kMcapChannel) definition(r, c);
    if (r.op != kMcapStatistics) continue;
    ByteCursor s(r.body, r.at, name(), N_("MCAP statistics record"));
    s.take(8 + 2 + 4 + 4 + 4 + 4 + 8 + 8, tr("counts"));
    ByteCursor m(s.string32(tr("message counts")), s.offset(), name(), N_("MCAP statistics record"));
    while (m.left() > 0) {
      const auto id = m.get<std::uint16_t>(tr("channel id"));
      counts[id] += m.get<std::uint64_t>(tr("message count"));
    }
  }
}

// A file without a summary: every record (chunks decompressed) for its schemas and channels.
void McapFile::scan_all() {
  const std::uint64_t end = size() - kMcapMagicBytes - kFooterBytes;
  read_records(bytes().substr(kMcapMagicBytes, end - kMcapMagicBytes), kMcapMagicBytes, ~std::uint64_t{0}, nullptr);
  data_end_ = false;
}

std::vector<BagTopic> McapFile::topics() {
  std::map<std::uint16_t, std::uint64_t> counts;
  scan_summary(counts);
  std::map<std::string, BagTopic> by_topic;
  for (const auto& [id, c] : channels_) {
    BagTopic& t = by_topic[c.topic];
    t.name = c.topic;
    const auto s = schemas_.find(c.schema);
    if (t.type.empty()) t.type = s != schemas_.end() ? s->second : c.encoding;
    t.messages += counts[id];
  }
  std::vector<BagTopic> out;
  out.reserve(by_topic.size());
  for (auto& [topic, t] : by_topic) out.push_back(std::move(t));
  return out;
}

// Records of the data section or of a chunk; messages of the topic go to `batch` (none while the
// topics are being found).
void McapFile::read_records(std::string_view bytes, std::uint64_t base, std::uint64_t chunk,
                            std::vector<ImuMessage>* batch) {
  ByteCursor c(bytes, base, name(), N_("MCAP record"));
  if (chunk != ~std::uint64_t{0}) c.inside_chunk(chunk);
  for (McapRecord r; !data_end_ && next_record(c, r);) {
    if (r.op == kMcapSchema || r.op == kMcapChannel) {
      definition(r, c);
    } else if (r.op == kMcapMessage && batch) {
      take_message(r, c, *batch);
    } else if (r.op == kMcapChunk) {
      ByteCursor k(r.body, r.at + 9, name(), N_("MCAP chunk record"));
      k.take(16, tr("times"));
      const auto size = k.get<std::uint64_t>(tr("uncompressed size"));
      k.get<std::uint32_t>(tr("uncompressed CRC"));
      const std::string_view compression = k.string32(tr("compression"));
      const std::string_view data = k.take(k.get<std::uint64_t>(tr("records length")), tr("records"));
      if (compression.empty()) {
        read_records(data, k.offset() - data.size(), ~std::uint64_t{0}, batch);
      } else {
        const std::string plain = decompress_chunk(compression, data, size, name(), r.at);
        read_records(plain, 0, r.at, batch);
      }
    } else if (r.op == kMcapDataEnd || r.op == kMcapFooter) {
      data_end_ = true;
    }
  }
}

void McapFile::take_message(const McapRecord& r, const ByteCursor& where, std::vector<ImuMessage>& batch) {
  ByteCursor c(r.body, r.at + 9, name(), N_("MCAP message record"));
  const auto channel = c.get<std::uint16_t>(tr("channel id"));
  const auto it = wanted_.find(channel);
  if (it == wanted_.end()) return;
  c.get<std::uint32_t>(tr("sequence"));
  const auto log_time = c.get<std::uint64_t>(tr("log time"));
  c.get<std::uint64_t>(tr("publish time"));
  const std::string_view data = c.take(c.left(), "");
  const Place place = where.place(r.at);
  ImuMessage m = it->second ? decode_ros1_imu(data, name(), place) : decode_cdr_imu(data, name(), place);
  if (log_time > static_cast<std::uint64_t>(INT64_MAX))
    throw InputError(name(), 0, trf("MCAP message record at {}: log time {} ns is beyond 2^63", place.str(), log_time));
  m.receive_ns = static_cast<std::int64_t>(log_time);
  batch.push_back(m);
}

// One top-level record at a time (a chunk holds many messages).
bool McapFile::next(std::vector<ImuMessage>& batch) {
  batch.clear();
  const std::uint64_t end = size() - kMcapMagicBytes - kFooterBytes;
  while (batch.empty() && !data_end_ && pos_ < end) {
    ByteCursor c(bytes().substr(pos_, end - pos_), pos_, name(), N_("MCAP record"));
    McapRecord r;
    next_record(c, r);
    read_records(bytes().substr(pos_, c.offset() - pos_), pos_, ~std::uint64_t{0}, &batch);
    pos_ = c.offset();
  }
  release(pos_);
  return !batch.empty();
}

}  // namespace

std::unique_ptr<BagStream> open_mcap(const std::string& path, const std::string& name) {
  return std::make_unique<McapFile>(path, name);
}

}  // namespace rwcalc::detail
