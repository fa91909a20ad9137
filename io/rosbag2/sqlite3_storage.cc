// rosbag2's sqlite3 storage (.db3). The schema, as the recorder writes it (read from the bags in
// ../shared/data/rosbag2; rosbag2_storage_sqlite3, schema versions 1-4 agree on these columns):
//   topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format TEXT,
//          offered_qos_profiles TEXT [v2+], type_description_hash TEXT [v4+])
//   messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB)
//   + index timestamp_idx on messages(timestamp); v3+ add tables schema and metadata, v4
//   message_definitions. Only the columns above the line are read, so every version opens.

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "io/rosbag2/errors.h"
#include "io/rosbag2/storage.h"
#include "odometry/text_format.h"

namespace fitcal::io::rosbag2 {
namespace {

// Every SQLite database starts with this 16-byte string (sqlite.org/fileformat.html, 1.3).
constexpr char kSqliteMagic[] = "SQLite format 3";

void CheckSqliteMagic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowBagError(InputErrorKind::kMissingFile, path, "cannot open the bag file");
  char magic[16] = {};
  in.read(magic, sizeof(magic));
  if (in.gcount() == 0) ThrowBagError(InputErrorKind::kEmptyFile, path, "empty .db3 file");
  if (in.gcount() < 16 || std::memcmp(magic, kSqliteMagic, sizeof(kSqliteMagic)) != 0) {
    ThrowBagError(InputErrorKind::kBadHeader, path,
                  "bad magic: not an SQLite database (truncated or not a .db3 file)");
  }
}

// A reader must not write next to its input, and must work on a read-only copy. SQLite opens a
// WAL-mode database (the recorder's resilient preset) by creating <db>-shm and <db>-wal beside
// it even with SQLITE_OPEN_READONLY, and fails where it cannot. A finished bag does not change
// while it is read: the URI parameter immutable=1 (sqlite.org/uri.html) makes SQLite take no
// lock and create no file. What an unfinished recording left in a -wal file is not in the
// database proper and immutable reads skip it: refused, so that no message is lost silently.
void CheckNoPendingWal(const std::string& path) {
  std::error_code ec;
  const auto wal_bytes = std::filesystem::file_size(path + "-wal", ec);
  if (!ec && wal_bytes > 0) {
    ThrowBagError(InputErrorKind::kBadValue, path,
                  "its write-ahead log " + path + "-wal holds " + std::to_string(wal_bytes) +
                      " bytes not yet in the database (a recording that did not finish); "
                      "checkpoint a copy first (sqlite3 <copy> 'PRAGMA wal_checkpoint')");
  }
}

// file: URI of `path` (sqlite.org/uri.html 3.1): absolute, every byte outside the unreserved
// set and '/' percent-encoded ('?', '#' and '%' would otherwise end or escape the path).
std::string ImmutableUri(const std::string& path) {
  const std::string absolute = std::filesystem::absolute(path).string();
  std::string uri = "file:";
  for (const char c : absolute) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (std::isalnum(u) || std::strchr("/-._~", c) != nullptr) {
      uri += c;
    } else {
      uri += StrFormat("%%%02X", u);
    }
  }
  return uri + "?immutable=1";
}

// SQLite's complaint, with what it means for a bag: a damaged file, or a database that is not
// a rosbag2 bag (no topics / messages table).
std::string Why(sqlite3* db) {
  const int code = sqlite3_errcode(db) & 0xFF;  // primary result code
  const std::string what = code == SQLITE_CORRUPT || code == SQLITE_NOTADB
                               ? "corrupt or truncated .db3 file"
                               : "not a rosbag2 database";
  return what + " (sqlite3: " + sqlite3_errmsg(db) + ")";
}

class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const std::string& path) : path_(path) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) {
      const std::string why = Why(db);
      sqlite3_finalize(stmt_);
      ThrowBagError(InputErrorKind::kBadHeader, path, why);
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  // True while there is a row; a corrupt database page is an InputError, not a silent end.
  bool Step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    ThrowBagError(InputErrorKind::kBadHeader, path_, Why(sqlite3_db_handle(stmt_)));
  }
  sqlite3_stmt* get() const { return stmt_; }

 private:
  sqlite3_stmt* stmt_ = nullptr;
  std::string path_;
};

std::string ColumnText(sqlite3_stmt* stmt, int column) {
  const auto* text = sqlite3_column_text(stmt, column);
  return text == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(text));
}

class Sqlite3Storage : public StorageReader {
 public:
  explicit Sqlite3Storage(const std::string& path) : path_(path) {
    CheckSqliteMagic(path);
    CheckNoPendingWal(path);
    sqlite3* db = nullptr;
    const int rc = sqlite3_open_v2(ImmutableUri(path).c_str(), &db,
                                   SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr);
    db_.reset(db);
    if (rc != SQLITE_OK) {
      ThrowBagError(InputErrorKind::kMissingFile, path,
                    std::string("sqlite3: ") + (db != nullptr ? sqlite3_errmsg(db) : "no memory"));
    }
    ReadTopics();
    CountMessages();
    messages_ = std::make_unique<Statement>(
        db, "SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp, id", path_);
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::int64_t start_time_ns() const override { return start_ns_; }
  std::int64_t end_time_ns() const override { return end_ns_; }
  bool Next(StoredMessage* message) override;
  // Write order is the messages table's id order (rosbag2 inserts them as they arrive).
  void VisitInWriteOrder(const std::function<bool(std::size_t, std::int64_t)>& visit) override {
    Statement in_write_order(db_.get(), "SELECT topic_id, timestamp FROM messages ORDER BY id",
                             path_);
    while (in_write_order.Step()) {
      const std::size_t topic = TopicIndex(sqlite3_column_int64(in_write_order.get(), 0));
      if (!visit(topic, sqlite3_column_int64(in_write_order.get(), 1))) return;
    }
  }

 private:
  void ReadTopics();
  void CountMessages();
  std::size_t TopicIndex(std::int64_t topic_id) const;

  struct CloseDb {
    void operator()(sqlite3* db) const { sqlite3_close(db); }
  };

  std::string path_;
  std::unique_ptr<sqlite3, CloseDb> db_;  // declared before messages_: closed after it
  std::vector<TopicInfo> topics_;
  std::map<std::int64_t, std::size_t> index_of_id_;
  std::int64_t start_ns_ = 0;
  std::int64_t end_ns_ = 0;
  std::unique_ptr<Statement> messages_;
  bool finished_ = false;
};

void Sqlite3Storage::ReadTopics() {
  Statement stmt(db_.get(), "SELECT id, name, type, serialization_format FROM topics ORDER BY id",
                 path_);
  while (stmt.Step()) {
    TopicInfo topic;
    topic.name = ColumnText(stmt.get(), 1);
    topic.type = ColumnText(stmt.get(), 2);
    topic.serialization_format = ColumnText(stmt.get(), 3);
    index_of_id_[sqlite3_column_int64(stmt.get(), 0)] = topics_.size();
    topics_.push_back(std::move(topic));
  }
}

void Sqlite3Storage::CountMessages() {
  Statement counts(db_.get(), "SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id", path_);
  while (counts.Step()) {
    const std::size_t i = TopicIndex(sqlite3_column_int64(counts.get(), 0));
    topics_[i].message_count = static_cast<std::uint64_t>(sqlite3_column_int64(counts.get(), 1));
  }
  Statement range(db_.get(), "SELECT MIN(timestamp), MAX(timestamp) FROM messages", path_);
  if (range.Step()) {
    start_ns_ = sqlite3_column_int64(range.get(), 0);
    end_ns_ = sqlite3_column_int64(range.get(), 1);
  }
}

std::size_t Sqlite3Storage::TopicIndex(std::int64_t topic_id) const {
  const auto it = index_of_id_.find(topic_id);
  if (it == index_of_id_.end()) {
    ThrowBagError(InputErrorKind::kBadValue, path_,
                  "a message refers to topic id " + std::to_string(topic_id) +
                      ", which the topics table does not list");
  }
  return it->second;
}

bool Sqlite3Storage::Next(StoredMessage* message) {
  sqlite3_stmt* stmt = messages_->get();
  // sqlite3_step after SQLITE_DONE would start the query over (sqlite.org/c3ref/step.html).
  if (finished_ || !messages_->Step()) {
    finished_ = true;
    return false;
  }
  if (sqlite3_column_type(stmt, 1) != SQLITE_INTEGER) {
    ThrowBagError(InputErrorKind::kNonNumeric, path_, "a message timestamp is not an integer");
  }
  message->topic_index = TopicIndex(sqlite3_column_int64(stmt, 0));
  message->time_ns = sqlite3_column_int64(stmt, 1);
  // sqlite3_column_blob before sqlite3_column_bytes (sqlite.org/c3ref/column_blob.html).
  const void* blob = sqlite3_column_blob(stmt, 2);
  const int size = sqlite3_column_bytes(stmt, 2);
  message->payload =
      ByteView(static_cast<const std::uint8_t*>(blob), static_cast<std::size_t>(size));
  return true;
}

}  // namespace

std::unique_ptr<StorageReader> OpenSqlite3Storage(const std::string& path) {
  return std::make_unique<Sqlite3Storage>(path);
}

}  // namespace fitcal::io::rosbag2
