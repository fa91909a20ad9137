#pragma once
// How the rosbag2 code reports a bad bag: one io::InputError whose message is one line naming the
// file, where in it (byte offset, topic, message) and what is wrong. Strings taken from the file
// are shortened and stripped of control characters before they reach a message.

#include <cstdint>
#include <string>
#include <string_view>

#include "io/input_error.h"

namespace fitcal::io::rosbag2 {

// At most `max_chars` printable characters of `text`, quoted; the rest is elided with "...".
std::string Printable(std::string_view text, std::size_t max_chars = 48);

// Throws InputError(kind, file, 0, message). Binary files have no line numbers: callers say the
// byte offset in `message` ("at byte 1234: ...").
[[noreturn]] void ThrowBagError(InputErrorKind kind, const std::string& file,
                                const std::string& message);

// "at byte N: " prefix for messages about one place in a binary file.
std::string AtByte(std::uint64_t offset);

}  // namespace fitcal::io::rosbag2
