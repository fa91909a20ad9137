#pragma once
// What every storage back end (one .db3 or one .mcap file) gives the bag reader: the topics it
// holds and its messages one at a time in recording-time order. The back ends are created by
// OpenSqlite3Storage (sqlite3_storage.cc) and OpenMcapStorage (mcap_storage.cc).

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "io/rosbag2/bytes.h"

namespace fitcal::io::rosbag2 {

// One topic as rosbag2 records it (topics table / MCAP Channel + Schema).
struct TopicInfo {
  std::string name;                  // "/joint_states"
  std::string type;                  // "sensor_msgs/msg/JointState"
  std::string serialization_format;  // "cdr"
  std::uint64_t message_count = 0;   // messages of this topic in the file (or bag)
};

// One message as stored. `payload` points into the storage's buffers and stays valid until the
// next call to StorageReader::Next on the same storage.
struct StoredMessage {
  std::size_t topic_index = 0;  // into StorageReader::topics()
  std::int64_t time_ns = 0;     // recording (receive) time, ns since the epoch
  ByteView payload;             // serialized message (CDR for rosbag2's default)
};

class StorageReader {
 public:
  virtual ~StorageReader() = default;

  // Every topic of the file with its message count, in the file's order (first appearance).
  virtual const std::vector<TopicInfo>& topics() const = 0;
  // Earliest and latest message time in the file (both 0 when it holds no message).
  virtual std::int64_t start_time_ns() const = 0;
  virtual std::int64_t end_time_ns() const = 0;
  // The next message by time (ties: file order); false after the last one.
  virtual bool Next(StoredMessage* message) = 0;
  // Each message's topic (index into topics()) and recording time in the file's own (write)
  // order, until `visit` returns false. Reads the file once more.
  virtual void VisitInWriteOrder(
      const std::function<bool(std::size_t topic_index, std::int64_t time_ns)>& visit) = 0;
};

// Opens one .db3 file read-only. Throws InputError when it is missing, not an SQLite database,
// or lacks the rosbag2 tables.
std::unique_ptr<StorageReader> OpenSqlite3Storage(const std::string& path);

// Opens one .mcap file. Throws InputError for a missing, truncated or corrupt file.
std::unique_ptr<StorageReader> OpenMcapStorage(const std::string& path);

}  // namespace fitcal::io::rosbag2
