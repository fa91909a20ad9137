#pragma once
// Reading a binary file by offset (pread) and front to back through a growing buffer. Every read
// says whether the bytes were there, so a truncated file is an error the caller can name.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fitcal::io::rosbag2 {

class RandomAccessFile {
 public:
  // Throws InputError(kMissingFile) when the file cannot be opened.
  explicit RandomAccessFile(const std::string& path);
  ~RandomAccessFile();
  RandomAccessFile(const RandomAccessFile&) = delete;
  RandomAccessFile& operator=(const RandomAccessFile&) = delete;

  std::uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }
  // Reads exactly `count` bytes at `offset` into `out`; false if the file is shorter or fails.
  bool ReadAt(std::uint64_t offset, std::size_t count, std::uint8_t* out) const;

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// Front-to-back reading in large blocks: Read(n) hands out n contiguous bytes that stay valid
// until the next Read.
class SequentialReader {
 public:
  explicit SequentialReader(const RandomAccessFile& file, std::size_t block_bytes = 1 << 20);

  // The next `count` bytes, or nullptr when fewer are left in the file.
  const std::uint8_t* Read(std::size_t count);
  // Offset in the file of the next byte Read returns.
  std::uint64_t offset() const { return buffer_offset_ + pos_; }
  std::uint64_t remaining() const { return file_.size() - offset(); }

 private:
  const RandomAccessFile& file_;
  std::vector<std::uint8_t> buffer_;
  std::uint64_t buffer_offset_ = 0;  // file offset of buffer_[0]
  std::size_t pos_ = 0;              // next unread byte in buffer_
  std::size_t filled_ = 0;           // valid bytes in buffer_
};

}  // namespace fitcal::io::rosbag2
