#pragma once
// metadata.yaml, the file rosbag2 writes beside a bag's storage files: which storage plugin, which
// files (in split order), when the recording started, how long it lasted, and the topics with
// their message counts. Read for any version 1-9 that rosbag2 has written (the keys read here
// are common to all of them).

#include <cstdint>
#include <string>
#include <vector>

#include "io/rosbag2/storage.h"

namespace fitcal::io::rosbag2 {

struct BagFileInfo {  // one entry of `files` (version 5 and later)
  std::string path;   // relative to the bag directory
  std::int64_t starting_time_ns = 0;
  std::int64_t duration_ns = 0;
  std::uint64_t message_count = 0;
};

struct BagMetadata {
  int version = 0;
  std::string storage_identifier;                // "sqlite3" or "mcap"
  std::vector<std::string> relative_file_paths;  // in recording order
  std::vector<BagFileInfo> files;                // empty before version 5
  std::int64_t starting_time_ns = 0;             // starting_time.nanoseconds_since_epoch
  std::int64_t duration_ns = 0;                  // duration.nanoseconds
  std::uint64_t message_count = 0;
  std::vector<TopicInfo> topics;   // topics_with_message_count, in the file's order
  std::string compression_format;  // "" or "zstd" (rosbag2 file/message compression)
  std::string compression_mode;    // "", "FILE" or "MESSAGE"
};

// Reads `path` (a metadata.yaml). Throws InputError (kMissingFile, kYamlSyntax, kMissingKey,
// kWrongYamlType, kBadValue) with the file and line.
BagMetadata ReadBagMetadata(const std::string& path);

// The bag a storage file given alone belongs to: the directory whose metadata.yaml lists it, and
// how many files that lists (0 when no metadata.yaml beside it reads or lists this file).
struct OwningBag {
  std::string directory;
  std::size_t files = 0;
};
OwningBag OwningBagOfFile(const std::string& file);

}  // namespace fitcal::io::rosbag2
