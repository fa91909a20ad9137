#include "interchange/optiodom/optiodom_format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <regex>
#include <set>
#include <string_view>

#include "io/atomic_file.h"
#include "io/input_error.h"
#include "io/staged_directory.h"
#include "io/text_file.h"
#include "odometry/parallel_for.h"
#include "io/output_guard.h"

namespace fitcal::optiodom {

namespace fs = std::filesystem;
using io::InputError;
using io::InputErrorKind;

namespace {

// Every key of the published metadata; any other is a format fitcal does not know.
const std::set<std::string> kMetadataKeys = {"type",  "ngear",  "encRes", "Li",       "Di",
                                             "Thi",   "N",      "L",      "imarkers", "gt_ti",
                                             "gt_tf", "odo_ti", "odo_tf"};

// A finite number, or InputError(path:line: `what` is not a finite number: '<field>').
double ParseNumber(const std::string& field, const std::string& path, int line,
                   const std::string& what) {
  double v = 0.0;
  bool finite = true;
  if (!io::ParseDouble(field, &v, &finite) || !finite) {
    throw InputError(InputErrorKind::kNonNumeric, path, line,
                     what + " is not a finite number: '" + field + "'");
  }
  return v;
}

}  // namespace

std::vector<double> Metadata::Values(const std::string& key, std::size_t count,
                                     bool positive) const {
  const auto it = rows.find(key);
  if (it == rows.end()) {
    throw InputError(InputErrorKind::kMissingKey, path, 0, "no row '" + key + "'");
  }
  const auto& [line, values] = it->second;
  if (values.size() != count) {
    throw InputError(InputErrorKind::kWrongColumnCount, path, line,
                     key + " needs " + std::to_string(count) + " value(s), found " +
                         std::to_string(values.size()));
  }
  for (double v : values) {
    if (positive && !(v > 0.0)) {
      throw InputError(InputErrorKind::kBadValue, path, line, key + " must be positive");
    }
  }
  return values;
}

int Metadata::NumRuns() const {
  const double n = Value("N", true);
  if (n != std::floor(n)) {
    throw InputError(InputErrorKind::kBadValue, path, rows.at("N").first,
                     "N is not a whole number");
  }
  return static_cast<int>(n);
}

Metadata ReadMetadata(const std::string& path, const std::string& expected_type) {
  const std::string text = io::ReadTextFile(path);
  io::LineScanner lines(text);
  std::string_view line;
  Metadata meta;
  meta.path = path;
  while (lines.Next(&line)) {
    if (io::Trim(line).empty()) continue;
    const std::vector<std::string> fields = io::SplitCsvFields(line);
    const std::string& key = fields[0];
    if (kMetadataKeys.count(key) == 0) {
      throw InputError(InputErrorKind::kUnknownKey, path, lines.line_number(),
                       "unknown metadata row '" + key + "'");
    }
    if (key == "type") {
      meta.type = fields.size() > 1 ? fields[1] : "";
      continue;
    }
    std::vector<double> values;
    for (std::size_t i = 1; i < fields.size(); ++i) {
      if (fields[i].empty()) continue;  // the file pads every row to the widest one
      values.push_back(
          ParseNumber(fields[i], path, lines.line_number(), key + " value " + std::to_string(i)));
    }
    meta.rows[key] = {lines.line_number(), values};
  }
  if (meta.type != expected_type) {
    throw InputError(InputErrorKind::kUnknownModel, path, 1,
                     "type '" + meta.type + "' is not " + expected_type);
  }
  return meta;
}

namespace {

// The session name of a folder: its last component ("…/circular/231220200121/" too).
std::string SessionName(const fs::path& dir) {
  return dir.filename().empty() ? dir.parent_path().filename().string() : dir.filename().string();
}

bool IsSessionFolder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / (SessionName(dir) + "_metadata.csv"), ec);
}

// A folder that is not a session: the robot's folder (diff/) or a path type's (diff/circular/),
// as a newcomer passes them. The error names the session folders below it to pass instead.
void RequireSessionFolder(const std::string& directory) {
  const fs::path dir(directory);
  if (IsSessionFolder(dir)) return;
  std::vector<std::string> below;  // path-type folders (circular, square) or sessions
  std::error_code ec;
  for (const auto& child : fs::directory_iterator(dir, ec)) {
    if (!child.is_directory(ec)) continue;
    if (IsSessionFolder(child.path())) {
      below.push_back((fs::path(directory) / "*").string());
      break;
    }
    for (const auto& grandchild : fs::directory_iterator(child.path(), ec)) {
      if (grandchild.is_directory(ec) && IsSessionFolder(grandchild.path())) {
        below.push_back((child.path() / "*").string());
        break;
      }
    }
  }
  std::sort(below.begin(), below.end());
  std::string hint = "; pass session folders, each holding <session>_metadata.csv";
  if (!below.empty()) {
    hint = "; it holds session folders: pass them, e.g. fitcal import optiodom";
    for (const std::string& b : below) hint += " " + b;
    hint += " --out <data set>";
  }
  throw InputError(
      InputErrorKind::kMissingFile, directory, 0,
      "not an OptiOdom session folder (no " + SessionName(dir) + "_metadata.csv)" + hint);
}

}  // namespace

SessionFiles ListSession(const std::string& directory) {
  const fs::path dir = fs::path(directory).lexically_normal();
  if (!fs::is_directory(dir)) {
    throw InputError(InputErrorKind::kMissingFile, directory, 0, "not a directory");
  }
  RequireSessionFolder(directory);
  const fs::path named = dir.has_filename() ? dir : dir.parent_path();
  SessionFiles files;
  files.name = named.filename().string();
  files.path_type = named.parent_path().filename().string();
  if (files.path_type.empty()) files.path_type = "path";
  files.metadata_path = (dir / (files.name + "_metadata.csv")).string();
  const std::regex run_name(files.name + "_run-([0-9]+)\\.csv");
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (std::regex_match(name, m, run_name)) {
      files.runs.emplace_back(std::stoi(m[1]), entry.path().string());
    }
  }
  std::sort(files.runs.begin(), files.runs.end());
  return files;
}

void CheckRunCount(const SessionFiles& files, int num_runs) {
  if (static_cast<int>(files.runs.size()) != num_runs) {
    throw InputError(InputErrorKind::kBadValue, files.metadata_path, 0,
                     "N = " + std::to_string(num_runs) + " runs, but the directory holds " +
                         std::to_string(files.runs.size()) + " run files");
  }
}

std::string SessionType(const std::string& directory) {
  if (fs::is_directory(directory)) RequireSessionFolder(directory);
  const fs::path dir(directory);
  const std::string path = (dir / (SessionName(dir) + "_metadata.csv")).string();
  const std::string text = io::ReadTextFile(path);
  io::LineScanner lines(text);
  std::string_view line;
  while (lines.Next(&line)) {
    const std::string_view t = io::Trim(line);
    if (t.substr(0, 5) != "type,") continue;
    const std::string_view rest = t.substr(5);
    return std::string(io::Trim(rest.substr(0, rest.find(','))));
  }
  throw InputError(InputErrorKind::kMissingKey, path, 0, "no 'type' row");
}

RunRows ReadRun(const std::string& path, int number, const std::string& column_names) {
  const std::size_t last = column_names.rfind(", ");
  const std::string short_row_hint =
      ": no " + column_names.substr(last == std::string::npos ? 0 : last + 2) + " column";
  const int encoder_columns =
      1 + static_cast<int>(std::count(column_names.begin(), column_names.end(), ','));
  const std::string text = io::ReadTextFile(path);
  io::LineScanner lines(text);
  std::string_view line;
  RunRows run;
  run.number = number;
  const std::size_t num_fields = 4 + static_cast<std::size_t>(encoder_columns);
  std::vector<double> v(num_fields);
  std::string previous_time;  // as the file writes it, for the message below
  while (lines.Next(&line)) {
    if (io::Trim(line).empty()) continue;
    const std::vector<std::string> fields = io::SplitCsvFields(line);
    if (fields.size() != num_fields) {
      throw InputError(InputErrorKind::kWrongColumnCount, path, lines.line_number(),
                       "expected " + std::to_string(num_fields) + " fields (t, x, y, theta, " +
                           column_names + "), found " + std::to_string(fields.size()) +
                           (fields.size() + 1 == num_fields ? short_row_hint : ""));
    }
    for (std::size_t i = 0; i < num_fields; ++i) {
      v[i] = ParseNumber(fields[i], path, lines.line_number(), "field " + std::to_string(i + 1));
    }
    if (!run.t_s.empty() && !(v[0] > run.t_s.back())) {
      throw InputError(InputErrorKind::kNonIncreasingTime, path, lines.line_number(),
                       "time " + fields[0] + " s is not after the previous row's " +
                           previous_time + " s");
    }
    previous_time = fields[0];
    if (run.first_line == 0) run.first_line = lines.line_number();
    run.t_s.push_back(v[0]);
    run.ground_truth.t_s.push_back(v[0]);
    run.ground_truth.world_T_robot.push_back(Pose2d{v[1], v[2], v[3]});
    // + 0.0 turns the file's "-0" into 0.
    std::vector<double>& row = run.encoder.emplace_back(v.begin() + 4, v.end());
    for (double& x : row) x += 0.0;
  }
  if (run.t_s.size() < 2) {
    throw InputError(InputErrorKind::kTooFewSamples, path, 0,
                     "needs at least two rows, found " + std::to_string(run.t_s.size()));
  }
  return run;
}

namespace {

// Rates over (t(k-1), t(k)], the reading column the mean of its ends (header).
EncoderLog RatesOf(const RunRows& run, double ticks_per_rev, int reading_column) {
  const int columns = static_cast<int>(run.encoder.front().size());
  const double rad_per_tick = 2.0 * M_PI / ticks_per_rev;
  EncoderLog log;
  log.t_s = run.t_s;
  log.samples = EncoderSamples(columns);
  std::vector<double> values(static_cast<std::size_t>(columns));
  for (std::size_t k = 1; k < run.t_s.size(); ++k) {
    const double dt = run.t_s[k] - run.t_s[k - 1];
    for (int j = 0; j < columns; ++j) {
      values[j] = j == reading_column ? 0.5 * (run.encoder[k - 1][j] + run.encoder[k][j])
                                      : rad_per_tick * run.encoder[k][j] / dt + 0.0;
    }
    log.samples.push_back(dt, values.data());
  }
  return log;
}

void AppendShortest(std::string* out, double v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);  // shortest exact
  out->append(buffer, end);
}

}  // namespace

RunLog RunLogOf(const RunRows& run, double ticks_per_rev, int reading_column) {
  RunLog log;
  log.encoders = RatesOf(run, ticks_per_rev, reading_column);
  log.ground_truth = run.ground_truth;
  log.start_pose = run.ground_truth.world_T_robot.front();
  return log;
}

std::string TicksCsv(const Robot& robot, const RunRows& run, int time_decimals,
                     int reading_column) {
  std::string out = "t";
  for (const ChannelInfo& c : robot.channels) {
    out += "," + (c.ticks_column.empty() ? c.rate_column : c.ticks_column);
  }
  out += "\n";
  out.reserve(out.size() + 40 * run.t_s.size());
  for (std::size_t k = 0; k < run.t_s.size(); ++k) {
    io::AppendFixed(&out, run.t_s[k], time_decimals);
    for (std::size_t j = 0; j < run.encoder[k].size(); ++j) {
      const bool counted_before_start = k == 0 && static_cast<int>(j) != reading_column;
      out += ',';
      io::AppendGeneral(&out, counted_before_start ? 0.0 : run.encoder[k][j], 10);
    }
    out += '\n';
  }
  return out;
}

std::string ExactRatesCsv(const Robot& robot, const RunLog& log) {
  std::string out = "t";
  for (const ChannelInfo& c : robot.channels) out += "," + c.rate_column;
  out += "\n";
  out.reserve(log.encoders.t_s.size() * 64);
  for (std::size_t k = 0; k < log.encoders.t_s.size(); ++k) {
    AppendShortest(&out, log.encoders.t_s[k]);
    for (int i = 0; i < robot.NumChannels(); ++i) {
      out += ',';
      AppendShortest(&out, k == 0 ? 0.0 : log.encoders.samples[k - 1].value[i]);
    }
    out += '\n';
  }
  return out;
}

std::string ExactGroundTruthCsv(const GroundTruthTrack& track) {
  std::string out = "t,x,y,theta\n";
  out.reserve(track.t_s.size() * 64);
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const Pose2d& pose = track.world_T_robot[k];
    for (double v : {track.t_s[k], pose.x, pose.y, pose.theta}) {
      AppendShortest(&out, v);
      out += ',';
    }
    out.back() = '\n';
  }
  return out;
}

void CheckUniqueRunIds(const std::vector<RunLog>& runs, const std::string& out) {
  std::set<std::string> ids;
  for (const RunLog& log : runs) {
    if (!ids.insert(log.id).second) {
      throw InputError(InputErrorKind::kDuplicateRunId, out, 0,
                       "run " + log.id + " is imported twice");
    }
  }
}

void WriteDataset(const std::vector<RunLog>& runs, const RobotModelInterface& model,
                  const DatasetText& text, const std::string& out, bool force,
                  const std::vector<std::string>& session_dirs) {
  io::StagedDirectory staged(out);
  const fs::path dir(staged.path());
  fs::create_directories(dir / "runs");
  std::vector<io::DatasetEntry> entries(runs.size());
  ParallelFor(runs.size(), 0, [&](std::size_t i) {
    const RunLog& log = runs[i];
    entries[i] = {log.id, log.trajectory, log.repetition, "runs/" + log.id + "_encoders.csv",
                  "runs/" + log.id + "_ground_truth.csv"};
    io::WriteFileAtomically((dir / entries[i].encoders).string(), text.encoder_csv(i));
    io::WriteFileAtomically((dir / entries[i].ground_truth).string(),
                            text.ground_truth_csv(log.ground_truth));
  });
  io::WriteFileAtomically((dir / "robot.yaml").string(),
                          text.header + model.RobotYaml(model.robot().nominal, ""));
  io::WriteFileAtomically((dir / "dataset.yaml").string(),
                          text.header + io::DatasetYaml("robot.yaml", entries));
  io::CommitDirectoryOutput(staged, out, io::kDatasetKind, force, session_dirs);
}

}  // namespace fitcal::optiodom
