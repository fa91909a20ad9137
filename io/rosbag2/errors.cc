#include "io/rosbag2/errors.h"

namespace fitcal::io::rosbag2 {

std::string Printable(std::string_view text, std::size_t max_chars) {
  std::string out = "\"";
  const std::size_t shown = text.size() < max_chars ? text.size() : max_chars;
  for (std::size_t i = 0; i < shown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  out += "\"";
  if (shown < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

void ThrowBagError(InputErrorKind kind, const std::string& file, const std::string& message) {
  throw InputError(kind, file, 0, message);
}

std::string AtByte(std::uint64_t offset) { return "at byte " + std::to_string(offset) + ": "; }

}  // namespace fitcal::io::rosbag2
