#include "io/yaml_reader.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <new>

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

// Bounds on a YAML document, far above any fitcal file (a data set of a thousand runs is ~200 KB
// and some 10^4 nodes, nested 4 deep) and far below what hangs a reader: yaml-cpp resolves an
// alias to the node it names, so a few lines that repeat each other ("billion laughs") make a
// tree of 10^9 nodes that every walk over the document - ours and every loader's - would expand.
constexpr std::size_t kMaxYamlBytes = std::size_t{16} << 20;
constexpr std::size_t kMaxYamlNodes = 1000000;
constexpr std::size_t kMaxYamlDepth = 64;

// One walk over the document, iterative (a deeply nested file must not overflow the stack),
// counting every node as the loaders will see it (an alias counts each time it is used):
// refuses a document beyond the bounds above, and a key written twice in one map (yaml-cpp keeps
// both entries and node[key] finds the first: the second would be silently ignored, a hand edit
// that "changes" a value without effect).
void CheckDocument(const YAML::Node& root, const std::string& path) {
  std::vector<std::pair<YAML::Node, std::size_t>> pending{{root, 1}};
  std::size_t visited = 0;
  while (!pending.empty()) {
    const auto [node, depth] = pending.back();
    pending.pop_back();
    if (++visited > kMaxYamlNodes) {
      throw InputError(InputErrorKind::kTooLarge, path, LineOf(node),
                       "the document expands to more than " + std::to_string(kMaxYamlNodes) +
                           " nodes (aliases that repeat each other?); refusing to read it");
    }
    if (depth > kMaxYamlDepth) {
      throw InputError(InputErrorKind::kTooLarge, path, LineOf(node),
                       "nested deeper than " + std::to_string(kMaxYamlDepth) +
                           " levels; no fitcal file nests like that");
    }
    if (node.IsSequence()) {
      for (const YAML::Node& child : node) pending.emplace_back(child, depth + 1);
    } else if (node.IsMap()) {
      std::map<std::string, int> first_line;
      for (const auto& entry : node) {
        if (entry.first.IsScalar()) {
          const auto [it, fresh] = first_line.emplace(entry.first.Scalar(), LineOf(entry.first));
          if (!fresh) {
            throw InputError(InputErrorKind::kDuplicateKey, path, LineOf(entry.first),
                             "key '" + entry.first.Scalar() +
                                 "' appears twice in one map (first at line " +
                                 std::to_string(it->second) + "); remove one");
          }
        } else {
          pending.emplace_back(entry.first, depth + 1);  // a complex key is walked too
        }
        pending.emplace_back(entry.second, depth + 1);
      }
    }
  }
}

// Edit distance with transpositions (optimal string alignment: "modle" is one edit from "model"),
// for "did you mean": keys are short, so the quadratic table is tiny.
std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

// `s` without its digits: "r_w1" and "r_w2" are two keys of a family, not one misspelt.
std::string WithoutDigits(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c < '0' || c > '9') out += c;
  }
  return out;
}

// The candidate closest to `key` when it is plausibly a misspelling of it (a fifth of its letters
// or fewer differ; keys of under four letters are too short to tell), "" otherwise.
std::string ClosestKey(const std::string& key, const std::vector<std::string>& candidates) {
  if (key.size() < 4) return "";
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(1, key.size() / 5) + 1;
  for (const std::string& c : candidates) {
    if (c != key && WithoutDigits(c) == WithoutDigits(key)) continue;
    const std::size_t d = EditDistance(key, c);
    if (d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace

YAML::Node ParseYaml(const std::string& text, const std::string& path) {
  if (text.size() > kMaxYamlBytes) {
    throw InputError(InputErrorKind::kTooLarge, path, 0,
                     "YAML file of " + std::to_string(text.size()) + " bytes is larger than " +
                         std::to_string(kMaxYamlBytes >> 20) + " MiB; no fitcal YAML is");
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(InputErrorKind::kYamlSyntax, path, e.mark.line + 1, e.msg);
  }
  CheckDocument(root, path);
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
    // A key present but misspelt is named on its own line, not reported as the right one missing.
    std::vector<std::string> present;
    for (const auto& entry : node_) {
      if (entry.first.IsScalar() && read_.count(entry.first.Scalar()) == 0) {
        present.push_back(entry.first.Scalar());
      }
    }
    const std::string misspelt = ClosestKey(key, present);
    if (!misspelt.empty()) {
      throw InputError(InputErrorKind::kUnknownKey, path_, LineOf(node_[misspelt]),
                       "unknown key '" + misspelt + "' in " + what_ + ": misspelt '" + key + "'?");
    }
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

std::string YamlMap::Name(const std::string& key) {
  const YAML::Node child = Required(key);
  const std::string name = YamlString(child, path_, what_ + "." + key);
  const std::string what = what_ + "." + key;
  if (name.empty() || name.find_first_not_of(" \t") == std::string::npos) {
    throw InputError(InputErrorKind::kBadValue, path_, LineOf(child), what + " is empty; name it");
  }
  if (name.size() > kMaxNameBytes) {
    throw InputError(InputErrorKind::kBadValue, path_, LineOf(child),
                     what + " is " + std::to_string(name.size()) + " bytes long (at most " +
                         std::to_string(kMaxNameBytes) + ")");
  }
  for (char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      throw InputError(InputErrorKind::kBadValue, path_, LineOf(child),
                       what + " holds a control character (code " + std::to_string(u) +
                           "); use printable characters");
    }
  }
  return name;
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
      const std::string known =
          ClosestKey(key, std::vector<std::string>(read_.begin(), read_.end()));
      throw InputError(InputErrorKind::kUnknownKey, path_, LineOf(entry.first),
                       "unknown key '" + key + "' in " + what_ +
                           (known.empty() ? "" : ": misspelt '" + known + "'?"));
    }
  }
}

}  // namespace fitcal::io
