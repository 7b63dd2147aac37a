// ROS 2 bags in SQLite storage (`.db3`): the `topics` table names each topic's type and
// serialization (CDR), the `messages` table holds (topic_id, timestamp, data) rows, read in the
// order they were written.
#include <sqlite3.h>

#include <fmt/format.h>

#include "bag.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::detail {

namespace {

// Rows taken per batch.
constexpr std::size_t kSqliteBatch = 4096;

class Ros2Sqlite final : public BagStream {
 public:
  Ros2Sqlite(const std::string& path, const std::string& name) : BagStream(path, name) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK)
      fail_db(tr("cannot open the SQLite database"));
    sqlite3_db_config(db_, SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
  }
  ~Ros2Sqlite() override {
    sqlite3_finalize(rows_);
    sqlite3_close(db_);
  }
  Ros2Sqlite(const Ros2Sqlite&) = delete;
  Ros2Sqlite& operator=(const Ros2Sqlite&) = delete;
  [[nodiscard]] std::string_view format() const override { return tr("ROS 2 bag (SQLite)"); }
  [[nodiscard]] std::size_t taken() const override { return 0; }
  bool next(std::vector<ImuMessage>& batch) override;

 protected:
  std::vector<BagTopic> topics() override;
  void start(const BagTopic& topic) override;

 private:
  [[noreturn]] void fail_db(const std::string& what) const {
    throw InputError(name(), 0, trf("{}: {}", what, db_ ? sqlite3_errmsg(db_) : "no memory"));
  }
  sqlite3_stmt* prepare(const char* sql) const {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_, sql, -1, &s, nullptr) != SQLITE_OK)
      fail_db(tr("not a ROS 2 bag's SQLite storage (no topics and messages tables as rosbag2 writes them)"));
    return s;
  }

  sqlite3* db_ = nullptr;
  sqlite3_stmt* rows_ = nullptr;
  bool done_ = false;
};

std::string column_text(sqlite3_stmt* s, int i) {
  const unsigned char* t = sqlite3_column_text(s, i);
  return t ? std::string(reinterpret_cast<const char*>(t), static_cast<std::size_t>(sqlite3_column_bytes(s, i))) : "";
}

std::vector<BagTopic> Ros2Sqlite::topics() {
  sqlite3_stmt* s = prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY name");
  std::vector<BagTopic> out;
  int rc = 0;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    BagTopic t;
    t.id = static_cast<std::uint32_t>(sqlite3_column_int64(s, 0));
    t.name = column_text(s, 1);
    t.type = column_text(s, 2);
    const std::string format = column_text(s, 3);
    if (format != "cdr" && is_imu_type(t.type)) t.type += " (" + format + ")";  // not decoded: not taken
    out.push_back(std::move(t));
  }
  sqlite3_finalize(s);
  if (rc != SQLITE_DONE) fail_db(tr("cannot read the topics table"));
  return out;
}

void Ros2Sqlite::start(const BagTopic& topic) {
  rows_ = prepare("SELECT id, timestamp, data FROM messages WHERE topic_id = ? ORDER BY id");
  sqlite3_bind_int64(rows_, 1, topic.id);
}

bool Ros2Sqlite::next(std::vector<ImuMessage>& batch) {
  batch.clear();
  while (!done_ && batch.size() < kSqliteBatch) {
    const int rc = sqlite3_step(rows_);
    if (rc == SQLITE_DONE) {
      done_ = true;
      break;
    }
    if (rc != SQLITE_ROW) fail_db(tr("cannot read the messages table"));
    const Place place{static_cast<std::uint64_t>(sqlite3_column_int64(rows_, 0)), ~std::uint64_t{0}, true};
    const void* blob = sqlite3_column_blob(rows_, 2);
    const std::string_view data(static_cast<const char*>(blob),
                                blob ? static_cast<std::size_t>(sqlite3_column_bytes(rows_, 2)) : 0);
    ImuMessage m = decode_cdr_imu(data, name(), place);
    m.receive_ns = sqlite3_column_int64(rows_, 1);
    batch.push_back(m);
  }
  return !batch.empty();
}

}  // namespace

std::unique_ptr<BagStream> open_ros2_sqlite(const std::string& path, const std::string& name) {
  return std::make_unique<Ros2Sqlite>(path, name);
}

}  // namespace rwcalc::detail
