#include <sqlite3.h>

#include <stdexcept>

#include "tests/bags/storage_writer.h"

namespace fitcal::io::rosbag2 {
namespace {

// The tables rosbag2's sqlite3 plugin creates at schema version 4 (as found in the recorder's
// own bags, ../shared/data/rosbag2/sqlite3/cdr_test).
constexpr const char* kCreateTables =
    "PRAGMA journal_mode=MEMORY; PRAGMA synchronous=OFF;"
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);"
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,"
    "metadata TEXT NOT NULL);"
    "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
    "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL,"
    "type_description_hash TEXT NOT NULL);"
    "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY,topic_type TEXT NOT NULL,"
    "encoding TEXT NOT NULL,encoded_message_definition TEXT NOT NULL,"
    "type_description_hash TEXT NOT NULL);"
    "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
    "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
    "INSERT INTO schema VALUES(4, 'fitcal');"
    "BEGIN TRANSACTION;";

class Sqlite3Writer : public StorageWriter {
 public:
  explicit Sqlite3Writer(const std::string& path) : path_(path) {
    sqlite3* db = nullptr;
    const int rc =
        sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
    db_ = db;
    try {
      if (rc != SQLITE_OK) Fail("cannot create");
      Exec(kCreateTables);
      Prepare("INSERT INTO topics VALUES(?, ?, ?, ?, '', '')", &insert_topic_);
      Prepare("INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", &insert_message_);
    } catch (...) {
      Release();
      throw;
    }
  }
  ~Sqlite3Writer() override { Release(); }

  void AddTopic(std::size_t topic_index, const TopicInfo& topic) override {
    sqlite3_bind_int64(insert_topic_, 1, static_cast<sqlite3_int64>(topic_index + 1));
    sqlite3_bind_text(insert_topic_, 2, topic.name.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert_topic_, 3, topic.type.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert_topic_, 4, topic.serialization_format.c_str(), -1, SQLITE_TRANSIENT);
    Run(insert_topic_);
  }

  void Write(std::size_t topic_index, std::int64_t time_ns, ByteView payload) override {
    sqlite3_bind_int64(insert_message_, 1, static_cast<sqlite3_int64>(topic_index + 1));
    sqlite3_bind_int64(insert_message_, 2, time_ns);
    // A zero-length blob must still be a blob, not NULL (data is NOT NULL).
    sqlite3_bind_blob64(insert_message_, 3, payload.size > 0 ? payload.data : nullptr, payload.size,
                        SQLITE_STATIC);
    if (payload.size == 0) sqlite3_bind_zeroblob(insert_message_, 3, 0);
    Run(insert_message_);
  }

  void Close() override { Exec("COMMIT;"); }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(path_ + ": " + what + ": " +
                             (db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory"));
  }
  void Exec(const char* sql) {
    if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) != SQLITE_OK) Fail("sqlite3");
  }
  void Prepare(const char* sql, sqlite3_stmt** stmt) {
    if (sqlite3_prepare_v2(db_, sql, -1, stmt, nullptr) != SQLITE_OK) Fail("sqlite3");
  }
  void Release() {
    sqlite3_finalize(insert_topic_);
    sqlite3_finalize(insert_message_);
    sqlite3_close(db_);
  }
  void Run(sqlite3_stmt* stmt) {
    if (sqlite3_step(stmt) != SQLITE_DONE) Fail("sqlite3 insert");
    sqlite3_reset(stmt);
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_topic_ = nullptr;
  sqlite3_stmt* insert_message_ = nullptr;
};

}  // namespace

std::unique_ptr<StorageWriter> CreateSqlite3Writer(const std::string& path) {
  return std::make_unique<Sqlite3Writer>(path);
}

}  // namespace fitcal::io::rosbag2
