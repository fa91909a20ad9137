#include "io/tum_file.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace fitcal::io {

std::string TumText(const std::vector<double>& t_s, const std::vector<Pose2d>& poses) {
  if (t_s.size() != poses.size()) {
    throw std::invalid_argument("TumText: one time per pose");
  }
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  char line[256];
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Pose2d& p = poses[i];
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g 0 0 0 %.17g %.17g\n", t_s[i], p.x, p.y,
                  std::sin(0.5 * p.theta), std::cos(0.5 * p.theta));
    out += line;
  }
  return out;
}

std::string FileNameOf(const std::string& id) {
  static const char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (std::size_t i = 0; i < id.size(); ++i) {
    const auto c = static_cast<unsigned char>(id[i]);
    const bool kept = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                      c == '_' || c == '-' || (c == '.' && i > 0);
    if (kept) {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out.empty() ? "%" : out;  // "%" alone decodes to no id: distinct from every other
}

}  // namespace fitcal::io
