#pragma once
// The MCAP container format, version 0 (mcap.dev/spec): magic, record opcodes and a bounds-checked
// reader of record fields. Shared by the reader (mcap_storage.cc) and the tests' writer
// (tests/bags/mcap_writer.cc).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "io/rosbag2/bytes.h"
#include "io/rosbag2/errors.h"

namespace fitcal::io::rosbag2::mcap {

// Spec "Magic": 0x89 'M' 'C' 'A' 'P' '0' '\r' '\n' at the start and the end of the file.
constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::size_t kMagicBytes = sizeof(kMagic);
// Spec "Records": <opcode uint8><content length uint64><content>.
constexpr std::size_t kRecordPrefixBytes = 9;
// Spec "Footer": summary_start u64, summary_offset_start u64, summary_crc u32.
constexpr std::size_t kFooterBytes = 20;
// Spec "Message": channel_id u16, sequence u32, log_time u64, publish_time u64, then data.
constexpr std::size_t kMessageHeaderBytes = 22;

enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Name of an opcode for messages ("Chunk", "opcode 0x91").
std::string OpcodeName(std::uint8_t opcode);

// Reads the fields of one record's content in order. Every read checks the bytes left, so a
// length field larger than the record is an InputError naming the file, the record and its offset.
class FieldReader {
 public:
  FieldReader(ByteView content, const std::string& file, std::uint64_t record_offset,
              const char* record_name)
      : content_(content), file_(file), record_offset_(record_offset), record_name_(record_name) {}

  std::uint16_t U16() { return LoadLe<std::uint16_t>(Take(2)); }
  std::uint32_t U32() { return LoadLe<std::uint32_t>(Take(4)); }
  std::uint64_t U64() { return LoadLe<std::uint64_t>(Take(8)); }
  // Spec "String": uint32 byte length, then the bytes.
  std::string_view String() {
    const std::uint32_t n = U32();
    return {reinterpret_cast<const char*>(Take(n)), n};
  }
  // Spec "Bytes" with a uint32 or uint64 length prefix (Schema data, Chunk records).
  ByteView Bytes32() {
    const std::uint32_t n = U32();
    return {Take(n), n};
  }
  ByteView Bytes64() {
    const std::uint64_t n = U64();
    return {Take(n), static_cast<std::size_t>(n)};
  }
  // Spec "Map" / "Array": a uint32 byte length, then the entries; skipped as one block.
  void SkipLengthPrefixed() { Take(U32()); }
  ByteView Rest() {
    const std::size_t n = content_.size - pos_;
    return {Take(n), n};
  }
  std::size_t position() const { return pos_; }

 private:
  const std::uint8_t* Take(std::uint64_t n) {
    if (n > content_.size - pos_) Fail(n);
    const std::uint8_t* p = content_.data + pos_;
    pos_ += static_cast<std::size_t>(n);
    return p;
  }
  [[noreturn]] void Fail(std::uint64_t wanted) const;

  ByteView content_;
  std::size_t pos_ = 0;
  const std::string& file_;
  std::uint64_t record_offset_;
  const char* record_name_;
};

}  // namespace fitcal::io::rosbag2::mcap
