// rosbag2's MCAP storage (.mcap), read from the specification (mcap.dev/spec) without the mcap
// library. The file is read front to back from the leading magic: the Summary section is not
// needed (a recorder killed before writing it still leaves a Data section we can use, as long
// as the Footer is there). Opening scans every record once: it checks the structure, decompresses
// each Chunk ("", "zstd", "lz4" frame), verifies every CRC the writer filled in (Chunk
// uncompressed_crc, Attachment crc, Data End data_section_crc, Footer summary_crc), learns the
// Schemas and Channels (rosbag2 writes them inside chunks) and counts messages per topic.
// Iteration then reads one chunk at a time again and yields messages by log_time across
// overlapping chunks (a k-way merge over the chunks whose time ranges overlap).

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <map>
#include <queue>

#include "io/rosbag2/compression.h"
#include "io/rosbag2/crc32.h"
#include "io/rosbag2/errors.h"
#include "io/rosbag2/mcap_format.h"
#include "io/rosbag2/storage.h"

namespace fitcal::io::rosbag2 {
namespace {

// Reading a binary file by offset (pread) and front to back through a growing buffer. Every read
// says whether the bytes were there, so a truncated file is an error the caller can name.
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

using mcap::FieldReader;
using mcap::Opcode;

// The largest record (and decompressed chunk) the reader will hold in memory. rosbag2 writes
// chunks of about 768 KiB to a few MiB; a larger length in a file is corruption or an attack.
constexpr std::uint64_t kMaxMcapRecordBytes = std::uint64_t{1} << 30;
// Messages outside chunks are grouped into blocks of about this size, read back as one unit.
constexpr std::uint64_t kLooseBlockBytes = 4 << 20;
constexpr std::int64_t kNoTime = std::numeric_limits<std::int64_t>::max();

// A run of records whose messages iteration reads together: a Chunk's records field, or
// consecutive Message records outside chunks ("loose" messages, spec "Data Section").
struct Block {
  std::uint64_t record_offset = 0;  // the Chunk record (or first loose Message), for messages
  std::uint64_t data_offset = 0;    // first stored byte
  std::uint64_t stored_bytes = 0;
  std::uint64_t uncompressed_bytes = 0;
  Compression compression = Compression::kNone;
  bool is_chunk = false;
  std::int64_t min_time_ns = kNoTime;
  std::int64_t max_time_ns = std::numeric_limits<std::int64_t>::min();
  std::uint64_t message_count = 0;
};

// One message of an open block: where its payload lies in the block's bytes.
struct Entry {
  std::int64_t time_ns;
  std::size_t payload_offset;
  std::size_t payload_size;
  std::size_t topic_index;
};

struct OpenBlock {
  std::size_t seq = 0;  // index into blocks_ (file order breaks ties between equal times)
  std::vector<std::uint8_t> bytes;
  std::vector<Entry> entries;  // sorted by time, stable
  std::size_t next = 0;
  std::int64_t next_time() const { return entries[next].time_ns; }
};

struct LaterFirst {
  bool operator()(const OpenBlock* a, const OpenBlock* b) const {
    if (a->next_time() != b->next_time()) return a->next_time() > b->next_time();
    return a->seq > b->seq;
  }
};

// A parsed Message record (spec "Message"); data is a view into the record.
struct MessageRecord {
  std::uint16_t channel_id;
  std::int64_t log_time_ns;
  ByteView data;
};

// Walks <opcode><length><content> records packed in `records` (a chunk's records field or a
// loose block), calling on_record(opcode, content, offset_in_records). `where` is the file
// offset used in messages.
template <typename OnRecord>
void WalkRecords(ByteView records, const std::string& file, std::uint64_t where,
                 const char* container, OnRecord&& on_record) {
  std::size_t pos = 0;
  while (pos < records.size) {
    if (records.size - pos < mcap::kRecordPrefixBytes) {
      ThrowBagError(InputErrorKind::kBadValue, file,
                    AtByte(where) + container + " ends inside a record header");
    }
    const std::uint8_t opcode = records.data[pos];
    const auto length = LoadLe<std::uint64_t>(records.data + pos + 1);
    if (length > records.size - pos - mcap::kRecordPrefixBytes) {
      ThrowBagError(InputErrorKind::kBadValue, file,
                    AtByte(where) + mcap::OpcodeName(opcode) + " record of " +
                        std::to_string(length) + " bytes runs past the end of the " + container);
    }
    on_record(opcode, records.Sub(pos + mcap::kRecordPrefixBytes, length), pos);
    pos += mcap::kRecordPrefixBytes + static_cast<std::size_t>(length);
  }
}

class McapStorage : public StorageReader {
 public:
  explicit McapStorage(const std::string& path);

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::int64_t start_time_ns() const override { return start_ns_; }
  std::int64_t end_time_ns() const override { return end_ns_; }
  bool Next(StoredMessage* message) override;
  // The blocks in file order, each one's messages in file order (before LoadBlock sorts them).
  void VisitInWriteOrder(const std::function<bool(std::size_t, std::int64_t)>& visit) override {
    for (std::size_t seq = 0; seq < blocks_.size(); ++seq) {
      if (blocks_[seq].message_count == 0) continue;
      // Held here: a range-for over a member of the temporary would outlive the block.
      const auto block = LoadBlock(seq, /*sorted=*/false);
      for (const Entry& e : block->entries) {
        if (!visit(e.topic_index, e.time_ns)) return;
      }
    }
  }

 private:
  // Opening: one pass over the file.
  struct Record {
    std::uint64_t offset;
    std::uint8_t prefix[mcap::kRecordPrefixBytes];  // a copy: Read() may move its buffer
    std::uint8_t opcode;
    ByteView content;
  };
  Record ReadRecord(SequentialReader* in, const char* missing);
  void Scan();
  void ReadLeadingMagicAndHeader(SequentialReader* in);
  bool ScanDataRecord(std::uint8_t opcode, ByteView content, std::uint64_t offset);
  void ScanSummary(SequentialReader* in);
  void CheckFooter(ByteView content, std::uint64_t offset);
  void OnSchema(ByteView content, std::uint64_t offset, const char* name);
  void OnChannel(ByteView content, std::uint64_t offset, const char* name);
  void OnChunk(ByteView content, std::uint64_t offset);
  void OnAttachment(ByteView content, std::uint64_t offset);
  void OnDataEnd(ByteView content, std::uint64_t offset);
  void OnLooseMessage(ByteView content, std::uint64_t record_offset, std::uint64_t record_end);
  void CountMessage(Block* block, ByteView content, std::uint64_t offset, const char* name);
  void ScanChunkRecords(Block* block, ByteView records);
  ByteView DecompressChunk(const Block& block, ByteView stored, std::vector<std::uint8_t>* out);
  MessageRecord ParseMessage(ByteView content, std::uint64_t offset, const char* name) const;
  void FinishScan();

  // Iteration.
  void OpenBlocksUpTo(std::int64_t time_ns);
  std::unique_ptr<OpenBlock> LoadBlock(std::size_t seq, bool sorted = true);

  [[noreturn]] void Fail(InputErrorKind kind, std::uint64_t offset, const std::string& what) const {
    ThrowBagError(kind, file_.path(), AtByte(offset) + what);
  }

  RandomAccessFile file_;
  Decompressor decompressor_;
  std::vector<TopicInfo> topics_;
  std::map<std::string, std::size_t> topic_by_name_;
  std::map<std::uint16_t, std::string> schema_names_;
  std::vector<std::int32_t> topic_of_channel_;  // channel id -> topic index, -1 when undefined
  std::vector<Block> blocks_;
  bool loose_block_open_ = false;
  Crc32 crc_;  // data section (spec "Data End"), then summary (spec "Footer")
  bool seen_data_end_ = false;
  std::int64_t start_ns_ = 0;
  std::int64_t end_ns_ = 0;
  std::vector<std::uint8_t> scratch_;

  // Iteration state: blocks in order of their first message time, the next one to open, and a
  // heap of open blocks by their next message. `retired_` keeps the block of the message last
  // returned alive until the following call (StoredMessage::payload points into it).
  std::vector<std::size_t> block_order_;
  std::size_t next_block_ = 0;
  std::vector<std::unique_ptr<OpenBlock>> open_;
  std::priority_queue<OpenBlock*, std::vector<OpenBlock*>, LaterFirst> heap_;
  std::unique_ptr<OpenBlock> retired_;
};

McapStorage::McapStorage(const std::string& path)
    : file_(path), topic_of_channel_(std::size_t{1} << 16, -1) {
  Scan();
  FinishScan();
}

// The next record, whole. `missing` says what the file lacks when it ends before a record.
McapStorage::Record McapStorage::ReadRecord(SequentialReader* in, const char* missing) {
  Record r{};
  r.offset = in->offset();
  const std::uint8_t* prefix = in->Read(mcap::kRecordPrefixBytes);
  if (prefix == nullptr) {
    Fail(InputErrorKind::kBadValue, r.offset, std::string("truncated file: ") + missing);
  }
  std::memcpy(r.prefix, prefix, mcap::kRecordPrefixBytes);
  r.opcode = r.prefix[0];
  const auto length = LoadLe<std::uint64_t>(r.prefix + 1);
  if (length > in->remaining()) {
    Fail(InputErrorKind::kBadValue, r.offset,
         "truncated file: " + mcap::OpcodeName(r.opcode) + " record of " + std::to_string(length) +
             " bytes runs past the end of the file (" + std::to_string(file_.size()) + " bytes)");
  }
  if (length > kMaxMcapRecordBytes) {
    Fail(InputErrorKind::kTooLarge, r.offset,
         mcap::OpcodeName(r.opcode) + " record of " + std::to_string(length) +
             " bytes is larger than the 1 GiB fitcal holds in memory");
  }
  r.content =
      ByteView(in->Read(static_cast<std::size_t>(length)), static_cast<std::size_t>(length));
  return r;
}

void McapStorage::Scan() {
  SequentialReader in(file_);
  ReadLeadingMagicAndHeader(&in);
  while (true) {
    const Record r = ReadRecord(&in, "it ends without a Data End or Footer record");
    // The data section CRC covers every byte before the Data End record (spec "Data End").
    if (r.opcode != static_cast<std::uint8_t>(Opcode::kDataEnd)) {
      crc_.Update(r.prefix, mcap::kRecordPrefixBytes);
    }
    if (!ScanDataRecord(r.opcode, r.content, r.offset)) break;
    crc_.Update(r.content.data, r.content.size);
    if (r.opcode == static_cast<std::uint8_t>(Opcode::kMessage)) {
      OnLooseMessage(r.content, r.offset, in.offset());
    }
  }
  ScanSummary(&in);
}

// Spec "Magic" and "Header": the file starts with the magic and a Header record.
void McapStorage::ReadLeadingMagicAndHeader(SequentialReader* in) {
  if (file_.size() == 0) ThrowBagError(InputErrorKind::kEmptyFile, file_.path(), "empty file");
  const std::uint8_t* magic = in->Read(mcap::kMagicBytes);
  if (magic == nullptr) {
    ThrowBagError(
        InputErrorKind::kBadValue, file_.path(),
        "truncated file: " + std::to_string(file_.size()) + " bytes, shorter than the MCAP magic");
  }
  if (std::memcmp(magic, mcap::kMagic, mcap::kMagicBytes) != 0) {
    ThrowBagError(InputErrorKind::kBadHeader, file_.path(),
                  "bad magic: the file does not start with the MCAP magic \\x89MCAP0\\r\\n");
  }
  crc_.Update(magic, mcap::kMagicBytes);
  const Record r = ReadRecord(in, "no Header record");
  if (r.opcode != static_cast<std::uint8_t>(Opcode::kHeader)) {
    Fail(InputErrorKind::kBadHeader, r.offset,
         "the first record is " + mcap::OpcodeName(r.opcode) + ", not a Header");
  }
  crc_.Update(r.prefix, mcap::kRecordPrefixBytes);
  crc_.Update(r.content.data, r.content.size);
  FieldReader fields(r.content, file_.path(), r.offset, "Header");
  fields.String();  // profile ("ros2" for rosbag2)
  fields.String();  // library
}

// One record of the data section; false at its end (Data End, or a Footer when a writer left
// Data End out, as files written before the spec required it do).
bool McapStorage::ScanDataRecord(std::uint8_t opcode, ByteView content, std::uint64_t offset) {
  switch (static_cast<Opcode>(opcode)) {
    case Opcode::kSchema:
      OnSchema(content, offset, "Schema");
      break;
    case Opcode::kChannel:
      OnChannel(content, offset, "Channel");
      break;
    case Opcode::kMessage:
      break;  // after the CRC update, by Scan (it needs the record's end offset)
    case Opcode::kChunk:
      OnChunk(content, offset);
      break;
    case Opcode::kAttachment:
      OnAttachment(content, offset);
      break;
    case Opcode::kDataEnd:
      OnDataEnd(content, offset);
      return false;
    case Opcode::kFooter:
      CheckFooter(content, offset);
      return false;
    case Opcode::kHeader:
      Fail(InputErrorKind::kBadValue, offset, "a second Header record");
    default:
      break;  // Message Index, Metadata, extensions (0x80-0xFF): not needed to read messages
  }
  if (opcode != static_cast<std::uint8_t>(Opcode::kMessage)) loose_block_open_ = false;
  return true;
}

// Spec "Schema": id u16, name, encoding, data (uint32-prefixed). Id 0 is invalid and ignored.
void McapStorage::OnSchema(ByteView content, std::uint64_t offset, const char* name) {
  FieldReader fields(content, file_.path(), offset, name);
  const std::uint16_t id = fields.U16();
  const std::string_view schema_name = fields.String();
  fields.String();   // encoding: "ros2msg", "ros2idl", ...
  fields.Bytes32();  // the definition text
  if (id != 0) schema_names_.emplace(id, std::string(schema_name));
}

// Spec "Channel": id u16, schema_id u16, topic, message_encoding, metadata map. A Schema must
// come before the Channels that use it; channels of one topic (several publishers) share it.
void McapStorage::OnChannel(ByteView content, std::uint64_t offset, const char* name) {
  FieldReader fields(content, file_.path(), offset, name);
  const std::uint16_t id = fields.U16();
  const std::uint16_t schema_id = fields.U16();
  const std::string topic(fields.String());
  const std::string encoding(fields.String());
  fields.SkipLengthPrefixed();             // metadata: offered_qos_profiles, type_description_hash
  if (topic_of_channel_[id] >= 0) return;  // a repeat (identical by the spec)
  const auto schema = schema_names_.find(schema_id);
  if (schema_id != 0 && schema == schema_names_.end()) {
    Fail(InputErrorKind::kBadValue, offset,
         "Channel " + std::to_string(id) + " refers to Schema " + std::to_string(schema_id) +
             ", which is not defined before it");
  }
  auto [it, added] = topic_by_name_.emplace(topic, topics_.size());
  if (added) {
    topics_.push_back({topic, schema_id != 0 ? schema->second : std::string(), encoding, 0});
  }
  topic_of_channel_[id] = static_cast<std::int32_t>(it->second);
}

// Spec "Message": channel_id u16, sequence u32, log_time, publish_time, data.
MessageRecord McapStorage::ParseMessage(ByteView content, std::uint64_t offset,
                                        const char* name) const {
  FieldReader fields(content, file_.path(), offset, name);
  MessageRecord message{};
  message.channel_id = fields.U16();
  fields.U32();  // sequence
  const std::uint64_t log_time = fields.U64();
  fields.U64();  // publish_time
  message.data = fields.Rest();
  if (log_time > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    Fail(InputErrorKind::kBadValue, offset, std::string(name) + " log_time beyond year 2262");
  }
  message.log_time_ns = static_cast<std::int64_t>(log_time);
  if (topic_of_channel_[message.channel_id] < 0) {
    Fail(InputErrorKind::kBadValue, offset,
         std::string(name) + " on channel " + std::to_string(message.channel_id) +
             ", which no Channel record before it defines");
  }
  return message;
}

void McapStorage::CountMessage(Block* block, ByteView content, std::uint64_t offset,
                               const char* name) {
  const MessageRecord message = ParseMessage(content, offset, name);
  ++topics_[static_cast<std::size_t>(topic_of_channel_[message.channel_id])].message_count;
  ++block->message_count;
  block->min_time_ns = std::min(block->min_time_ns, message.log_time_ns);
  block->max_time_ns = std::max(block->max_time_ns, message.log_time_ns);
}

void McapStorage::OnLooseMessage(ByteView content, std::uint64_t record_offset,
                                 std::uint64_t record_end) {
  if (!loose_block_open_ || record_end - blocks_.back().data_offset > kLooseBlockBytes) {
    Block block;
    block.record_offset = record_offset;
    block.data_offset = record_offset;
    blocks_.push_back(block);
    loose_block_open_ = true;
  }
  Block& block = blocks_.back();
  block.stored_bytes = block.uncompressed_bytes = record_end - block.data_offset;
  CountMessage(&block, content, record_offset, "Message");
}

// Spec "Chunk": message_start_time, message_end_time, uncompressed_size u64, uncompressed_crc
// u32, compression string, records (uint64-prefixed). Schemas, Channels and Messages inside.
void McapStorage::OnChunk(ByteView content, std::uint64_t offset) {
  FieldReader fields(content, file_.path(), offset, "Chunk");
  fields.U64();  // message_start_time: recomputed from the messages themselves
  fields.U64();  // message_end_time
  Block block;
  block.record_offset = offset;
  block.is_chunk = true;
  block.uncompressed_bytes = fields.U64();
  const std::uint32_t crc = fields.U32();
  const std::string_view compression = fields.String();
  const std::size_t records_at = fields.position() + 8;
  const ByteView stored = fields.Bytes64();
  block.data_offset = offset + mcap::kRecordPrefixBytes + records_at;
  block.stored_bytes = stored.size;
  const auto parsed = ParseCompression(compression);
  if (!parsed) {
    Fail(InputErrorKind::kBadValue, offset,
         "Chunk has unknown compression " + Printable(compression) + " (known: \"\", zstd, lz4)");
  }
  block.compression = *parsed;
  const ByteView records = DecompressChunk(block, stored, &scratch_);
  if (crc != 0 && ComputeCrc32(records.data, records.size) != crc) {
    Fail(InputErrorKind::kBadValue, offset,
         "Chunk CRC mismatch: its records do not match uncompressed_crc (corrupt chunk)");
  }
  ScanChunkRecords(&block, records);
  blocks_.push_back(block);
}

ByteView McapStorage::DecompressChunk(const Block& block, ByteView stored,
                                      std::vector<std::uint8_t>* out) {
  if (block.compression == Compression::kNone) {
    if (stored.size != block.uncompressed_bytes) {
      Fail(InputErrorKind::kBadValue, block.record_offset,
           "uncompressed Chunk declares " + std::to_string(block.uncompressed_bytes) +
               " bytes but stores " + std::to_string(stored.size));
    }
    return stored;
  }
  if (block.uncompressed_bytes > kMaxMcapRecordBytes) {
    Fail(InputErrorKind::kTooLarge, block.record_offset,
         "Chunk declares " + std::to_string(block.uncompressed_bytes) +
             " uncompressed bytes, more than the 1 GiB fitcal holds in memory");
  }
  std::string error;
  if (!decompressor_.CheckDeclaredSize(block.compression, stored, block.uncompressed_bytes,
                                       &error)) {
    Fail(InputErrorKind::kBadValue, block.record_offset,
         std::string("bad ") + CompressionName(block.compression) + " Chunk: " + error);
  }
  out->resize(static_cast<std::size_t>(block.uncompressed_bytes));
  if (!decompressor_.Decompress(block.compression, stored, out->data(), out->size(), &error)) {
    Fail(InputErrorKind::kBadValue, block.record_offset,
         std::string("cannot decompress the ") + CompressionName(block.compression) +
             " Chunk: " + error);
  }
  return ByteView(*out);
}

void McapStorage::ScanChunkRecords(Block* block, ByteView records) {
  const std::uint64_t at = block->record_offset;
  WalkRecords(records, file_.path(), at, "Chunk's records",
              [&](std::uint8_t opcode, ByteView content, std::size_t) {
                switch (static_cast<Opcode>(opcode)) {
                  case Opcode::kSchema:
                    OnSchema(content, at, "Schema in a Chunk");
                    break;
                  case Opcode::kChannel:
                    OnChannel(content, at, "Channel in a Chunk");
                    break;
                  case Opcode::kMessage:
                    CountMessage(block, content, at, "Message in a Chunk");
                    break;
                  default:
                    break;  // only those three belong in a chunk; ignore future records
                }
              });
}

// Spec "Attachment": ..., crc u32 over all preceding fields (0: not computed).
void McapStorage::OnAttachment(ByteView content, std::uint64_t offset) {
  FieldReader fields(content, file_.path(), offset, "Attachment");
  fields.U64();  // log_time
  fields.U64();  // create_time
  fields.String();
  fields.String();
  fields.Bytes64();
  const std::size_t covered = fields.position();
  const std::uint32_t crc = fields.U32();
  if (crc != 0 && ComputeCrc32(content.data, covered) != crc) {
    Fail(InputErrorKind::kBadValue, offset, "Attachment CRC mismatch (corrupt attachment)");
  }
}

// Spec "Data End": data_section_crc u32 over every byte before this record, magic included
// (0: not computed).
void McapStorage::OnDataEnd(ByteView content, std::uint64_t offset) {
  FieldReader fields(content, file_.path(), offset, "DataEnd");
  const std::uint32_t crc = fields.U32();
  if (crc != 0 && crc != crc_.value()) {
    Fail(InputErrorKind::kBadValue, offset,
         "data section CRC mismatch: the bytes before Data End are corrupt");
  }
  seen_data_end_ = true;
  crc_ = Crc32();  // the summary CRC starts after Data End
}

// Records after Data End up to the Footer (spec "Summary Section", "Summary Offset Section").
// Their Schemas and Channels repeat the data section's; Chunk Index, Statistics and the offsets
// are for readers that seek, which this one does not need.
void McapStorage::ScanSummary(SequentialReader* in) {
  if (!seen_data_end_) return;  // the Footer came straight after the data
  while (true) {
    const Record r = ReadRecord(in, "it ends without a Footer record");
    crc_.Update(r.prefix, mcap::kRecordPrefixBytes);
    if (r.opcode == static_cast<std::uint8_t>(Opcode::kFooter)) {
      CheckFooter(r.content, r.offset);
      return;
    }
    if (r.opcode == static_cast<std::uint8_t>(Opcode::kMessage) ||
        r.opcode == static_cast<std::uint8_t>(Opcode::kChunk)) {
      Fail(InputErrorKind::kBadValue, r.offset,
           mcap::OpcodeName(r.opcode) + " record after Data End (only the summary may follow)");
    }
    crc_.Update(r.content.data, r.content.size);
  }
}

// Spec "Footer": summary_start u64, summary_offset_start u64, summary_crc u32 over the summary
// sections and the Footer up to (not including) summary_crc; then the closing magic, last.
void McapStorage::CheckFooter(ByteView content, std::uint64_t offset) {
  if (content.size != mcap::kFooterBytes) {
    Fail(InputErrorKind::kBadValue, offset,
         "Footer record has " + std::to_string(content.size) + " bytes, not 20");
  }
  crc_.Update(content.data, 16);
  const auto summary_crc = LoadLe<std::uint32_t>(content.data + 16);
  if (seen_data_end_ && summary_crc != 0 && summary_crc != crc_.value()) {
    Fail(InputErrorKind::kBadValue, offset, "summary CRC mismatch: the summary section is corrupt");
  }
  const std::uint64_t end = offset + mcap::kRecordPrefixBytes + mcap::kFooterBytes;
  std::uint8_t magic[mcap::kMagicBytes] = {};
  if (!file_.ReadAt(end, mcap::kMagicBytes, magic)) {
    Fail(InputErrorKind::kBadValue, end, "truncated file: no closing magic after the Footer");
  }
  if (std::memcmp(magic, mcap::kMagic, mcap::kMagicBytes) != 0) {
    Fail(InputErrorKind::kBadHeader, end, "bad magic after the Footer");
  }
  if (end + mcap::kMagicBytes != file_.size()) {
    Fail(InputErrorKind::kBadValue, end + mcap::kMagicBytes,
         std::to_string(file_.size() - end - mcap::kMagicBytes) + " bytes after the closing magic");
  }
}

void McapStorage::FinishScan() {
  std::int64_t first = kNoTime;
  std::int64_t last = std::numeric_limits<std::int64_t>::min();
  for (std::size_t i = 0; i < blocks_.size(); ++i) {
    if (blocks_[i].message_count == 0) continue;
    block_order_.push_back(i);
    first = std::min(first, blocks_[i].min_time_ns);
    last = std::max(last, blocks_[i].max_time_ns);
  }
  std::stable_sort(block_order_.begin(), block_order_.end(), [&](std::size_t a, std::size_t b) {
    return blocks_[a].min_time_ns < blocks_[b].min_time_ns;
  });
  if (!block_order_.empty()) {
    start_ns_ = first;
    end_ns_ = last;
  }
  scratch_ = std::vector<std::uint8_t>();
}

// Reads a block again (the scan checked it; a file changed since is still caught by the bounds
// checks) and lists its messages by time.
std::unique_ptr<OpenBlock> McapStorage::LoadBlock(std::size_t seq, bool sorted) {
  const Block& block = blocks_[seq];
  auto open = std::make_unique<OpenBlock>();
  open->seq = seq;
  std::vector<std::uint8_t>& stored =
      block.compression == Compression::kNone ? open->bytes : scratch_;
  stored.resize(static_cast<std::size_t>(block.stored_bytes));
  if (!file_.ReadAt(block.data_offset, stored.size(), stored.data())) {
    Fail(InputErrorKind::kBadValue, block.record_offset, "the file changed while being read");
  }
  if (block.compression != Compression::kNone)
    DecompressChunk(block, ByteView(stored), &open->bytes);
  open->entries.reserve(static_cast<std::size_t>(block.message_count));
  const char* name = block.is_chunk ? "Message in a Chunk" : "Message";
  WalkRecords(ByteView(open->bytes), file_.path(), block.record_offset,
              block.is_chunk ? "Chunk's records" : "data section",
              [&](std::uint8_t opcode, ByteView content, std::size_t) {
                if (opcode != static_cast<std::uint8_t>(Opcode::kMessage)) return;
                const MessageRecord m = ParseMessage(content, block.record_offset, name);
                open->entries.push_back(
                    {m.log_time_ns, static_cast<std::size_t>(m.data.data - open->bytes.data()),
                     m.data.size, static_cast<std::size_t>(topic_of_channel_[m.channel_id])});
              });
  const auto by_time = [](const Entry& a, const Entry& b) { return a.time_ns < b.time_ns; };
  if (sorted && !std::is_sorted(open->entries.begin(), open->entries.end(), by_time)) {
    std::stable_sort(open->entries.begin(), open->entries.end(), by_time);
  }
  return open;
}

// Opens every block whose first message is not later than `time_ns`: only then can the block
// with the earliest pending message be known (blocks may overlap in time).
void McapStorage::OpenBlocksUpTo(std::int64_t time_ns) {
  while (next_block_ < block_order_.size() &&
         (heap_.empty() || blocks_[block_order_[next_block_]].min_time_ns <= time_ns)) {
    std::unique_ptr<OpenBlock> block = LoadBlock(block_order_[next_block_++]);
    if (block->entries.empty()) continue;
    heap_.push(block.get());
    open_.push_back(std::move(block));
    time_ns = heap_.top()->next_time();
  }
}

bool McapStorage::Next(StoredMessage* message) {
  retired_.reset();
  OpenBlocksUpTo(heap_.empty() ? kNoTime : heap_.top()->next_time());
  if (heap_.empty()) return false;
  OpenBlock* block = heap_.top();
  heap_.pop();
  const Entry& entry = block->entries[block->next++];
  message->topic_index = entry.topic_index;
  message->time_ns = entry.time_ns;
  message->payload = ByteView(block->bytes.data() + entry.payload_offset, entry.payload_size);
  if (block->next < block->entries.size()) {
    heap_.push(block);
  } else {
    const auto it =
        std::find_if(open_.begin(), open_.end(),
                     [&](const std::unique_ptr<OpenBlock>& b) { return b.get() == block; });
    retired_ = std::move(*it);
    open_.erase(it);
  }
  return true;
}

}  // namespace

std::unique_ptr<StorageReader> OpenMcapStorage(const std::string& path) {
  return std::make_unique<McapStorage>(path);
}

}  // namespace fitcal::io::rosbag2
