#pragma once
// Chunk compression of MCAP (spec, "Chunk" and "Supported compression formats"): none, Zstandard
// frames, or LZ4 *frame* format (not raw LZ4 blocks). Decompression writes exactly the declared
// uncompressed size and fails on more or less, so a lying header cannot make us write past a
// buffer or hand out bytes nobody wrote.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "io/rosbag2/bytes.h"

namespace fitcal::io::rosbag2 {

enum class Compression { kNone, kZstd, kLz4 };

// "" / "zstd" / "lz4" (the spelling in MCAP chunk records); nullopt for anything else.
std::optional<Compression> ParseCompression(std::string_view name);
const char* CompressionName(Compression compression);

// Holds the decoder contexts so that a reader decompressing thousands of chunks reuses them.
class Decompressor {
 public:
  Decompressor();
  ~Decompressor();
  Decompressor(const Decompressor&) = delete;
  Decompressor& operator=(const Decompressor&) = delete;

  // Decompresses `input` into out[0, expected_size). Returns false and says why in `error` when
  // the input is not a valid stream or does not decompress to exactly `expected_size` bytes.
  bool Decompress(Compression compression, ByteView input, std::uint8_t* out,
                  std::size_t expected_size, std::string* error);

  // Before allocating `declared_size` bytes: false (with the reason) when the compressed stream
  // cannot decompress to that size. A zstd frame or an lz4 frame header that records its content
  // size must agree with it; lz4 cannot expand more than 255:1 (a match length grows by 255 per
  // extra byte, lz4 block format). Guards against a chunk header that claims gigabytes.
  bool CheckDeclaredSize(Compression compression, ByteView input, std::uint64_t declared_size,
                         std::string* error);

 private:
  struct Contexts;
  std::unique_ptr<Contexts> contexts_;
};

}  // namespace fitcal::io::rosbag2
