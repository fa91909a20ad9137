#pragma once
// What the bag writer needs of a storage file: topics, then messages, then Close. Topic i gets
// the storage id i + 1 (sqlite3 topics.id, MCAP Schema and Channel ids).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/rosbag2/bytes.h"
#include "io/rosbag2/compression.h"
#include "io/rosbag2/storage.h"

namespace fitcal::io::rosbag2 {

// Appends `value` as sizeof(T) little-endian bytes.
template <typename T>
void AppendLe(std::vector<std::uint8_t>* out, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out->push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * i)));
  }
}

inline void AppendBytes(std::vector<std::uint8_t>* out, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

class StorageWriter {
 public:
  virtual ~StorageWriter() = default;
  virtual void AddTopic(std::size_t topic_index, const TopicInfo& topic) = 0;
  virtual void Write(std::size_t topic_index, std::int64_t time_ns, ByteView payload) = 0;
  // Finishes the file; throws std::runtime_error when it cannot be written.
  virtual void Close() = 0;
};

// sqlite3_writer.cc: the schema version 4 layout of rosbag2 (see io/rosbag2/sqlite3_storage.cc).
std::unique_ptr<StorageWriter> CreateSqlite3Writer(const std::string& path);

struct McapWriterOptions {
  Compression compression = Compression::kNone;
  std::size_t chunk_bytes = 1 << 20;  // a chunk is closed once its records reach this size
  bool crcs = true;                   // chunk, data section and summary CRCs (0 when off)
  bool summary = true;                // Summary and Summary Offset sections
  bool chunked = true;                // false: Schema, Channel, Message records outside chunks
};

// mcap_writer.cc: chunks with Message Index records after each, Data End, optional summary.
std::unique_ptr<StorageWriter> CreateMcapWriter(const std::string& path,
                                                const McapWriterOptions& options);

}  // namespace fitcal::io::rosbag2
