#include "tests/bags/bag_writer.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace fitcal::io::rosbag2 {

namespace fs = std::filesystem;

namespace {

void EmitTopic(YAML::Emitter& out, const TopicInfo& topic) {
  out << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << topic.name;
  out << YAML::Key << "type" << YAML::Value << topic.type;
  out << YAML::Key << "serialization_format" << YAML::Value << topic.serialization_format;
  out << YAML::Key << "offered_qos_profiles" << YAML::Value << YAML::DoubleQuoted << "";
  out << YAML::EndMap;
  out << YAML::Key << "message_count" << YAML::Value << topic.message_count << YAML::EndMap;
}

void EmitTime(YAML::Emitter& out, const char* key, const char* inner, std::int64_t value_ns) {
  out << YAML::Key << key << YAML::Value << YAML::BeginMap << YAML::Key << inner << YAML::Value
      << value_ns << YAML::EndMap;
}

void EmitFile(YAML::Emitter& out, const BagFileInfo& file) {
  out << YAML::BeginMap << YAML::Key << "path" << YAML::Value << file.path;
  EmitTime(out, "starting_time", "nanoseconds_since_epoch", file.starting_time_ns);
  EmitTime(out, "duration", "nanoseconds", file.duration_ns);
  out << YAML::Key << "message_count" << YAML::Value << file.message_count << YAML::EndMap;
}

// The YAML text rosbag2 would write for `metadata` (version 5 layout).
std::string BagMetadataToYaml(const BagMetadata& m) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value
      << YAML::BeginMap;
  out << YAML::Key << "version" << YAML::Value << m.version;
  out << YAML::Key << "storage_identifier" << YAML::Value << m.storage_identifier;
  EmitTime(out, "duration", "nanoseconds", m.duration_ns);
  EmitTime(out, "starting_time", "nanoseconds_since_epoch", m.starting_time_ns);
  out << YAML::Key << "message_count" << YAML::Value << m.message_count;
  out << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
  for (const TopicInfo& topic : m.topics) EmitTopic(out, topic);
  out << YAML::EndSeq;
  out << YAML::Key << "compression_format" << YAML::Value << YAML::DoubleQuoted
      << m.compression_format;
  out << YAML::Key << "compression_mode" << YAML::Value << YAML::DoubleQuoted << m.compression_mode;
  out << YAML::Key << "relative_file_paths" << YAML::Value << m.relative_file_paths;
  out << YAML::Key << "files" << YAML::Value << YAML::BeginSeq;
  for (const BagFileInfo& file : m.files) EmitFile(out, file);
  out << YAML::EndSeq << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

BagWriter::BagWriter(const std::string& directory, BagWriterOptions options)
    : directory_(directory), options_(options) {
  fs::create_directories(directory);
  metadata_.version = 5;
  metadata_.storage_identifier = options_.storage == StorageFormat::kMcap ? "mcap" : "sqlite3";
  OpenNextFile();
}

BagWriter::~BagWriter() {
  try {
    Close();
  } catch (...) {
    // A destructor must not throw; callers who care call Close themselves.
  }
}

void BagWriter::OpenNextFile() {
  const std::string extension = options_.storage == StorageFormat::kMcap ? ".mcap" : ".db3";
  const std::string name =
      fs::path(directory_).filename().string() + "_" + std::to_string(paths_.size()) + extension;
  const std::string path = (fs::path(directory_) / name).string();
  fs::remove(path);  // sqlite3 would otherwise append to an old database
  current_ = options_.storage == StorageFormat::kMcap ? CreateMcapWriter(path, options_.mcap)
                                                      : CreateSqlite3Writer(path);
  paths_.push_back(path);
  metadata_.relative_file_paths.push_back(name);
  file_ = BagFileInfo{name, 0, 0, 0};
  // Every file of a split bag lists every topic known so far, as rosbag2 does.
  for (std::size_t i = 0; i < topics_.size(); ++i) current_->AddTopic(i, topics_[i]);
}

void BagWriter::AddTopic(const std::string& name, const std::string& type,
                         const std::string& serialization_format) {
  if (topic_index_.count(name) != 0) return;
  topic_index_[name] = topics_.size();
  topics_.push_back({name, type, serialization_format, 0});
  current_->AddTopic(topics_.size() - 1, topics_.back());
}

void BagWriter::Write(const std::string& topic, std::int64_t time_ns, ByteView payload) {
  const auto it = topic_index_.find(topic);
  if (it == topic_index_.end()) throw std::invalid_argument("BagWriter: unknown topic " + topic);
  if (options_.split_after_messages > 0 && file_.message_count == options_.split_after_messages) {
    CloseCurrentFile();
    OpenNextFile();
  }
  current_->Write(it->second, time_ns, payload);
  ++topics_[it->second].message_count;
  if (file_.message_count == 0 || time_ns < file_.starting_time_ns) {
    file_.starting_time_ns = time_ns;
  }
  file_end_ns_ = file_.message_count == 0 ? time_ns : std::max(file_end_ns_, time_ns);
  ++file_.message_count;
}

void BagWriter::CloseCurrentFile() {
  current_->Close();
  current_.reset();
  file_.duration_ns = file_.message_count > 0 ? file_end_ns_ - file_.starting_time_ns : 0;
  metadata_.files.push_back(file_);
}

void BagWriter::Close() {
  if (closed_) return;
  closed_ = true;
  CloseCurrentFile();
  std::int64_t first = 0, last = 0;
  bool any = false;
  for (const BagFileInfo& f : metadata_.files) {
    if (f.message_count == 0) continue;
    first = any ? std::min(first, f.starting_time_ns) : f.starting_time_ns;
    last = any ? std::max(last, f.starting_time_ns + f.duration_ns)
               : f.starting_time_ns + f.duration_ns;
    any = true;
    metadata_.message_count += f.message_count;
  }
  metadata_.starting_time_ns = first;
  metadata_.duration_ns = last - first;
  metadata_.topics = topics_;
  std::ofstream out(fs::path(directory_) / "metadata.yaml");
  out << BagMetadataToYaml(metadata_);
  if (!out) throw std::runtime_error(directory_ + ": cannot write metadata.yaml");
}

}  // namespace fitcal::io::rosbag2
