#include "io/log_files.h"

#include <array>
#include <cmath>
#include <string_view>

#include "io/input_error.h"
#include "io/text_file.h"

namespace fitcal::io {

namespace {

constexpr int kMaxColumns = 8;

// Splits `line` at `separator` (or at runs of blanks when separator is ' ') into exactly n
// numbers; throws with the file, the line and the offending field otherwise.
void ParseRow(std::string_view line, char separator, int n, const std::string& path,
              int line_number, double* out) {
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

}  // namespace

EncoderLog ReadEncoderCsv(const std::string& path) {
  const std::string text = ReadTextFile(path);
  LineScanner lines(text);
  std::string_view line;
  if (!lines.Next(&line) || IsBlank(line)) {
    throw InputError(InputErrorKind::kEmptyFile, path, 1, "empty file (expected header 't,w_a,w_b,w_c')");
  }
  ExpectHeader(line, {"t", "w_a", "w_b", "w_c"}, path, lines.line_number());
  EncoderLog log;
  // ~30 characters a row: reserve once instead of growing.
  log.t_s.reserve(text.size() / 24 + 2);
  log.samples.reserve(text.size() / 24 + 2);
  double row[kMaxColumns];
  while (lines.Next(&line)) {
    if (IsBlank(line)) continue;
    ParseRow(line, ',', 4, path, lines.line_number(), row);
    if (!log.t_s.empty()) {
      CheckIncreasing(log.t_s.back(), row[0], path, lines.line_number());
      WheelSample sample;
      sample.dt_s = row[0] - log.t_s.back();
      sample.rate_rad_s[0] = row[1];
      sample.rate_rad_s[1] = row[2];
      sample.rate_rad_s[2] = row[3];
      log.samples.push_back(sample);
    }
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
      throw InputError(InputErrorKind::kBadHeader, path, lines.line_number(),
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
    throw InputError(InputErrorKind::kTooFewSamples, path, 0,
                     "needs at least two ground-truth samples, found " +
                         std::to_string(track.t_s.size()));
  }
  return track;
}

}  // namespace fitcal::io
