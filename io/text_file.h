#pragma once
// Reading text files: whole (small files: YAML), or line by line as they stream (logs, which can
// be larger than the memory their samples need twice), the line/field scanning shared by the
// CSV and TUM loaders, and its inverse: items joined into one text.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace fitcal::io {

// Reads the file into memory; throws InputError (kMissingFile, kTooLarge, kOutOfMemory).
std::string ReadTextFile(const std::string& path);

// Opens `path` for reading: refuses anything but a regular file (a FIFO, a device, a socket, a
// directory) without blocking on it, and a file larger than half of the free memory. Returns the
// descriptor; *size_bytes gets the size. Throws InputError (kMissingFile, kTooLarge).
int OpenRegularFile(const std::string& path, std::uint64_t* size_bytes);

// Streams a regular file line by line through a fixed buffer, so a loader holds what it parses
// and never a copy of the whole text. Strips a UTF-8 byte-order mark at the start and a '\r'
// before each '\n'; counts lines from 1. A line longer than kMaxLineBytes is an InputError (no
// log line is that long; it is a binary or a corrupted file).
class TextFileReader {
 public:
  static constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;

  explicit TextFileReader(const std::string& path);
  ~TextFileReader();
  TextFileReader(const TextFileReader&) = delete;
  TextFileReader& operator=(const TextFileReader&) = delete;

  // Next line (without its terminator), valid until the next call; false at the end.
  bool Next(std::string_view* line);
  int line_number() const { return line_number_; }
  const std::string& path() const { return path_; }
  // Lines in the file (one pass over it, memchr speed), to reserve sample storage exactly; then
  // reading starts again at line 1.
  std::size_t CountLinesAndRewind();

 private:
  bool Fill();  // reads more bytes after the unread ones; false at the end of the file
  void Rewind();

  std::string path_;
  int fd_ = -1;
  std::vector<char> buffer_;
  std::size_t begin_ = 0;  // unread bytes are [begin_, end_)
  std::size_t end_ = 0;
  bool eof_ = false;
  int line_number_ = 0;
};

// Walks a text buffer line by line: strips a UTF-8 byte-order mark at the start and a '\r' before
// each '\n', and counts lines from 1.
class LineScanner {
 public:
  explicit LineScanner(std::string_view text);
  // Next line (without its terminator); false at the end of the text.
  bool Next(std::string_view* line);
  int line_number() const { return line_number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_number_ = 0;
};

// Parses one decimal number, surrounding blanks allowed. Returns false if the field is not a
// number; *finite is false for NaN, Inf and values beyond the double range.
bool ParseDouble(std::string_view field, double* value, bool* finite);

std::string_view Trim(std::string_view s);
// The comma-separated fields of one line, each trimmed ("a, b," -> "a", "b", "").
std::vector<std::string> SplitCsvFields(std::string_view line);

// The text of each item, `separator` between them: a message's list of names ("a, b, c"), the
// elements of a JSON list or map.
template <typename Items, typename Text>
std::string Joined(const Items& items, const char* separator, const Text& text) {
  std::string out;
  bool first = true;
  for (const auto& item : items) {
    out += (first ? "" : separator) + text(item);
    first = false;
  }
  return out;
}
// Items that are text already (strings, string views, C strings).
template <typename Items>
std::string Joined(const Items& items, const char* separator) {
  return Joined(items, separator, [](const auto& item) { return std::string(item); });
}

}  // namespace fitcal::io
