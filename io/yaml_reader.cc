#include "io/yaml_reader.h"

#include <cmath>

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
int LineOf(const YAML::Node& node) { return node.Mark().line >= 0 ? node.Mark().line + 1 : 0; }
}  // namespace

YAML::Node LoadYamlFile(const std::string& path) {
  const std::string text = ReadTextFile(path);
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(InputErrorKind::kYamlSyntax, path, e.mark.line + 1, e.msg);
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
