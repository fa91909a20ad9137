#include "io/rosbag2/compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <cstring>

#include "odometry/invalid.h"

namespace fitcal::io::rosbag2 {

std::optional<Compression> ParseCompression(std::string_view name) {
  if (name.empty()) return Compression::kNone;
  if (name == "zstd") return Compression::kZstd;
  if (name == "lz4") return Compression::kLz4;
  return std::nullopt;
}

const char* CompressionName(Compression compression) {
  switch (compression) {
    case Compression::kNone:
      return "";
    case Compression::kZstd:
      return "zstd";
    case Compression::kLz4:
      return "lz4";
  }
  return "";
}

struct Decompressor::Contexts {
  ZSTD_DCtx* zstd = nullptr;
  LZ4F_dctx* lz4 = nullptr;
};

Decompressor::Decompressor() : contexts_(std::make_unique<Contexts>()) {
  contexts_->zstd = ZSTD_createDCtx();
  if (LZ4F_isError(LZ4F_createDecompressionContext(&contexts_->lz4, LZ4F_VERSION))) {
    contexts_->lz4 = nullptr;
  }
  if (contexts_->zstd == nullptr || contexts_->lz4 == nullptr) {
    throw std::bad_alloc();
  }
}

Decompressor::~Decompressor() {
  ZSTD_freeDCtx(contexts_->zstd);
  LZ4F_freeDecompressionContext(contexts_->lz4);
}

namespace {

bool DecompressZstd(ZSTD_DCtx* ctx, ByteView input, std::uint8_t* out, std::size_t expected,
                    std::string* error) {
  const std::size_t written = ZSTD_decompressDCtx(ctx, out, expected, input.data, input.size);
  if (ZSTD_isError(written))
    return Invalid(error, std::string("zstd: ") + ZSTD_getErrorName(written));
  if (written != expected)
    return Invalid(error, "zstd data decompresses to " + std::to_string(written) +
                              " bytes, not the declared " + std::to_string(expected));
  return true;
}

// LZ4 frame format (lz4 project's lz4_Frame_format.md): a stream may hold several frames;
// LZ4F_decompress returns 0 at the end of each one. Output beyond `expected` means the header's
// uncompressed size is wrong.
bool DecompressLz4(LZ4F_dctx* ctx, ByteView input, std::uint8_t* out, std::size_t expected,
                   std::string* error) {
  LZ4F_resetDecompressionContext(ctx);
  std::size_t in_pos = 0;
  std::size_t out_pos = 0;
  std::size_t hint = 1;  // nonzero: inside a frame
  while (in_pos < input.size) {
    std::size_t out_size = expected - out_pos;
    std::size_t in_size = input.size - in_pos;
    hint = LZ4F_decompress(ctx, out + out_pos, &out_size, input.data + in_pos, &in_size, nullptr);
    if (LZ4F_isError(hint)) return Invalid(error, std::string("lz4: ") + LZ4F_getErrorName(hint));
    in_pos += in_size;
    out_pos += out_size;
    if (in_size == 0 && out_size == 0)
      return Invalid(error, "lz4 data decompresses to more than the declared " +
                                std::to_string(expected) + " bytes");
  }
  if (hint != 0) return Invalid(error, "lz4 frame is truncated");
  if (out_pos != expected)
    return Invalid(error, "lz4 data decompresses to " + std::to_string(out_pos) +
                              " bytes, not the declared " + std::to_string(expected));
  return true;
}

}  // namespace

bool Decompressor::Decompress(Compression compression, ByteView input, std::uint8_t* out,
                              std::size_t expected_size, std::string* error) {
  switch (compression) {
    case Compression::kNone:
      if (input.size != expected_size)
        return Invalid(error, "uncompressed size " + std::to_string(expected_size) +
                                  " differs from the " + std::to_string(input.size) +
                                  " bytes stored");
      if (expected_size > 0) std::memcpy(out, input.data, expected_size);
      return true;
    case Compression::kZstd:
      return DecompressZstd(contexts_->zstd, input, out, expected_size, error);
    case Compression::kLz4:
      return DecompressLz4(contexts_->lz4, input, out, expected_size, error);
  }
  return Invalid(error, "unknown compression");
}

bool Decompressor::CheckDeclaredSize(Compression compression, ByteView input,
                                     std::uint64_t declared_size, std::string* error) {
  const std::string declared = "declared uncompressed size " + std::to_string(declared_size);
  if (compression == Compression::kZstd) {
    const unsigned long long content = ZSTD_getFrameContentSize(input.data, input.size);
    if (content == ZSTD_CONTENTSIZE_ERROR) return Invalid(error, "not a zstd frame");
    const bool one_frame = ZSTD_findFrameCompressedSize(input.data, input.size) == input.size;
    if (content != ZSTD_CONTENTSIZE_UNKNOWN && one_frame && content != declared_size)
      return Invalid(error, declared + " differs from the zstd frame's " + std::to_string(content));
  } else if (compression == Compression::kLz4) {
    constexpr std::uint64_t kMaxLz4Ratio = 255;
    if (declared_size > input.size * kMaxLz4Ratio + 65536)
      return Invalid(error, declared + " is more than lz4 can expand " +
                                std::to_string(input.size) + " bytes to");
    LZ4F_resetDecompressionContext(contexts_->lz4);
    LZ4F_frameInfo_t info{};
    std::size_t consumed = input.size;
    if (LZ4F_isError(LZ4F_getFrameInfo(contexts_->lz4, &info, input.data, &consumed)))
      return Invalid(error, "not an lz4 frame");
    if (info.contentSize != 0 && info.contentSize > declared_size)
      return Invalid(
          error, declared + " is less than the lz4 frame's " + std::to_string(info.contentSize));
  }
  return true;
}

}  // namespace fitcal::io::rosbag2
