#include "tests/bags/cdr_writer.h"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

namespace fitcal::io::rosbag2 {

namespace fcdr = eprosima::fastcdr;

struct CdrWriter::Impl {
  explicit Impl(bool big_endian)
      : cdr(buffer, big_endian ? fcdr::Cdr::BIG_ENDIANNESS : fcdr::Cdr::LITTLE_ENDIANNESS,
            fcdr::Cdr::DDS_CDR) {}
  fcdr::FastBuffer buffer;  // grows as needed
  fcdr::Cdr cdr;
};

CdrWriter::CdrWriter(bool big_endian) : impl_(std::make_unique<Impl>(big_endian)) {
  // 0x00 0x00|0x01, options 0x0000; alignment restarts after it.
  impl_->cdr.serialize_encapsulation();
}

CdrWriter::~CdrWriter() = default;

// fastcdr leaves alignment padding uninitialized (its buffer grows with realloc); writing the
// padding as explicit zero octets first keeps the output deterministic. Alignment counts from
// the byte after the 4-byte encapsulation header, as fastcdr's own does.
void CdrWriter::Align(std::size_t size) {
  const std::size_t position = impl_->cdr.getSerializedDataLength() - 4;
  const std::size_t padding = (size - position % size) % size;
  for (std::size_t i = 0; i < padding; ++i) impl_->cdr.serialize(std::uint8_t{0});
}

void CdrWriter::Bool(bool value) { impl_->cdr.serialize(value); }
void CdrWriter::Uint8(std::uint8_t value) { impl_->cdr.serialize(value); }
void CdrWriter::Int32(std::int32_t value) {
  Align(4);
  impl_->cdr.serialize(value);
}
void CdrWriter::Uint32(std::uint32_t value) {
  Align(4);
  impl_->cdr.serialize(value);
}
void CdrWriter::Float64(double value) {
  Align(8);
  impl_->cdr.serialize(value);
}
// The length including the NUL, then the bytes and the NUL, as ROS 2 does.
void CdrWriter::String(const std::string& value) {
  Uint32(static_cast<std::uint32_t>(value.size() + 1));
  impl_->cdr.serializeArray(value.c_str(), value.size() + 1);
}

void CdrWriter::Array(const double* values, std::size_t count) {
  if (count == 0) return;
  Align(8);
  impl_->cdr.serializeArray(values, count);
}

void CdrWriter::Sequence(const std::vector<double>& values) {
  Uint32(static_cast<std::uint32_t>(values.size()));
  Array(values.data(), values.size());
}

void CdrWriter::Sequence(const std::vector<std::string>& values) {
  Uint32(static_cast<std::uint32_t>(values.size()));
  for (const std::string& value : values) String(value);
}

std::vector<std::uint8_t> CdrWriter::Bytes() const {
  const auto* begin = reinterpret_cast<const std::uint8_t*>(impl_->buffer.getBuffer());
  return std::vector<std::uint8_t>(begin, begin + impl_->cdr.getSerializedDataLength());
}

}  // namespace fitcal::io::rosbag2
