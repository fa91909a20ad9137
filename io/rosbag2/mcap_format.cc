#include "io/rosbag2/mcap_format.h"

#include <array>

namespace fitcal::io::rosbag2::mcap {

std::string OpcodeName(std::uint8_t opcode) {
  static constexpr std::array<const char*, 16> kNames = {
      "opcode 0x00", "Header",        "Footer",          "Schema",
      "Channel",     "Message",       "Chunk",           "MessageIndex",
      "ChunkIndex",  "Attachment",    "AttachmentIndex", "Statistics",
      "Metadata",    "MetadataIndex", "SummaryOffset",   "DataEnd"};
  if (opcode < kNames.size()) return kNames[opcode];
  static constexpr char kHex[] = "0123456789abcdef";
  return std::string("opcode 0x") + kHex[opcode >> 4] + kHex[opcode & 0xF];
}

void FieldReader::Fail(std::uint64_t wanted) const {
  ThrowBagError(InputErrorKind::kBadValue, file_,
                AtByte(record_offset_) + record_name_ + " record is malformed: a field of " +
                    std::to_string(wanted) + " bytes at offset " + std::to_string(pos_) +
                    " runs past the record's " + std::to_string(content_.size) + " bytes");
}

}  // namespace fitcal::io::rosbag2::mcap
