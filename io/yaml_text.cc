#include "io/yaml_text.h"

#include <algorithm>
#include <cctype>

#include "io/input_error.h"
#include "io/yaml_scalar.h"

namespace fitcal::io {

bool IsSafePlainYaml(const std::string& s) {
  if (s.empty()) return false;
  // Must start with a letter or '_' (not a digit, sign or '.': numbers, ".inf", "-1").
  const auto first = static_cast<unsigned char>(s.front());
  if (!(std::isalpha(first) || first == '_')) return false;
  // Letters, digits and "_-./" only: no ':', '#', quotes, spaces, flow or control characters.
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (!(std::isalnum(u) || c == '_' || c == '-' || c == '.' || c == '/')) return false;
  }
  // The words YAML 1.1 and 1.2 read as booleans or null, in any case.
  std::string lower = s;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* word : {"y", "n", "yes", "no", "true", "false", "on", "off", "null"}) {
    if (lower == word) return false;
  }
  return true;
}

std::string YamlScalar(const std::string& s) {
  YAML::Emitter out;
  out << YamlText(s);
  return out.c_str();
}

std::string YamlDoubleQuoted(const std::string& s) {
  YAML::Emitter out;
  out << YAML::DoubleQuoted << s;
  return out.c_str();
}

std::string YamlCommentText(const std::string& s) { return OneLine(s, std::string::npos); }

}  // namespace fitcal::io
