#include "io/rosbag2/binary_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "io/rosbag2/errors.h"

namespace fitcal::io::rosbag2 {

RandomAccessFile::RandomAccessFile(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (fd_ < 0 || ::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    const std::string why = fd_ < 0 ? std::strerror(errno) : "not a regular file";
    if (fd_ >= 0) ::close(fd_);
    ThrowBagError(InputErrorKind::kMissingFile, path, "cannot open the bag file: " + why);
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

RandomAccessFile::~RandomAccessFile() { ::close(fd_); }

bool RandomAccessFile::ReadAt(std::uint64_t offset, std::size_t count, std::uint8_t* out) const {
  if (offset > size_ || count > size_ - offset) return false;
  while (count > 0) {
    const ssize_t n = ::pread(fd_, out, count, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    out += n;
    offset += static_cast<std::uint64_t>(n);
    count -= static_cast<std::size_t>(n);
  }
  return true;
}

SequentialReader::SequentialReader(const RandomAccessFile& file, std::size_t block_bytes)
    : file_(file), buffer_(block_bytes) {}

const std::uint8_t* SequentialReader::Read(std::size_t count) {
  if (count > remaining()) return nullptr;
  if (filled_ - pos_ < count) {
    // Keep the unread tail, grow for a record larger than the buffer, refill behind it.
    std::memmove(buffer_.data(), buffer_.data() + pos_, filled_ - pos_);
    buffer_offset_ += pos_;
    filled_ -= pos_;
    pos_ = 0;
    if (buffer_.size() < count) buffer_.resize(count);
    const std::uint64_t in_file = file_.size() - (buffer_offset_ + filled_);
    const std::size_t want =
        static_cast<std::size_t>(std::min<std::uint64_t>(buffer_.size() - filled_, in_file));
    if (!file_.ReadAt(buffer_offset_ + filled_, want, buffer_.data() + filled_)) return nullptr;
    filled_ += want;
  }
  const std::uint8_t* p = buffer_.data() + pos_;
  pos_ += count;
  return p;
}

}  // namespace fitcal::io::rosbag2
