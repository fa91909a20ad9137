#pragma once
// Strict reading of YAML maps: every key that is present must be read, a missing required key or
// a key nobody reads is an InputError naming the file and line. Used by every YAML loader so that
// a typo in a config file is an error, not silence.

#include <yaml-cpp/yaml.h>

#include <set>
#include <string>

namespace fitcal::io {

// The 1-based line of a node in its file, as InputError reports it; 0 for a node without a position
// (a missing key's null node).
int LineOf(const YAML::Node& node);

// Parses a YAML file; throws InputError (kMissingFile, kYamlSyntax, kDuplicateKey).
YAML::Node LoadYamlFile(const std::string& path);
// The same for text already in memory; `path` names it in messages.
YAML::Node ParseYaml(const std::string& text, const std::string& path);

class YamlMap {
 public:
  // `what` names the map in messages (e.g. "robot", "wheel 2").
  YamlMap(const YAML::Node& node, std::string path, std::string what);

  bool Has(const std::string& key) const;
  YAML::Node Required(const std::string& key);
  YAML::Node Optional(const std::string& key);  // null node when absent

  std::string String(const std::string& key);
  // A name (robot, wheel, run id, trajectory): a non-empty string of at most kMaxNameBytes
  // without control characters, which would break the one-line messages and the files it is
  // written into.
  static constexpr std::size_t kMaxNameBytes = 200;
  std::string Name(const std::string& key);
  double Double(const std::string& key);
  int Int(const std::string& key);
  // A two-element list [lo, hi] of numbers.
  std::pair<double, double> Pair(const std::string& key);

  // Throws kUnknownKey for a key that was never asked for.
  void RejectUnread() const;

  int line(const YAML::Node& node) const { return node.Mark().line + 1; }
  const std::string& path() const { return path_; }

 private:
  YAML::Node node_;
  std::string path_;
  std::string what_;
  std::set<std::string> read_;
};

// Typed access to a scalar node with file/line errors.
double YamlDouble(const YAML::Node& node, const std::string& path, const std::string& what);
std::string YamlString(const YAML::Node& node, const std::string& path, const std::string& what);
void ExpectYamlType(const YAML::Node& node, YAML::NodeType::value type, const std::string& path,
                    const std::string& what);

}  // namespace fitcal::io
