#pragma once
// A read-only view of bytes, and little-endian loads for the binary formats (MCAP
// serializes every fixed-width integer little-endian: MCAP spec, "Serialization").

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fitcal::io::rosbag2 {

// Bytes owned by someone else (C++17 has no std::span).
struct ByteView {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;

  ByteView() = default;
  ByteView(const std::uint8_t* bytes, std::size_t count) : data(bytes), size(count) {}
  explicit ByteView(const std::vector<std::uint8_t>& bytes)
      : data(bytes.data()), size(bytes.size()) {}

  ByteView Sub(std::size_t offset, std::size_t count) const { return {data + offset, count}; }
};

// Loads an unsigned integer of sizeof(T) bytes stored little-endian at `p`.
template <typename T>
T LoadLe(const std::uint8_t* p) {
  T value = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) value |= static_cast<T>(p[i]) << (8 * i);
  return value;
}

}  // namespace fitcal::io::rosbag2
