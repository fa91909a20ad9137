#pragma once
// Writing a rosbag2 bag (a directory with metadata.yaml and one or more storage files) that
// BagReader and ROS 2's own rosbag2 can read: sqlite3 or MCAP, MCAP chunks optionally zstd or lz4
// compressed, optionally split into several files after a number of messages. For tests and for
// tools that turn fitcal's data into bags.
//
//   rosbag2::BagWriter bag("out/run_1", {rosbag2::StorageFormat::kMcap});
//   bag.AddTopic("/joint_states", "sensor_msgs/msg/JointState");
//   bag.Write("/joint_states", t_ns, ByteView(EncodeJointState(js)));
//   bag.Close();

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "io/rosbag2/bag_metadata.h"
#include "tests/bags/storage_writer.h"

namespace fitcal::io::rosbag2 {

enum class StorageFormat { kSqlite3, kMcap };

struct BagWriterOptions {
  StorageFormat storage = StorageFormat::kMcap;
  McapWriterOptions mcap;                  // MCAP only: chunk compression, size, CRCs, summary
  std::uint64_t split_after_messages = 0;  // 0: one file; n: a new file after every n messages
};

class BagWriter {
 public:
  // Creates `directory` (and parents); files are named <directory name>_<i>.db3 / .mcap, as
  // rosbag2 names them. Throws std::runtime_error when it cannot write.
  explicit BagWriter(const std::string& directory, BagWriterOptions options = {});
  ~BagWriter();  // closes if Close was not called (errors then are swallowed)
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  void AddTopic(const std::string& name, const std::string& type,
                const std::string& serialization_format = "cdr");
  // Throws std::invalid_argument for a topic not added.
  void Write(const std::string& topic, std::int64_t time_ns, ByteView payload);
  // Finishes the last file and writes metadata.yaml.
  void Close();

  const std::vector<std::string>& files() const { return paths_; }

 private:
  void OpenNextFile();
  void CloseCurrentFile();

  std::string directory_;
  BagWriterOptions options_;
  std::vector<TopicInfo> topics_;
  std::map<std::string, std::size_t> topic_index_;
  std::unique_ptr<StorageWriter> current_;
  std::vector<std::string> paths_;
  BagMetadata metadata_;
  BagFileInfo file_;  // the open file's statistics
  std::int64_t file_end_ns_ = 0;
  bool closed_ = false;
};

}  // namespace fitcal::io::rosbag2
