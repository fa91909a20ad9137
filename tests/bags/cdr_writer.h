#pragma once
// Writing one CDR-serialized message, the mirror of CdrReader (same layout: 4-byte encapsulation
// header, alignment from the byte after it, NUL-terminated strings, uint32-counted sequences),
// through libfastcdr's Cdr with a growing FastBuffer. Used by the bag writer's tests and tools.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace fitcal::io::rosbag2 {

class CdrWriter {
 public:
  // Little-endian (CDR_LE, what every x86/ARM ROS 2 machine writes) unless `big_endian`.
  explicit CdrWriter(bool big_endian = false);
  ~CdrWriter();
  CdrWriter(const CdrWriter&) = delete;
  CdrWriter& operator=(const CdrWriter&) = delete;

  void Bool(bool value);
  void Uint8(std::uint8_t value);
  void Int32(std::int32_t value);
  void Uint32(std::uint32_t value);
  void Float64(double value);
  void String(const std::string& value);
  void Array(const double* values, std::size_t count);    // float64[N]
  void Sequence(const std::vector<double>& values);       // float64[]
  void Sequence(const std::vector<std::string>& values);  // string[]

  // The serialized message, header included.
  std::vector<std::uint8_t> Bytes() const;

 private:
  struct Impl;
  void Align(std::size_t size);
  std::unique_ptr<Impl> impl_;
};

}  // namespace fitcal::io::rosbag2
