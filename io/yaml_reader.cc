#include "io/yaml_reader.h"

#include <cmath>
#include <map>
#include <new>
#include <vector>

#include "io/input_error.h"
#include "io/text_file.h"

namespace fitcal::io {

namespace {
const char* TypeName(YAML::NodeType::value type) {
  switch (type) {
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Scalar:
      return "a scalar";
    case YAML::NodeType::Null:
      return "empty";
    case YAML::NodeType::Undefined:
      return "undefined";
  }
  return "unknown";
}
}  // namespace

int LineOf(const YAML::Node& node) { return node.Mark().line >= 0 ? node.Mark().line + 1 : 0; }

namespace {
// yaml-cpp keeps both entries of a key written twice, and node[key] finds the first: the second
// would be silently ignored (a hand edit that "changes" a value without effect). Every map of
// the document is checked, iteratively (a deeply nested file must not overflow the stack).
void RejectDuplicateKeys(const YAML::Node& root, const std::string& path) {
  std::vector<YAML::Node> pending{root};
  while (!pending.empty()) {
    const YAML::Node node = pending.back();
    pending.pop_back();
    if (node.IsSequence()) {
      for (const YAML::Node& child : node) pending.push_back(child);
    } else if (node.IsMap()) {
      std::map<std::string, int> first_line;
      for (const auto& entry : node) {
        if (entry.first.IsScalar()) {
          const auto [it, fresh] = first_line.emplace(entry.first.Scalar(), LineOf(entry.first));
          if (!fresh) {
            throw InputError(InputErrorKind::kDuplicateKey, path, LineOf(entry.first),
                             "key '" + entry.first.Scalar() +
                                 "' appears twice in one map (first "
                                 "at line " +
                                 std::to_string(it->second) + "); remove one");
          }
        }
        pending.push_back(entry.second);
      }
    }
  }
}
}  // namespace

YAML::Node ParseYaml(const std::string& text, const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(InputErrorKind::kYamlSyntax, path, e.mark.line + 1, e.msg);
  }
  RejectDuplicateKeys(root, path);
  return root;
}

YAML::Node LoadYamlFile(const std::string& path) {
  const std::string text = ReadTextFile(path);
  try {
    return ParseYaml(text, path);
  } catch (const std::bad_alloc&) {
    throw InputError(InputErrorKind::kOutOfMemory, path, 0,
                     "out of memory while parsing this file");
  }
}

void ExpectYamlType(const YAML::Node& node, YAML::NodeType::value type, const std::string& path,
                    const std::string& what) {
  if (node.Type() != type) {
    throw InputError(InputErrorKind::kWrongYamlType, path, LineOf(node),
                     what + " must be " + TypeName(type) + ", found " + TypeName(node.Type()));
  }
}

double YamlDouble(const YAML::Node& node, const std::string& path, const std::string& what) {
  ExpectYamlType(node, YAML::NodeType::Scalar, path, what);
  double value = 0.0;
  bool finite = true;
  if (!ParseDouble(node.Scalar(), &value, &finite)) {
    throw InputError(InputErrorKind::kNonNumeric, path, LineOf(node),
                     what + " is not a number: '" + node.Scalar() + "'");
  }
  if (!finite) {
    throw InputError(InputErrorKind::kNonFinite, path, LineOf(node),
                     what + " is not finite: '" + node.Scalar() + "'");
  }
  return value;
}

std::string YamlString(const YAML::Node& node, const std::string& path, const std::string& what) {
  ExpectYamlType(node, YAML::NodeType::Scalar, path, what);
  return node.Scalar();
}

YamlMap::YamlMap(const YAML::Node& node, std::string path, std::string what)
    : node_(node), path_(std::move(path)), what_(std::move(what)) {
  ExpectYamlType(node_, YAML::NodeType::Map, path_, what_);
}

bool YamlMap::Has(const std::string& key) const { return static_cast<bool>(node_[key]); }

YAML::Node YamlMap::Required(const std::string& key) {
  read_.insert(key);
  const YAML::Node child = node_[key];
  if (!child) {
    throw InputError(InputErrorKind::kMissingKey, path_, LineOf(node_),
                     what_ + " has no '" + key + "'");
  }
  return child;
}

YAML::Node YamlMap::Optional(const std::string& key) {
  read_.insert(key);
  return node_[key];
}

std::string YamlMap::String(const std::string& key) {
  return YamlString(Required(key), path_, what_ + "." + key);
}

double YamlMap::Double(const std::string& key) {
  return YamlDouble(Required(key), path_, what_ + "." + key);
}

int YamlMap::Int(const std::string& key) {
  const YAML::Node child = Required(key);
  const double value = YamlDouble(child, path_, what_ + "." + key);
  if (value != std::floor(value) || std::abs(value) > 1e9) {
    throw InputError(InputErrorKind::kBadValue, path_, LineOf(child),
                     what_ + "." + key + " must be a whole number, found '" + child.Scalar() + "'");
  }
  return static_cast<int>(value);
}

std::pair<double, double> YamlMap::Pair(const std::string& key) {
  const YAML::Node child = Required(key);
  const std::string what = what_ + "." + key;
  ExpectYamlType(child, YAML::NodeType::Sequence, path_, what);
  if (child.size() != 2) {
    throw InputError(InputErrorKind::kBadValue, path_, LineOf(child),
                     what + " must be a list [lo, hi] of two numbers");
  }
  return {YamlDouble(child[0], path_, what + "[0]"), YamlDouble(child[1], path_, what + "[1]")};
}

void YamlMap::RejectUnread() const {
  for (const auto& entry : node_) {
    const std::string key = entry.first.Scalar();
    if (read_.count(key) == 0) {
      throw InputError(InputErrorKind::kUnknownKey, path_, LineOf(entry.first),
                       "unknown key '" + key + "' in " + what_);
    }
  }
}

}  // namespace fitcal::io
