#pragma once
// Reading one CDR-serialized ROS 2 message (OMG CDR as in DDS-XTYPES 1.3, "XCDR version 1",
// which is what rmw_fastrtps / rmw_cyclonedds put in a bag). Layout:
//   4-byte encapsulation header: 0x00, then 0x00 (CDR_BE) or 0x01 (CDR_LE), then 2 option bytes;
//   fields in declaration order, each primitive aligned to its own size (at most 8) counted from
//   the first byte *after* the header; strings as uint32 length (including the NUL) + bytes + NUL;
//   sequences as uint32 element count + elements; fixed arrays as the bare elements.
// Decoding goes through Debian's libfastcdr (eprosima::fastcdr::Cdr over a FastBuffer); this
// class adds the checks a file from outside needs: every length is compared with the bytes left
// before anything is allocated, strings must end in NUL, and a short payload is an InputError
// naming the message, never a crash or a huge allocation.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "io/rosbag2/bytes.h"

namespace fitcal::io::rosbag2 {

class CdrReader {
 public:
  // `payload` starts with the encapsulation header. `what` names the message in errors (file,
  // topic, time); it becomes the InputError's file. Throws for a bad header.
  CdrReader(ByteView payload, std::string what);
  ~CdrReader();
  CdrReader(const CdrReader&) = delete;
  CdrReader& operator=(const CdrReader&) = delete;

  // Bytes not yet read (trailing alignment padding included).
  std::size_t remaining() const;

  // A primitive field: bool, std::(u)int8_t .. std::(u)int64_t, float or double.
  template <typename T>
  T Read();
  std::string String();

  // A fixed-size array (`T name[N]` in a .msg file) of one of those, of char or of strings.
  template <typename T>
  void Array(T* out, std::size_t count);

  // The uint32 element count of a sequence, checked: `count * min_element_bytes` (after the
  // first element's alignment to `alignment`) must fit in the bytes left.
  std::uint32_t SequenceLength(std::size_t min_element_bytes, std::size_t alignment);

  // `T[] name`: a sequence of primitives or strings.
  template <typename T>
  std::vector<T> Sequence() {
    const std::size_t size = std::is_same<T, std::string>::value ? 4 : sizeof(T);
    std::vector<T> out(SequenceLength(size, size < 8 ? size : 8));
    if (!out.empty()) Array(out.data(), out.size());
    return out;
  }

 private:
  struct Impl;
  [[noreturn]] void Fail(const std::string& why) const;

  std::unique_ptr<Impl> impl_;
  std::string what_;
  std::size_t size_;
};

template <>
void CdrReader::Array<std::string>(std::string* out, std::size_t count);

}  // namespace fitcal::io::rosbag2
