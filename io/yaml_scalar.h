#pragma once
// User strings (names, joints, ids, paths) in YAML written as text rather than through a
// YAML::Emitter: every one goes through these, which ask yaml-cpp's emitter (io/yaml_text.h's
// rule: plain only for an identifier-like word, else double-quoted with escapes), so a quote,
// `: #`, a leading '-', a backslash, control characters or unicode read back as written.

#include <string>

namespace fitcal::io {

// `s` as a YAML scalar (a value or a key): plain when every reader reads it back the same,
// double-quoted and escaped otherwise.
std::string YamlScalar(const std::string& s);

// `s` always double-quoted and escaped (flow lists of names, where ROS tools expect strings).
std::string YamlDoubleQuoted(const std::string& s);

// `s` on one comment line: line breaks and other control characters shown as '?', so that a path
// or a topic name in a `# ...` header cannot end the comment and start YAML of its own.
std::string YamlCommentText(const std::string& s);

}  // namespace fitcal::io
