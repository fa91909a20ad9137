#include "io/rosbag2/bag_reader.h"

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <limits>
#include <map>

#include "io/rosbag2/errors.h"

namespace fitcal::io::rosbag2 {
namespace {

namespace fs = std::filesystem;

// The storage plugin of a single file, from its extension (rosbag2 names them so).
std::string StorageOfFile(const fs::path& file) {
  if (file.extension() == ".db3") return "sqlite3";
  if (file.extension() == ".mcap") return "mcap";
  ThrowBagError(InputErrorKind::kBadValue, file.string(),
                "not a bag: expected a bag directory, metadata.yaml, .db3 or .mcap file");
}

// A relative_file_paths entry resolved inside the bag directory, never outside it. rosbag2 wrote
// "<bag directory name>/<file>" in metadata versions 1-3 (relative to the directory above the
// bag) and "<file>" from version 4 on; for the old versions the first component is dropped,
// whatever the directory is called now (a bag copied under another name). A listed file that is
// not in the bag is refused: a file of the same name beside the bag belongs to another recording.
std::string ResolveBagFile(const fs::path& bag_dir, const std::string& relative, int version,
                           const std::string& metadata_path) {
  const fs::path rel(relative);
  for (const fs::path& part : rel) {
    if (part == "..") {
      ThrowBagError(InputErrorKind::kBadPath, metadata_path,
                    "file " + Printable(relative) + " lies outside the bag directory");
    }
  }
  if (rel.is_absolute() || relative.empty()) {
    ThrowBagError(InputErrorKind::kBadPath, metadata_path,
                  "file " + Printable(relative) + " is not a path relative to the bag");
  }
  fs::path in_bag;
  for (auto part = version < 4 ? std::next(rel.begin()) : rel.begin(); part != rel.end(); ++part) {
    in_bag /= *part;
  }
  if (in_bag.empty() || !in_bag.has_filename()) {
    ThrowBagError(InputErrorKind::kBadPath, metadata_path,
                  "file " + Printable(relative) + " of a version " + std::to_string(version) +
                      " bag names no file inside its directory (<bag directory>/<file>)");
  }
  const fs::path path = bag_dir / in_bag;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    ThrowBagError(InputErrorKind::kMissingFile, metadata_path,
                  "lists file " + Printable(relative) + ", which is not in the bag directory " +
                      Printable(bag_dir.string(), 200));
  }
  return path.string();
}

}  // namespace

std::string Describe(const BagMessage& message) {
  return (message.file != nullptr ? *message.file : std::string("?")) + " " +
         (message.topic != nullptr ? message.topic->name : std::string("?")) + " message at " +
         std::to_string(message.time_ns) + " ns";
}

BagReader::BagReader(const std::string& path) {
  const fs::path p(path);
  if (fs::is_directory(p)) {
    OpenFromMetadata((p / "metadata.yaml").string());
  } else if (p.filename() == "metadata.yaml") {
    OpenFromMetadata(path);
  } else {
    if (!fs::exists(p)) ThrowBagError(InputErrorKind::kMissingFile, path, "no such bag file");
    storage_identifier_ = StorageOfFile(p);
    files_.push_back(path);
  }
  OpenStorages();
}

BagReader::~BagReader() = default;

void BagReader::OpenFromMetadata(const std::string& metadata_path) {
  if (!fs::exists(metadata_path)) {
    ThrowBagError(InputErrorKind::kMissingFile, metadata_path, "the bag has no metadata.yaml");
  }
  metadata_ = std::make_unique<BagMetadata>(ReadBagMetadata(metadata_path));
  storage_identifier_ = metadata_->storage_identifier;
  if (storage_identifier_ != "sqlite3" && storage_identifier_ != "mcap") {
    ThrowBagError(
        InputErrorKind::kBadValue, metadata_path,
        "unknown storage_identifier " + Printable(storage_identifier_) + " (known: sqlite3, mcap)");
  }
  if (!metadata_->compression_mode.empty() || !metadata_->compression_format.empty()) {
    ThrowBagError(InputErrorKind::kBadValue, metadata_path,
                  "compressed bag (compression_mode " + Printable(metadata_->compression_mode) +
                      ", format " + Printable(metadata_->compression_format) +
                      ") is not supported; MCAP chunk compression is");
  }
  const fs::path bag_dir = fs::path(metadata_path).parent_path();
  for (const std::string& relative : metadata_->relative_file_paths) {
    files_.push_back(ResolveBagFile(bag_dir, relative, metadata_->version, metadata_path));
    // A file listed twice would be read twice: its messages would repeat (refused later as a
    // clock that does not advance, which names neither the list nor the file).
    if (std::find(files_.begin(), files_.end() - 1, files_.back()) != files_.end() - 1) {
      ThrowBagError(InputErrorKind::kBadValue, metadata_path,
                    "lists file " + Printable(relative) + " twice (relative_file_paths)");
    }
  }
}

void BagReader::OpenStorages() {
  std::int64_t first = std::numeric_limits<std::int64_t>::max();
  std::int64_t last = std::numeric_limits<std::int64_t>::min();
  for (const std::string& file : files_) {
    storages_.push_back(storage_identifier_ == "mcap" ? OpenMcapStorage(file)
                                                      : OpenSqlite3Storage(file));
    MergeTopics(storages_.size() - 1);
    const StorageReader& storage = *storages_.back();
    std::uint64_t count = 0;
    for (const TopicInfo& topic : storage.topics()) count += topic.message_count;
    if (count == 0) continue;
    first = std::min(first, storage.start_time_ns());
    last = std::max(last, storage.end_time_ns());
  }
  if (first <= last) {
    start_ns_ = first;
    end_ns_ = last;
  }
  pending_.resize(storages_.size());
  has_pending_.assign(storages_.size(), false);
}

// Topics are matched across the files of a split bag by name, and must agree on their type.
void BagReader::MergeTopics(std::size_t file_index) {
  std::vector<std::size_t> map;
  for (const TopicInfo& topic : storages_[file_index]->topics()) {
    std::size_t i = 0;
    while (i < topics_.size() && topics_[i].name != topic.name) ++i;
    // One name, one type: the messages of a topic are decoded with its type.
    if (i < topics_.size() && topics_[i].type != topic.type) {
      ThrowBagError(InputErrorKind::kBadValue, files_[file_index],
                    "topic " + Printable(topic.name) + " has type " + Printable(topic.type) +
                        " here and " + Printable(topics_[i].type) +
                        " in an earlier file of the bag");
    }
    if (i == topics_.size()) {
      topics_.push_back(topic);
      topics_.back().message_count = 0;
    }
    topics_[i].message_count += topic.message_count;
    map.push_back(i);
  }
  topic_map_.push_back(std::move(map));
}

const TopicInfo* BagReader::FindTopic(const std::string& name) const {
  for (const TopicInfo& topic : topics_) {
    if (topic.name == name) return &topic;
  }
  return nullptr;
}

std::uint64_t BagReader::message_count() const {
  std::uint64_t count = 0;
  for (const TopicInfo& topic : topics_) count += topic.message_count;
  return count;
}

bool BagReader::Advance(std::size_t file_index) {
  has_pending_[file_index] = storages_[file_index]->Next(&pending_[file_index]);
  return has_pending_[file_index];
}

std::optional<ClockStepBack> BagReader::RecordingClockStepBack(std::string* file) {
  std::map<std::string, std::int64_t> latest_ns;  // by topic, over the files in split order
  std::optional<ClockStepBack> step;
  for (std::size_t i = 0; i < storages_.size() && !step; ++i) {
    *file = files_[i];
    storages_[i]->VisitInWriteOrder([&](std::size_t topic_index, std::int64_t t) {
      const auto [it, first] = latest_ns.emplace(topics_[topic_map_[i][topic_index]].name, t);
      if (!first && t < it->second - kClockStepBackToleranceNs) step = ClockStepBack{it->second, t};
      it->second = std::max(it->second, t);
      return !step;
    });
  }
  return step;
}

// A k-way merge of the files, each already in time order. Only the file whose message went out
// last is advanced, so the payloads of the others stay valid.
bool BagReader::ReadNext(BagMessage* message) {
  if (!started_) {
    for (std::size_t i = 0; i < storages_.size(); ++i) Advance(i);
    started_ = true;
  } else if (!storages_.empty() && has_pending_[last_file_]) {
    Advance(last_file_);
  }
  std::size_t best = storages_.size();
  for (std::size_t i = 0; i < storages_.size(); ++i) {
    if (has_pending_[i] &&
        (best == storages_.size() || pending_[i].time_ns < pending_[best].time_ns)) {
      best = i;
    }
  }
  if (best == storages_.size()) return false;
  last_file_ = best;
  const StoredMessage& next = pending_[best];
  message->topic = &topics_[topic_map_[best][next.topic_index]];
  message->file = &files_[best];
  message->time_ns = next.time_ns;
  message->payload = next.payload;
  return true;
}

}  // namespace fitcal::io::rosbag2
