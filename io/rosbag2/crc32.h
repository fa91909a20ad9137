#pragma once
// CRC-32 as MCAP uses it for chunk, data-section and summary checksums (MCAP spec, "Chunk",
// "Data End", "Footer"): the ISO-HDLC / zlib CRC, reflected polynomial 0xEDB88320, initial value
// and final xor 0xFFFFFFFF. Computed eight bytes per step ("slicing by 8") so that checking a
// chunk costs far less than reading it.

#include <cstddef>
#include <cstdint>

namespace fitcal::io::rosbag2 {

class Crc32 {
 public:
  void Update(const std::uint8_t* data, std::size_t size);
  std::uint32_t value() const { return state_ ^ 0xFFFFFFFFu; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

// CRC-32 of one buffer.
std::uint32_t ComputeCrc32(const std::uint8_t* data, std::size_t size);

}  // namespace fitcal::io::rosbag2
