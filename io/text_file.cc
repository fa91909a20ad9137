#include "io/text_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>

#include "io/input_error.h"

namespace fitcal::io {

namespace {
struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

// A file is only loaded when it fits in half of the memory that is free now, so an oversized
// input is refused with a message instead of an allocation failure.
std::size_t MaxLoadableBytes() {
  const long pages = sysconf(_SC_AVPHYS_PAGES);
  const long page_size = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page_size <= 0) return static_cast<std::size_t>(1) << 34;
  return static_cast<std::size_t>(pages) * static_cast<std::size_t>(page_size) / 2;
}
}  // namespace

std::string ReadTextFile(const std::string& path) {
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw InputError(InputErrorKind::kMissingFile, path, 0, "cannot open file");
  // A directory or a device opens too, but its "size" is meaningless (ext4 reports 2^31-1 for a
  // directory): only regular files are read.
  struct stat info {};
  if (fstat(fileno(file.get()), &info) != 0 || !S_ISREG(info.st_mode)) {
    throw InputError(InputErrorKind::kMissingFile, path, 0, "not a regular file");
  }
  if (std::fseek(file.get(), 0, SEEK_END) != 0) {
    throw InputError(InputErrorKind::kMissingFile, path, 0, "cannot read file (not seekable)");
  }
  const long size = std::ftell(file.get());
  if (size < 0) throw InputError(InputErrorKind::kMissingFile, path, 0, "cannot read file");
  if (static_cast<std::size_t>(size) > MaxLoadableBytes()) {
    throw InputError(InputErrorKind::kTooLarge, path, 0,
                     "file of " + std::to_string(size) +
                         " bytes is larger than half of the free memory; split the log");
  }
  std::rewind(file.get());
  std::string text(static_cast<std::size_t>(size), '\0');
  if (size > 0 && std::fread(text.data(), 1, text.size(), file.get()) != text.size()) {
    throw InputError(InputErrorKind::kMissingFile, path, 0, "cannot read file (short read)");
  }
  return text;
}

LineScanner::LineScanner(std::string_view text) : text_(text) {
  if (text_.size() >= 3 && text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
}

bool LineScanner::Next(std::string_view* line) {
  if (pos_ >= text_.size()) return false;
  std::size_t end = text_.find('\n', pos_);
  if (end == std::string_view::npos) end = text_.size();
  std::size_t stop = end;
  if (stop > pos_ && text_[stop - 1] == '\r') --stop;
  *line = text_.substr(pos_, stop - pos_);
  pos_ = end + 1;
  ++line_number_;
  return true;
}

std::string_view Trim(std::string_view s) {
  std::size_t b = 0;
  std::size_t e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
  return s.substr(b, e - b);
}

bool ParseDouble(std::string_view field, double* value, bool* finite) {
  field = Trim(field);
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  if (field.empty()) return false;
  const char* first = field.data();
  const char* last = first + field.size();
  const auto result = std::from_chars(first, last, *value);
  if (result.ptr != last) return false;
  if (result.ec == std::errc::result_out_of_range) {
    *finite = false;
    return true;
  }
  if (result.ec != std::errc()) return false;
  *finite = std::isfinite(*value);
  return true;
}

}  // namespace fitcal::io
