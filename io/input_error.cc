#include "io/input_error.h"

namespace fitcal::io {

std::string OneLine(const std::string& text, std::size_t max_chars) {
  std::string out = text;
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (out.size() <= max_chars) return out;
  const std::string gap = "...[" + std::to_string(out.size() - max_chars) + " bytes]...";
  const std::size_t keep = max_chars > gap.size() ? max_chars - gap.size() : 0;
  return out.substr(0, keep - keep / 3) + gap + out.substr(out.size() - keep / 3);
}

// The path and the message are each clamped (a path near PATH_MAX, a header line of a binary
// file). The message's clamp is above fitcal's own longest sentences (~400 characters: an angle
// glitch's with its hint was cut mid-word at 300), so that only what a message echoes is cut.
std::string FileLineText(const std::string& file, int line, const std::string& message) {
  std::string out = OneLine(file, 200);
  if (line > 0) out += ":" + std::to_string(line);
  return out + ": " + OneLine(message, 600);
}

InputError::InputError(InputErrorKind kind, std::string file, int line, const std::string& message)
    : std::runtime_error(FileLineText(file, line, message)),
      kind_(kind),
      file_(std::move(file)),
      line_(line) {}

}  // namespace fitcal::io
