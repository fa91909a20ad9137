#include "io/rosbag2/bag_metadata.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>

#include "io/input_error.h"
#include "io/yaml_reader.h"

namespace fitcal::io::rosbag2 {

namespace fs = std::filesystem;

namespace {

YAML::Node Required(const YAML::Node& map, const std::string& key, const std::string& path) {
  if (!map.IsMap()) {
    throw InputError(InputErrorKind::kWrongYamlType, path, LineOf(map),
                     "expected a map holding '" + key + "'");
  }
  const YAML::Node value = map[key];
  if (!value) {
    throw InputError(InputErrorKind::kMissingKey, path, LineOf(map), "missing key '" + key + "'");
  }
  return value;
}

template <typename T>
T Scalar(const YAML::Node& node, const std::string& key, const std::string& path) {
  if (!node.IsScalar()) {
    throw InputError(InputErrorKind::kWrongYamlType, path, LineOf(node),
                     "'" + key + "' is not a scalar");
  }
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(node),
                     "'" + key + "' has a value of the wrong type");
  }
}

template <typename T>
T Get(const YAML::Node& map, const std::string& key, const std::string& path) {
  return Scalar<T>(Required(map, key, path), key, path);
}

// An optional string (a key absent or `~` reads as "").
std::string OptionalString(const YAML::Node& map, const std::string& key, const std::string& path) {
  const YAML::Node value = map[key];
  if (!value || value.IsNull()) return "";
  return Scalar<std::string>(value, key, path);
}

YAML::Node RequiredList(const YAML::Node& map, const std::string& key, const std::string& path) {
  const YAML::Node list = Required(map, key, path);
  if (!list.IsSequence()) {
    throw InputError(InputErrorKind::kWrongYamlType, path, LineOf(list),
                     "'" + key + "' is not a list");
  }
  return list;
}

std::int64_t Nanoseconds(const YAML::Node& map, const std::string& key, const std::string& inner,
                         const std::string& path) {
  return Get<std::int64_t>(Required(map, key, path), inner, path);
}

TopicInfo ReadTopic(const YAML::Node& entry, const std::string& path) {
  const YAML::Node topic = Required(entry, "topic_metadata", path);
  // A braced list reads the keys in order, so the first missing one is the one reported.
  return {Get<std::string>(topic, "name", path), Get<std::string>(topic, "type", path),
          Get<std::string>(topic, "serialization_format", path),
          Get<std::uint64_t>(entry, "message_count", path)};
}

BagFileInfo ReadFileInfo(const YAML::Node& entry, const std::string& path) {
  return {Get<std::string>(entry, "path", path),
          Nanoseconds(entry, "starting_time", "nanoseconds_since_epoch", path),
          Nanoseconds(entry, "duration", "nanoseconds", path),
          Get<std::uint64_t>(entry, "message_count", path)};
}

// rosbag2's metadata versions so far: 1-9 (9 from Jazzy, 2024). A version outside them is a
// layout fitcal was not written for (version 4 moved the file paths, 6 the QoS): refused, not
// read as if it were known.
constexpr int kNewestMetadataVersion = 9;

BagMetadata ReadInformation(const YAML::Node& info, const std::string& path) {
  BagMetadata m;
  m.version = Get<int>(info, "version", path);
  if (m.version < 1 || m.version > kNewestMetadataVersion) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(info["version"]),
                     "version " + std::to_string(m.version) +
                         " of the bag's metadata is not one fitcal reads (1-" +
                         std::to_string(kNewestMetadataVersion) + ")");
  }
  m.storage_identifier = Get<std::string>(info, "storage_identifier", path);
  for (const YAML::Node& p : RequiredList(info, "relative_file_paths", path)) {
    m.relative_file_paths.push_back(Scalar<std::string>(p, "relative_file_paths", path));
  }
  if (info["files"]) {
    for (const YAML::Node& f : RequiredList(info, "files", path)) {
      m.files.push_back(ReadFileInfo(f, path));
    }
  }
  m.starting_time_ns = Nanoseconds(info, "starting_time", "nanoseconds_since_epoch", path);
  m.duration_ns = Nanoseconds(info, "duration", "nanoseconds", path);
  m.message_count = Get<std::uint64_t>(info, "message_count", path);
  for (const YAML::Node& t : RequiredList(info, "topics_with_message_count", path)) {
    m.topics.push_back(ReadTopic(t, path));
  }
  m.compression_format = OptionalString(info, "compression_format", path);
  m.compression_mode = OptionalString(info, "compression_mode", path);
  return m;
}

}  // namespace

BagMetadata ReadBagMetadata(const std::string& path) {
  // The shared reader: regular files only (a FIFO does not block), duplicate keys refused.
  const YAML::Node root = LoadYamlFile(path);
  return ReadInformation(Required(root, "rosbag2_bagfile_information", path), path);
}

OwningBag OwningBagOfFile(const std::string& file) {
  const fs::path metadata_path = fs::path(file).parent_path() / "metadata.yaml";
  std::error_code ec;
  if (!fs::is_regular_file(metadata_path, ec)) return {};
  try {
    const BagMetadata metadata = ReadBagMetadata(metadata_path.string());
    // Versions before 5 listed each file with the bag's folder in front: compare file names.
    const fs::path name = fs::path(file).filename();
    const auto is_this = [&](const std::string& p) { return fs::path(p).filename() == name; };
    const std::vector<std::string>& parts = metadata.relative_file_paths;
    if (std::none_of(parts.begin(), parts.end(), is_this)) return {};
    return {metadata_path.parent_path().string(), parts.size()};
  } catch (const InputError&) {
    return {};  // a metadata.yaml that does not read is no bag this file belongs to
  }
}

}  // namespace fitcal::io::rosbag2
