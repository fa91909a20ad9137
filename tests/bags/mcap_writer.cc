// An MCAP writer (mcap.dev/spec) laid out as rosbag2's MCAP plugin does: Schema and Channel
// records inside the first chunk that needs them, Message Index records after every chunk, Data
// End, then (optionally) a summary with Schemas, Channels, Statistics and Chunk Indexes, the
// Summary Offsets and the Footer.

#include <lz4frame.h>
#include <zstd.h>

#include <cstdio>
#include <map>
#include <stdexcept>

#include "io/rosbag2/crc32.h"
#include "io/rosbag2/mcap_format.h"
#include "tests/bags/storage_writer.h"

namespace fitcal::io::rosbag2 {
namespace {

using mcap::Opcode;
using Bytes = std::vector<std::uint8_t>;

void AppendString(Bytes* out, const std::string& text) {
  AppendLe(out, static_cast<std::uint32_t>(text.size()));
  AppendBytes(out, text.data(), text.size());
}

// zstd at level 1 (fast, as rosbag2's default preset favours write speed); lz4 as one LZ4 frame
// with the content size recorded.
std::vector<std::uint8_t> Compress(Compression compression, ByteView input) {
  std::vector<std::uint8_t> out;
  if (compression == Compression::kNone) return {input.data, input.data + input.size};
  if (compression == Compression::kZstd) {
    out.resize(ZSTD_compressBound(input.size));
    const std::size_t n = ZSTD_compress(out.data(), out.size(), input.data, input.size, 1);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
  }
  LZ4F_preferences_t prefs{};
  prefs.frameInfo.contentSize = input.size;
  out.resize(LZ4F_compressFrameBound(input.size, &prefs));
  const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), input.data, input.size, &prefs);
  if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
  out.resize(n);
  return out;
}

// <opcode><uint64 length><content> (spec "Records").
void AppendRecord(Bytes* out, Opcode opcode, const Bytes& content) {
  out->push_back(static_cast<std::uint8_t>(opcode));
  AppendLe(out, static_cast<std::uint64_t>(content.size()));
  AppendBytes(out, content.data(), content.size());
}

// Spec "Schema": rosbag2 names the schema after the type; the definition text is left empty
// (our reader does not need it; tools that do can take it from the type name).
Bytes SchemaContent(std::uint16_t id, const TopicInfo& topic) {
  Bytes c;
  AppendLe(&c, id);
  AppendString(&c, topic.type);
  AppendString(&c, "ros2msg");
  AppendLe(&c, std::uint32_t{0});
  return c;
}

// Spec "Channel": schema and channel share the id; metadata as rosbag2 writes it (empty QoS).
Bytes ChannelContent(std::uint16_t id, const TopicInfo& topic) {
  Bytes metadata;
  AppendString(&metadata, "offered_qos_profiles");
  AppendString(&metadata, "");
  Bytes c;
  AppendLe(&c, id);
  AppendLe(&c, id);
  AppendString(&c, topic.name);
  AppendString(&c, topic.serialization_format);
  AppendLe(&c, static_cast<std::uint32_t>(metadata.size()));
  AppendBytes(&c, metadata.data(), metadata.size());
  return c;
}

struct ChunkIndexEntry {
  std::uint64_t start_ns, end_ns, offset, length, index_length, compressed, uncompressed;
  std::map<std::uint16_t, std::uint64_t> index_offsets;
};

class McapWriter : public StorageWriter {
 public:
  McapWriter(const std::string& path, const McapWriterOptions& options)
      : path_(path), options_(options), file_(std::fopen(path.c_str(), "wb")) {
    if (file_ == nullptr) throw std::runtime_error(path + ": cannot create the MCAP file");
    Emit(mcap::kMagic, mcap::kMagicBytes);
    Bytes header;
    AppendString(&header, "ros2");
    AppendString(&header, "fitcal rosbag2 writer");
    EmitRecord(Opcode::kHeader, header);
  }
  ~McapWriter() override {
    if (file_ != nullptr) std::fclose(file_);
  }

  void AddTopic(std::size_t topic_index, const TopicInfo& topic) override;
  void Write(std::size_t topic_index, std::int64_t time_ns, ByteView payload) override;
  void Close() override;

 private:
  void Emit(const void* data, std::size_t size);
  void EmitRecord(Opcode opcode, const Bytes& content);
  void FlushChunk();
  void ResetChunk();
  void WriteMessageIndexes(ChunkIndexEntry* entry);
  void WriteSummary();
  void WriteFooter(std::uint64_t summary_start, std::uint64_t summary_offset_start);

  std::string path_;
  McapWriterOptions options_;
  std::FILE* file_;
  std::uint64_t offset_ = 0;
  Crc32 crc_;  // data section, then summary
  std::vector<std::pair<std::uint16_t, TopicInfo>> topics_;
  std::map<std::uint16_t, std::uint32_t> sequence_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  // The open chunk: its records, time range and per-channel (log_time, offset) index.
  Bytes chunk_;
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0, chunk_message_count_ = 0;
  std::map<std::uint16_t, Bytes> chunk_index_;
  std::vector<ChunkIndexEntry> chunk_indexes_;
  std::uint64_t message_count_ = 0, start_ns_ = 0, end_ns_ = 0;
};

void McapWriter::Emit(const void* data, std::size_t size) {
  if (std::fwrite(data, 1, size, file_) != size) {
    throw std::runtime_error(path_ + ": write failed");
  }
  crc_.Update(static_cast<const std::uint8_t*>(data), size);
  offset_ += size;
}

void McapWriter::EmitRecord(Opcode opcode, const Bytes& content) {
  Bytes record;
  AppendRecord(&record, opcode, content);
  Emit(record.data(), record.size());
}

void McapWriter::AddTopic(std::size_t topic_index, const TopicInfo& topic) {
  const auto id = static_cast<std::uint16_t>(topic_index + 1);
  topics_.emplace_back(id, topic);
  AppendRecord(&chunk_, Opcode::kSchema, SchemaContent(id, topic));
  AppendRecord(&chunk_, Opcode::kChannel, ChannelContent(id, topic));
}

void McapWriter::Write(std::size_t topic_index, std::int64_t time_ns, ByteView payload) {
  const auto id = static_cast<std::uint16_t>(topic_index + 1);
  const auto log_time = static_cast<std::uint64_t>(time_ns);
  Bytes& index = chunk_index_[id];
  AppendLe(&index, log_time);
  AppendLe(&index, static_cast<std::uint64_t>(chunk_.size()));
  // Spec "Message": channel_id, sequence, log_time, publish_time (= log_time here), data.
  chunk_.push_back(static_cast<std::uint8_t>(Opcode::kMessage));
  AppendLe(&chunk_, static_cast<std::uint64_t>(mcap::kMessageHeaderBytes + payload.size));
  AppendLe(&chunk_, id);
  AppendLe(&chunk_, sequence_[id]++);
  AppendLe(&chunk_, log_time);
  AppendLe(&chunk_, log_time);
  AppendBytes(&chunk_, payload.data, payload.size);
  const bool first_in_chunk = chunk_message_count_++ == 0;
  chunk_start_ns_ = first_in_chunk ? log_time : std::min(chunk_start_ns_, log_time);
  chunk_end_ns_ = first_in_chunk ? log_time : std::max(chunk_end_ns_, log_time);
  start_ns_ = message_count_ == 0 ? log_time : std::min(start_ns_, log_time);
  end_ns_ = message_count_ == 0 ? log_time : std::max(end_ns_, log_time);
  ++message_count_;
  ++channel_counts_[id];
  if (chunk_.size() >= options_.chunk_bytes) FlushChunk();
}

// Spec "Chunk": start/end time, uncompressed size and CRC, compression, records.
void McapWriter::FlushChunk() {
  if (chunk_.empty()) return;
  if (!options_.chunked) {  // the same records, straight into the data section
    Emit(chunk_.data(), chunk_.size());
    ResetChunk();
    return;
  }
  const Bytes stored = Compress(options_.compression, ByteView(chunk_));
  Bytes content;
  AppendLe(&content, chunk_index_.empty() ? std::uint64_t{0} : chunk_start_ns_);
  AppendLe(&content, chunk_index_.empty() ? std::uint64_t{0} : chunk_end_ns_);
  AppendLe(&content, static_cast<std::uint64_t>(chunk_.size()));
  AppendLe(&content, options_.crcs ? ComputeCrc32(chunk_.data(), chunk_.size()) : 0u);
  AppendString(&content, CompressionName(options_.compression));
  AppendLe(&content, static_cast<std::uint64_t>(stored.size()));
  AppendBytes(&content, stored.data(), stored.size());
  ChunkIndexEntry entry{chunk_index_.empty() ? 0 : chunk_start_ns_,
                        chunk_index_.empty() ? 0 : chunk_end_ns_,
                        offset_,
                        mcap::kRecordPrefixBytes + content.size(),
                        0,
                        stored.size(),
                        chunk_.size(),
                        {}};
  EmitRecord(Opcode::kChunk, content);
  WriteMessageIndexes(&entry);
  chunk_indexes_.push_back(std::move(entry));
  ResetChunk();
}

void McapWriter::ResetChunk() {
  chunk_.clear();
  chunk_index_.clear();
  chunk_message_count_ = 0;
}

// Spec "Message Index": channel_id, Array<Tuple<log_time, offset>>; one per channel, after the
// chunk.
void McapWriter::WriteMessageIndexes(ChunkIndexEntry* entry) {
  const std::uint64_t start = offset_;
  for (const auto& [id, index] : chunk_index_) {
    Bytes content;
    AppendLe(&content, id);
    AppendLe(&content, static_cast<std::uint32_t>(index.size()));
    AppendBytes(&content, index.data(), index.size());
    entry->index_offsets[id] = offset_;
    EmitRecord(Opcode::kMessageIndex, content);
  }
  entry->index_length = offset_ - start;
}

void McapWriter::Close() {
  if (file_ == nullptr) return;
  FlushChunk();
  Bytes data_end;
  AppendLe(&data_end, options_.crcs ? crc_.value() : 0u);
  EmitRecord(Opcode::kDataEnd, data_end);
  crc_ = Crc32();  // the summary CRC starts after Data End (spec "Footer")
  WriteSummary();
  Emit(mcap::kMagic, mcap::kMagicBytes);
  if (std::fclose(file_) != 0) {
    file_ = nullptr;
    throw std::runtime_error(path_ + ": write failed");
  }
  file_ = nullptr;
}

// Spec "Statistics".
Bytes StatisticsContent(std::uint64_t message_count, std::size_t topic_count,
                        std::size_t chunk_count, std::uint64_t start_ns, std::uint64_t end_ns,
                        const std::map<std::uint16_t, std::uint64_t>& channel_counts) {
  Bytes c;
  AppendLe(&c, message_count);
  AppendLe(&c, static_cast<std::uint16_t>(topic_count));  // schema_count
  AppendLe(&c, static_cast<std::uint32_t>(topic_count));  // channel_count
  AppendLe(&c, std::uint32_t{0});                         // attachment_count
  AppendLe(&c, std::uint32_t{0});                         // metadata_count
  AppendLe(&c, static_cast<std::uint32_t>(chunk_count));
  AppendLe(&c, start_ns);
  AppendLe(&c, end_ns);
  AppendLe(&c, static_cast<std::uint32_t>(channel_counts.size() * 10));
  for (const auto& [id, count] : channel_counts) {
    AppendLe(&c, id);
    AppendLe(&c, count);
  }
  return c;
}

// Spec "Chunk Index".
Bytes ChunkIndexContent(const ChunkIndexEntry& e, Compression compression) {
  Bytes c;
  AppendLe(&c, e.start_ns);
  AppendLe(&c, e.end_ns);
  AppendLe(&c, e.offset);
  AppendLe(&c, e.length);
  AppendLe(&c, static_cast<std::uint32_t>(e.index_offsets.size() * 10));
  for (const auto& [id, offset] : e.index_offsets) {
    AppendLe(&c, id);
    AppendLe(&c, offset);
  }
  AppendLe(&c, e.index_length);
  AppendString(&c, CompressionName(compression));
  AppendLe(&c, e.compressed);
  AppendLe(&c, e.uncompressed);
  return c;
}

}  // namespace

// Summary section grouped by opcode (spec "Summary Section"), then one Summary Offset per group.
void McapWriter::WriteSummary() {
  if (!options_.summary) {
    WriteFooter(0, 0);
    return;
  }
  const std::uint64_t summary_start = offset_;
  std::vector<std::pair<Opcode, std::pair<std::uint64_t, std::uint64_t>>> groups;
  const auto group = [&](Opcode opcode, const std::vector<Bytes>& contents) {
    const std::uint64_t start = offset_;
    for (const Bytes& content : contents) EmitRecord(opcode, content);
    if (!contents.empty()) groups.push_back({opcode, {start, offset_ - start}});
  };
  std::vector<Bytes> schemas, channels, chunk_indexes;
  for (const auto& [id, topic] : topics_) {
    schemas.push_back(SchemaContent(id, topic));
    channels.push_back(ChannelContent(id, topic));
  }
  for (const ChunkIndexEntry& e : chunk_indexes_) {
    chunk_indexes.push_back(ChunkIndexContent(e, options_.compression));
  }
  group(Opcode::kSchema, schemas);
  group(Opcode::kChannel, channels);
  group(Opcode::kStatistics,
        {StatisticsContent(message_count_, topics_.size(), chunk_indexes_.size(), start_ns_,
                           end_ns_, channel_counts_)});
  group(Opcode::kChunkIndex, chunk_indexes);
  const std::uint64_t summary_offset_start = offset_;
  for (const auto& [opcode, range] : groups) {
    Bytes c;
    c.push_back(static_cast<std::uint8_t>(opcode));
    AppendLe(&c, range.first);
    AppendLe(&c, range.second);
    EmitRecord(Opcode::kSummaryOffset, c);
  }
  WriteFooter(summary_start, summary_offset_start);
}

// Spec "Footer": summary_crc covers the summary sections and the footer up to that field.
void McapWriter::WriteFooter(std::uint64_t summary_start, std::uint64_t summary_offset_start) {
  Bytes record;
  record.push_back(static_cast<std::uint8_t>(Opcode::kFooter));
  AppendLe(&record, static_cast<std::uint64_t>(mcap::kFooterBytes));
  AppendLe(&record, summary_start);
  AppendLe(&record, summary_offset_start);
  Crc32 crc = crc_;
  crc.Update(record.data(), record.size());
  AppendLe(&record, options_.crcs ? crc.value() : 0u);
  Emit(record.data(), record.size());
}

std::unique_ptr<StorageWriter> CreateMcapWriter(const std::string& path,
                                                const McapWriterOptions& options) {
  return std::make_unique<McapWriter>(path, options);
}

}  // namespace fitcal::io::rosbag2
