#pragma once
// rosbag2's MCAP storage (.mcap), read from the specification (mcap.dev/spec) without the mcap
// library. The file is read front to back from the leading magic: the Summary section is not
// needed (a recorder killed before writing it still leaves a Data section we can use, as long
// as the Footer is there). Opening scans every record once: it checks the structure, decompresses
// each Chunk ("", "zstd", "lz4" frame), verifies every CRC the writer filled in (Chunk
// uncompressed_crc, Attachment crc, Data End data_section_crc, Footer summary_crc), learns the
// Schemas and Channels (rosbag2 writes them inside chunks) and counts messages per topic.
// Iteration then reads one chunk at a time again and yields messages by log_time across
// overlapping chunks (a k-way merge over the chunks whose time ranges overlap).

#include <cstdint>
#include <memory>
#include <string>

#include "io/rosbag2/storage.h"

namespace fitcal::io::rosbag2 {

// The largest record (and decompressed chunk) the reader will hold in memory. rosbag2 writes
// chunks of about 768 KiB to a few MiB; a larger length in a file is corruption or an attack.
constexpr std::uint64_t kMaxMcapRecordBytes = std::uint64_t{1} << 30;

// Opens one .mcap file. Throws InputError for a missing, truncated or corrupt file.
std::unique_ptr<StorageReader> OpenMcapStorage(const std::string& path);

}  // namespace fitcal::io::rosbag2
