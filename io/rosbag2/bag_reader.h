#pragma once
// Reading a rosbag2 bag without ROS: open a bag directory (or its metadata.yaml, or one .db3 /
// .mcap file), list its topics, and walk its messages in recording-time order across every file
// of a split bag. Payloads come out serialized (CDR); ros_messages.h decodes the types fitcal
// uses.
//
//   rosbag2::BagReader bag("recordings/run_3");
//   rosbag2::BagMessage m;
//   while (bag.ReadNext(&m)) {
//     if (m.topic->type == "sensor_msgs/msg/JointState") {
//       Use(DecodeJointState(m.payload, Describe(m)));
//     }
//   }

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/rosbag2/bag_metadata.h"
#include "io/rosbag2/storage.h"

namespace fitcal::io::rosbag2 {

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

struct BagMessage {
  const TopicInfo* topic = nullptr;   // into BagReader::topics()
  const std::string* file = nullptr;  // into BagReader::files()
  std::int64_t time_ns = 0;           // recording time, ns since the epoch
  ByteView payload;                   // valid until the next ReadNext
};

// "<file> <topic> message at <time> ns": names a message in decoder errors (the `what` of
// ros_messages.h).
std::string Describe(const BagMessage& message);

class BagReader {
 public:
  // Throws InputError when the bag, its metadata.yaml or any of its files is missing or bad.
  explicit BagReader(const std::string& path);
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  // metadata.yaml as written by the recorder; nullptr when a single file was opened.
  const BagMetadata* metadata() const { return metadata_.get(); }
  // "sqlite3" or "mcap".
  const std::string& storage_identifier() const { return storage_identifier_; }
  // The storage files, resolved, in split order.
  const std::vector<std::string>& files() const { return files_; }
  // Every topic of every file (first appearance order), message counts summed over the files.
  const std::vector<TopicInfo>& topics() const { return topics_; }
  const TopicInfo* FindTopic(const std::string& name) const;
  std::uint64_t message_count() const;
  // First and last message time over all files (0 for a bag without messages).
  std::int64_t start_time_ns() const { return start_ns_; }
  std::int64_t end_time_ns() const { return end_ns_; }

  // The next message by time (ties: earlier file first, then file order); false at the end.
  bool ReadNext(BagMessage* message);

  // The first step back of the recording clock by more than kClockStepBackToleranceNs in the
  // order the recorder wrote each topic's messages (file by file, and from one split file to
  // the next), with the file it is in. Reads the bag once more.
  std::optional<ClockStepBack> RecordingClockStepBack(std::string* file);

 private:
  void OpenFromMetadata(const std::string& metadata_path);
  void OpenStorages();
  void MergeTopics(std::size_t file_index);
  bool Advance(std::size_t file_index);

  std::unique_ptr<BagMetadata> metadata_;
  std::string storage_identifier_;
  std::vector<std::string> files_;
  std::vector<std::unique_ptr<StorageReader>> storages_;
  std::vector<std::vector<std::size_t>> topic_map_;  // [file][storage topic] -> topics_ index
  std::vector<TopicInfo> topics_;
  std::int64_t start_ns_ = 0;
  std::int64_t end_ns_ = 0;
  // The merge: each file's next message, and the file whose message was returned last.
  std::vector<StoredMessage> pending_;
  std::vector<bool> has_pending_;
  std::size_t last_file_ = 0;
  bool started_ = false;
};

}  // namespace fitcal::io::rosbag2
