#include "io/log_files.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "io/input_error.h"
#include "io/text_file.h"

namespace fitcal::io {

namespace {

constexpr int kMaxColumns = 8;

// Splits `line` at `separator` (or at runs of blanks when separator is ' ') into exactly n
// numbers; throws with the file, the line and the offending field otherwise.
// The common case of a comma-separated row of n finite numbers, parsed in one pass without
// splitting (the loaders' hot loop). Accepts exactly what the general path below accepts; returns
// false on anything unusual, and the general path then finds and reports the problem.
bool ParseCommaRowFast(std::string_view line, int n, double* out) {
  const char* p = line.data();
  const char* const end = p + line.size();
  for (int i = 0; i < n; ++i) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    if (p < end && *p == '+') ++p;
    const auto result = std::from_chars(p, end, out[i]);
    if (result.ec != std::errc() || result.ptr == p || !std::isfinite(out[i])) return false;
    p = result.ptr;
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    if (i + 1 < n) {
      if (p == end || *p != ',') return false;
      ++p;
    }
  }
  return p == end;
}

void ParseRow(std::string_view line, char separator, int n, const std::string& path,
              int line_number, double* out) {
  if (separator == ',' && ParseCommaRowFast(line, n, out)) return;
  int count = 0;
  std::size_t pos = 0;
  while (pos <= line.size()) {
    std::size_t end;
    if (separator == ' ') {
      while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t')) ++pos;
      if (pos >= line.size()) break;
      end = pos;
      while (end < line.size() && line[end] != ' ' && line[end] != '\t') ++end;
    } else {
      end = line.find(separator, pos);
      if (end == std::string_view::npos) end = line.size();
    }
    const std::string_view field = line.substr(pos, end - pos);
    if (count >= n) {
      throw InputError(InputErrorKind::kWrongColumnCount, path, line_number,
                       "expected " + std::to_string(n) + " fields, found more");
    }
    bool finite = true;
    if (!ParseDouble(field, &out[count], &finite)) {
      throw InputError(InputErrorKind::kNonNumeric, path, line_number,
                       "field " + std::to_string(count + 1) + " is not a number: '" +
                           std::string(Trim(field)) + "'");
    }
    if (!finite) {
      throw InputError(InputErrorKind::kNonFinite, path, line_number,
                       "field " + std::to_string(count + 1) + " is not finite: '" +
                           std::string(Trim(field)) + "'");
    }
    ++count;
    pos = end + 1;
  }
  if (count != n) {
    throw InputError(InputErrorKind::kWrongColumnCount, path, line_number,
                     "expected " + std::to_string(n) + " fields, found " + std::to_string(count));
  }
}

void ExpectHeader(std::string_view line, const std::array<std::string_view, 4>& names,
                  const std::string& path, int line_number) {
  std::string expected;
  for (const auto& name : names) expected += (expected.empty() ? "" : ",") + std::string(name);
  std::size_t pos = 0;
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::size_t end = line.find(',', pos);
    if (end == std::string_view::npos) end = line.size();
    const bool last = i + 1 == names.size();
    if (Trim(line.substr(pos, end - pos)) != names[i] || (last != (end == line.size()))) {
      throw InputError(InputErrorKind::kBadHeader, path, line_number,
                       "header must be '" + expected + "', found '" + std::string(line) + "'");
    }
    pos = end + 1;
  }
}

void CheckIncreasing(double previous, double t, const std::string& path, int line_number) {
  if (!(t > previous)) {
    throw InputError(InputErrorKind::kNonIncreasingTime, path, line_number,
                     "time " + std::to_string(t) + " s is not after the previous row's " +
                         std::to_string(previous) + " s");
  }
}

bool IsBlank(std::string_view line) { return Trim(line).empty(); }

// Upper bound on the data rows of a text: its number of lines.
std::size_t CountLines(std::string_view text) {
  std::size_t n = 1;
  const char* p = text.data();
  const char* end = p + text.size();
  while ((p = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)))) !=
         nullptr) {
    ++n;
    ++p;
  }
  return n;
}

}  // namespace

EncoderLog ReadEncoderCsv(const std::string& path, const std::optional<EncoderTicks>& ticks) {
  const std::string text = ReadTextFile(path);
  LineScanner lines(text);
  std::string_view line;
  if (!lines.Next(&line) || IsBlank(line)) {
    throw InputError(InputErrorKind::kEmptyFile, path, 1,
                     "empty file (expected header 't,w_a,w_b,w_c' or 't,ticks_a,ticks_b,ticks_c')");
  }
  const bool in_ticks = Trim(line).substr(0, 8) == "t,ticks_";
  if (in_ticks) {
    ExpectHeader(line, {"t", "ticks_a", "ticks_b", "ticks_c"}, path, lines.line_number());
    if (!ticks || !(ticks->ticks_per_rev > 0.0)) {
      throw InputError(InputErrorKind::kBadHeader, path, lines.line_number(),
                       "encoder ticks need 'encoder: {ticks_per_rev: N, cumulative: false|true}' "
                       "in the robot YAML");
    }
  } else {
    ExpectHeader(line, {"t", "w_a", "w_b", "w_c"}, path, lines.line_number());
  }
  const double rad_per_tick = in_ticks ? 2.0 * M_PI / ticks->ticks_per_rev : 0.0;
  const bool cumulative = in_ticks && ticks->cumulative;
  double previous_count[3] = {0.0, 0.0, 0.0};
  EncoderLog log;
  // Reserve exactly once (one row per line; memchr-speed count) so that a large log holds 40
  // bytes per sample (t + a 32-byte sample row) and is never copied while growing.
  const std::size_t rows = CountLines(text);
  log.t_s.reserve(rows);
  log.samples.reserve(rows);
  double row[kMaxColumns];
  while (lines.Next(&line)) {
    if (IsBlank(line)) continue;
    ParseRow(line, ',', 4, path, lines.line_number(), row);
    if (!log.t_s.empty()) {
      CheckIncreasing(log.t_s.back(), row[0], path, lines.line_number());
      const double dt = row[0] - log.t_s.back();
      double values[3];
      for (int i = 0; i < 3; ++i) {
        if (!in_ticks) {
          values[i] = row[1 + i];
        } else {
          const double dticks = cumulative ? row[1 + i] - previous_count[i] : row[1 + i];
          values[i] = rad_per_tick * dticks / dt;
        }
      }
      log.samples.push_back(dt, values);
    }
    for (int i = 0; i < 3; ++i) previous_count[i] = row[1 + i];
    log.t_s.push_back(row[0]);
  }
  if (log.t_s.size() < 2) {
    throw InputError(InputErrorKind::kTooFewSamples, path, 0,
                     "needs at least two rows (a start time and one interval), found " +
                         std::to_string(log.t_s.size()));
  }
  return log;
}

GroundTruthTrack ReadGroundTruth(const std::string& path) {
  const std::string text = ReadTextFile(path);
  LineScanner lines(text);
  std::string_view line;
  // The first non-blank, non-comment line decides the format.
  bool tum = false;
  bool found = false;
  while (lines.Next(&line)) {
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') {
      if (!t.empty()) tum = true;  // only TUM files carry '#' comments
      continue;
    }
    found = true;
    if (t.size() >= 2 && t[0] == 't' && t[1] == ',') {
      ExpectHeader(line, {"t", "x", "y", "theta"}, path, lines.line_number());
      tum = false;
    } else if (t.find(',') == std::string_view::npos) {
      tum = true;
    } else {
      throw InputError(
          InputErrorKind::kBadHeader, path, lines.line_number(),
          "header must be 't,x,y,theta' (or a TUM file 't x y z qx qy qz qw'), found '" +
              std::string(line) + "'");
    }
    break;
  }
  if (!found) {
    throw InputError(InputErrorKind::kEmptyFile, path, 1,
                     "empty file (expected header 't,x,y,theta' or TUM rows)");
  }
  GroundTruthTrack track;
  double row[kMaxColumns];
  auto add = [&](double t, const Pose2d& pose) {
    if (!track.t_s.empty()) CheckIncreasing(track.t_s.back(), t, path, lines.line_number());
    track.t_s.push_back(t);
    track.world_T_robot.push_back(pose);
  };
  if (tum) {
    // The line that decided the format is a data row.
    do {
      const std::string_view t = Trim(line);
      if (t.empty() || t.front() == '#') continue;
      ParseRow(line, ' ', 8, path, lines.line_number(), row);
      const double qx = row[4], qy = row[5], qz = row[6], qw = row[7];
      const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
      if (!(norm > 0.5 && norm < 1.5)) {
        throw InputError(InputErrorKind::kBadValue, path, lines.line_number(),
                         "quaternion is not a unit quaternion (norm " + std::to_string(norm) + ")");
      }
      const double yaw = std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
      add(row[0], Pose2d{row[1], row[2], yaw});
    } while (lines.Next(&line));
  } else {
    while (lines.Next(&line)) {
      if (IsBlank(line)) continue;
      ParseRow(line, ',', 4, path, lines.line_number(), row);
      add(row[0], Pose2d{row[1], row[2], row[3]});
    }
  }
  if (track.t_s.size() < 2) {
    throw InputError(
        InputErrorKind::kTooFewSamples, path, 0,
        "needs at least two ground-truth samples, found " + std::to_string(track.t_s.size()));
  }
  return track;
}

}  // namespace fitcal::io
