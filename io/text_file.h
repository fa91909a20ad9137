#pragma once
// Reading whole text files, and the line/field scanning shared by the CSV and TUM loaders.

#include <cstddef>
#include <string>
#include <string_view>

namespace fitcal::io {

// Reads the file into memory; throws InputError (kMissingFile, kTooLarge).
std::string ReadTextFile(const std::string& path);

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

}  // namespace fitcal::io
