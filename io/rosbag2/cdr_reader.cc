#include "io/rosbag2/cdr_reader.h"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>

#include "io/rosbag2/errors.h"

namespace fitcal::io::rosbag2 {

namespace fcdr = eprosima::fastcdr;

// Encapsulation header (DDS-XTYPES 1.3, 7.6.3.1.2 / RTPS 2.5, 10.2): identifier CDR_BE = 0x0000,
// CDR_LE = 0x0001, then a 16-bit options field.
constexpr std::size_t kEncapsulationBytes = 4;

struct CdrReader::Impl {
  // FastBuffer takes a char* even for reading; deserialization never writes through it.
  explicit Impl(ByteView payload)
      : buffer(reinterpret_cast<char*>(const_cast<std::uint8_t*>(payload.data)), payload.size),
        cdr(buffer, fcdr::Cdr::DEFAULT_ENDIAN, fcdr::Cdr::DDS_CDR) {}
  fcdr::FastBuffer buffer;
  fcdr::Cdr cdr;
};

CdrReader::CdrReader(ByteView payload, std::string what)
    : what_(std::move(what)), size_(payload.size) {
  if (payload.size < kEncapsulationBytes) {
    Fail("payload of " + std::to_string(payload.size) +
         " bytes is shorter than the 4-byte CDR header");
  }
  if (payload.data[0] != 0x00 || payload.data[1] > 0x01) {
    Fail("unsupported CDR encapsulation " + std::to_string(payload.data[0]) + "," +
         std::to_string(payload.data[1]) + " (only plain CDR big/little endian)");
  }
  impl_ = std::make_unique<Impl>(payload);
  // Reads the header, switches endianness and restarts alignment after it.
  impl_->cdr.read_encapsulation();
}

CdrReader::~CdrReader() = default;

std::size_t CdrReader::remaining() const { return size_ - impl_->cdr.getSerializedDataLength(); }

void CdrReader::Fail(const std::string& why) const {
  ThrowBagError(InputErrorKind::kBadValue, what_, why);
}

template <typename T>
T CdrReader::Read() {
  T value{};
  const std::size_t at = impl_->cdr.getSerializedDataLength();
  try {
    impl_->cdr.deserialize(value);
  } catch (const fcdr::exception::Exception& e) {
    Fail("payload shorter than its fields: a " + std::to_string(sizeof(T)) +
         "-byte field at byte " + std::to_string(at) + " of " + std::to_string(size_) + " (" +
         e.what() + ")");
  }
  return value;
}

template <typename T>
void CdrReader::Array(T* out, std::size_t count) {
  const std::size_t at = impl_->cdr.getSerializedDataLength();
  try {
    impl_->cdr.deserializeArray(out, count);
  } catch (const fcdr::exception::Exception& e) {
    Fail("payload shorter than its fields: " + std::to_string(count) + " elements of " +
         std::to_string(sizeof(T)) + " bytes at byte " + std::to_string(at) + " of " +
         std::to_string(size_) + " (" + e.what() + ")");
  }
}

// A string: uint32 length counting the terminating NUL, the bytes, the NUL. A length of 0 (no
// NUL at all) is accepted as "", as some serializers write it for the empty string.
std::string CdrReader::String() {
  const std::uint32_t length = Read<std::uint32_t>();
  if (length == 0) return std::string();
  const std::size_t at = impl_->cdr.getSerializedDataLength();
  if (length > remaining()) {
    Fail("string length " + std::to_string(length) + " at byte " + std::to_string(at) +
         " exceeds the " + std::to_string(remaining()) + " bytes left in the payload");
  }
  const char* text = impl_->cdr.getCurrentPosition();
  if (text[length - 1] != '\0') {
    Fail("string of " + std::to_string(length) + " bytes at byte " + std::to_string(at) +
         " has no terminating NUL");
  }
  // Read through fastcdr rather than skipped with jump(): fastcdr skips the alignment of a
  // field no wider than the last one it read, so it must know the last read was 1-byte chars.
  std::string out(length, '\0');
  impl_->cdr.deserializeArray(&out[0], length);
  out.pop_back();
  return out;
}

template <>
void CdrReader::Array<std::string>(std::string* out, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) out[i] = String();
}

// The types a message may hold (the template definitions stay here, beside fastcdr).
template bool CdrReader::Read<bool>();
template std::uint8_t CdrReader::Read<std::uint8_t>();
template std::int8_t CdrReader::Read<std::int8_t>();
template std::int16_t CdrReader::Read<std::int16_t>();
template std::uint16_t CdrReader::Read<std::uint16_t>();
template std::int32_t CdrReader::Read<std::int32_t>();
template std::uint32_t CdrReader::Read<std::uint32_t>();
template std::int64_t CdrReader::Read<std::int64_t>();
template std::uint64_t CdrReader::Read<std::uint64_t>();
template float CdrReader::Read<float>();
template double CdrReader::Read<double>();
template void CdrReader::Array<bool>(bool*, std::size_t);
template void CdrReader::Array<std::uint8_t>(std::uint8_t*, std::size_t);
template void CdrReader::Array<char>(char*, std::size_t);
template void CdrReader::Array<std::int8_t>(std::int8_t*, std::size_t);
template void CdrReader::Array<std::int16_t>(std::int16_t*, std::size_t);
template void CdrReader::Array<std::uint16_t>(std::uint16_t*, std::size_t);
template void CdrReader::Array<std::int32_t>(std::int32_t*, std::size_t);
template void CdrReader::Array<std::uint32_t>(std::uint32_t*, std::size_t);
template void CdrReader::Array<std::int64_t>(std::int64_t*, std::size_t);
template void CdrReader::Array<std::uint64_t>(std::uint64_t*, std::size_t);
template void CdrReader::Array<float>(float*, std::size_t);
template void CdrReader::Array<double>(double*, std::size_t);

std::uint32_t CdrReader::SequenceLength(std::size_t min_element_bytes, std::size_t alignment) {
  const std::uint32_t count = Read<std::uint32_t>();
  // Alignment counts from the end of the encapsulation header (see the file comment).
  const std::size_t position = impl_->cdr.getSerializedDataLength() - kEncapsulationBytes;
  const std::size_t padding = (alignment - position % alignment) % alignment;
  const std::size_t left = remaining() > padding ? remaining() - padding : 0;
  if (count > 0 && static_cast<std::uint64_t>(count) * min_element_bytes > left) {
    Fail("sequence length " + std::to_string(count) + " at byte " +
         std::to_string(position + kEncapsulationBytes - 4) + " is larger than the " +
         std::to_string(left) + " bytes left in the payload");
  }
  return count;
}

}  // namespace fitcal::io::rosbag2
