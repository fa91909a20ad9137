#pragma once
// A read-only view of bytes, and little-endian loads/stores for the binary formats (MCAP
// serializes every fixed-width integer little-endian: MCAP spec, "Serialization").

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
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
  std::vector<std::uint8_t> ToVector() const { return {data, data + size}; }
};

// Loads an unsigned integer of sizeof(T) bytes stored little-endian at `p`.
template <typename T>
T LoadLe(const std::uint8_t* p) {
  T value = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) value |= static_cast<T>(p[i]) << (8 * i);
  return value;
}

// Appends `value` as sizeof(T) little-endian bytes.
template <typename T>
void AppendLe(std::vector<std::uint8_t>* out, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out->push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * i)));
  }
}

// Overwrites sizeof(T) bytes at `offset` of `out` with `value`, little-endian.
template <typename T>
void StoreLe(std::vector<std::uint8_t>* out, std::size_t offset, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    (*out)[offset + i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * i));
  }
}

inline void AppendBytes(std::vector<std::uint8_t>* out, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace fitcal::io::rosbag2
