#include "io/text_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <new>

#include "io/input_error.h"
#include "io/input_registry.h"

namespace fitcal::io {

namespace {

// A file is only loaded when it fits in half of the memory that is free now, so an oversized
// input is refused with a message instead of an allocation failure. (A log's samples take about
// as many bytes as its text: 8 bytes per number against ~10 characters.)
std::size_t MaxLoadableBytes() {
  const long pages = sysconf(_SC_AVPHYS_PAGES);
  const long page_size = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page_size <= 0) return static_cast<std::size_t>(1) << 34;
  return static_cast<std::size_t>(pages) * static_cast<std::size_t>(page_size) / 2;
}

const char* FileTypeName(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The buffer a reader starts with; Fill() doubles it for a longer line, up to kMaxLineBytes. A log
// line is short: a 1 MiB start was zeroed and page-faulted afresh for every file read (a data set
// is hundreds of small files), 18 % of a fit's time in the sanitizer build, where freed memory is
// held back from reuse (docs/tests.md).
constexpr std::size_t kBufferBytes = std::size_t{1} << 16;

}  // namespace

int OpenRegularFile(const std::string& path, std::uint64_t* size_bytes) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever. It has no
  // effect on the reads of a regular file, the only kind accepted below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    throw InputError(InputErrorKind::kMissingFile, path, 0,
                     std::string("cannot open file: ") + std::strerror(errno));
  }
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    const mode_t mode = info.st_mode;
    ::close(fd);
    // A directory or a device opens too, but its "size" is meaningless (ext4 reports 2^31-1 for
    // a directory), and a device or a FIFO may never end: only regular files are read.
    throw InputError(InputErrorKind::kMissingFile, path, 0,
                     std::string("is ") + FileTypeName(mode) + ", not a regular file");
  }
  const auto size = static_cast<std::uint64_t>(info.st_size);
  if (size > MaxLoadableBytes()) {
    ::close(fd);
    throw InputError(InputErrorKind::kTooLarge, path, 0,
                     "file of " + std::to_string(size) +
                         " bytes is larger than half of the free memory; split the log");
  }
  *size_bytes = size;
  RegisterInput(path);  // an output must never replace what was read (io/input_registry.h)
  return fd;
}

std::string ReadTextFile(const std::string& path) {
  std::uint64_t size = 0;
  const int fd = OpenRegularFile(path, &size);
  std::string text;
  try {
    text.resize(static_cast<std::size_t>(size));
  } catch (const std::bad_alloc&) {
    ::close(fd);
    throw InputError(InputErrorKind::kOutOfMemory, path, 0,
                     "out of memory reading a file of " + std::to_string(size) + " bytes");
  }
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::read(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
  if (done != text.size()) {
    throw InputError(InputErrorKind::kMissingFile, path, 0, "cannot read file (short read)");
  }
  return text;
}

TextFileReader::TextFileReader(const std::string& path) : path_(path) {
  std::uint64_t size_bytes = 0;
  fd_ = OpenRegularFile(path, &size_bytes);
  try {
    buffer_.resize(kBufferBytes);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

TextFileReader::~TextFileReader() { ::close(fd_); }

bool TextFileReader::Fill() {
  if (eof_) return false;
  if (begin_ > 0) {  // keep the unread tail (a partial line) at the front
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (end_ == buffer_.size()) {
    if (buffer_.size() >= kMaxLineBytes) {
      throw InputError(InputErrorKind::kWrongColumnCount, path_, line_number_ + 1,
                       "line longer than " + std::to_string(kMaxLineBytes) +
                           " bytes (a binary or corrupted file?)");
    }
    buffer_.resize(buffer_.size() * 2);
  }
  for (;;) {
    const ssize_t n = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      throw InputError(InputErrorKind::kMissingFile, path_, 0,
                       std::string("cannot read file: ") + std::strerror(errno));
    }
    if (n == 0) eof_ = true;
    end_ += static_cast<std::size_t>(n);
    return n > 0;
  }
}

bool TextFileReader::Next(std::string_view* line) {
  if (line_number_ == 0 && begin_ == 0 && end_ == 0) {
    while (end_ < 3 && Fill()) {
    }
    if (end_ >= 3 && std::memcmp(buffer_.data(), "\xEF\xBB\xBF", 3) == 0) begin_ = 3;
  }
  for (;;) {
    const char* start = buffer_.data() + begin_;
    const void* newline = std::memchr(start, '\n', end_ - begin_);
    if (newline != nullptr || (eof_ && end_ > begin_)) {
      const char* stop =
          newline != nullptr ? static_cast<const char*>(newline) : buffer_.data() + end_;
      std::size_t length = static_cast<std::size_t>(stop - start);
      begin_ += length + (newline != nullptr ? 1 : 0);
      if (length > 0 && start[length - 1] == '\r') --length;
      *line = std::string_view(start, length);
      ++line_number_;
      return true;
    }
    if (!Fill() && end_ == begin_) return false;
  }
}

void TextFileReader::Rewind() {
  if (::lseek(fd_, 0, SEEK_SET) != 0) {
    throw InputError(InputErrorKind::kMissingFile, path_, 0, "cannot read file (not seekable)");
  }
  begin_ = end_ = 0;
  eof_ = false;
  line_number_ = 0;
}

std::size_t TextFileReader::CountLinesAndRewind() {
  Rewind();
  std::size_t lines = 1;
  for (;;) {
    const ssize_t n = ::read(fd_, buffer_.data(), buffer_.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    const char* p = buffer_.data();
    const char* const end = p + n;
    while ((p = static_cast<const char*>(
                std::memchr(p, '\n', static_cast<std::size_t>(end - p)))) != nullptr) {
      ++lines;
      ++p;
    }
  }
  Rewind();
  return lines;
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

std::vector<std::string> SplitCsvFields(std::string_view line) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos <= line.size()) {
    std::size_t end = line.find(',', pos);
    if (end == std::string_view::npos) end = line.size();
    out.emplace_back(Trim(line.substr(pos, end - pos)));
    pos = end + 1;
  }
  return out;
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
