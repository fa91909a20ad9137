#pragma once
// Text written into YAML so that every YAML reader reads back the same string. yaml-cpp's emitter
// writes a string plain when it can, and a plain "007", "1e3", "true", "no", "null" or "12:30" is
// a number, a boolean, null or a sexagesimal number to another reader (YAML 1.1 parsers such as
// PyYAML; ROS tools); and a name with ':', '#', quotes or control characters needs quoting and
// escaping. `out << YamlText(s)` writes `s` plain only when it is an identifier-like word no
// reader takes for anything but a string, double-quoted (with escapes) otherwise.

#include <yaml-cpp/yaml.h>

#include <string>

namespace fitcal::io {

struct YamlText {
  explicit YamlText(const std::string& s) : text(s) {}
  const std::string& text;
};

// True when `s` reads back as the same string in every YAML reader if written plain.
bool IsSafePlainYaml(const std::string& s);

inline YAML::Emitter& operator<<(YAML::Emitter& out, const YamlText& t) {
  if (!IsSafePlainYaml(t.text)) out << YAML::DoubleQuoted;
  return out << t.text;
}

}  // namespace fitcal::io
