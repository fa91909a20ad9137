#include "io/rosbag2/crc32.h"

#include <array>

namespace fitcal::io::rosbag2 {
namespace {

constexpr std::uint32_t kReflectedPolynomial = 0xEDB88320u;

// table[0] is the classic byte-at-a-time table; table[k][b] is the CRC of byte b followed by k
// zero bytes, which lets eight input bytes be folded in with eight independent lookups.
using SliceTables = std::array<std::array<std::uint32_t, 256>, 8>;

SliceTables MakeTables() {
  SliceTables table{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t crc = b;
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ ((crc & 1u) ? kReflectedPolynomial : 0u);
    table[0][b] = crc;
  }
  for (std::size_t k = 1; k < 8; ++k) {
    for (std::uint32_t b = 0; b < 256; ++b) {
      const std::uint32_t prev = table[k - 1][b];
      table[k][b] = (prev >> 8) ^ table[0][prev & 0xFFu];
    }
  }
  return table;
}

const SliceTables& Tables() {
  static const SliceTables tables = MakeTables();
  return tables;
}

std::uint32_t Load32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

}  // namespace

void Crc32::Update(const std::uint8_t* data, std::size_t size) {
  const SliceTables& t = Tables();
  std::uint32_t crc = state_;
  while (size >= 8) {
    const std::uint32_t lo = Load32(data) ^ crc;
    const std::uint32_t hi = Load32(data + 4);
    crc = t[7][lo & 0xFFu] ^ t[6][(lo >> 8) & 0xFFu] ^ t[5][(lo >> 16) & 0xFFu] ^ t[4][lo >> 24] ^
          t[3][hi & 0xFFu] ^ t[2][(hi >> 8) & 0xFFu] ^ t[1][(hi >> 16) & 0xFFu] ^ t[0][hi >> 24];
    data += 8;
    size -= 8;
  }
  while (size-- > 0) crc = (crc >> 8) ^ t[0][(crc ^ *data++) & 0xFFu];
  state_ = crc;
}

std::uint32_t ComputeCrc32(const std::uint8_t* data, std::size_t size) {
  Crc32 crc;
  crc.Update(data, size);
  return crc.value();
}

}  // namespace fitcal::io::rosbag2
