#pragma once
// What every storage back end (one .db3 or one .mcap file) gives the bag reader: the topics it
// holds and its messages one at a time in recording-time order. The back ends are created by
// OpenSqlite3Storage (sqlite3_storage.h) and OpenMcapStorage (mcap_storage.h).

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
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

// Where the recording time goes back in the order the recorder wrote the messages (a clock
// stepped back while it recorded): the latest time written before and the time written after.
struct ClockStepBack {
  std::int64_t before_ns = 0;
  std::int64_t after_ns = 0;
};

// A recorder writes each topic's messages in the order it received them (a converter may write
// one topic after another, so only a topic's own order counts); several threads can swap two by
// a fraction of a millisecond. A step back by more than this is the clock's.
constexpr std::int64_t kClockStepBackToleranceNs = 10000000;  // 10 ms

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
  // The first step back of a topic's recording time by more than kClockStepBackToleranceNs in
  // the file's own (write) order, if any; `latest_ns` (by topic name) carries each topic's
  // latest time from the files before it and is updated. Reads the file once more.
  virtual std::optional<ClockStepBack> RecordingClockStepBack(
      std::map<std::string, std::int64_t>* latest_ns) = 0;
};

}  // namespace fitcal::io::rosbag2
