#include "tools/import_optiodom_tricycle.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <stdexcept>

#include "fit/final_pose_errors.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/staged_directory.h"
#include "io/text_file.h"
#include "models/tricycle/tricycle_checks.h"
#include "models/tricycle/tricycle_model.h"
#include "odometry/aligned_run.h"
#include "tools/import_channel_order.h"
#include "tools/miswired_error.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

namespace fs = std::filesystem;
using io::InputError;
using io::InputErrorKind;
using K = TricycleKinematics;

namespace {

constexpr int kRunFields = 6;  // t, x, y, theta, ticks, steering
// Every key of the published metadata; any other is a format fitcal does not know.
const std::set<std::string> kMetadataKeys = {"type",  "ngear",  "encRes", "Li",       "Di",
                                             "Thi",   "N",      "L",      "imarkers", "gt_ti",
                                             "gt_tf", "odo_ti", "odo_tf"};

std::vector<std::string> SplitCsv(std::string_view line) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t end = line.find(',', pos);
    out.emplace_back(io::Trim(line.substr(pos, end == std::string_view::npos ? end : end - pos)));
    if (end == std::string_view::npos) break;
    pos = end + 1;
  }
  return out;
}

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

// key -> (line, numbers); empty fields (the file pads rows to the widest) are skipped.
using MetadataRows = std::map<std::string, std::pair<int, std::vector<double>>>;

MetadataRows ReadMetadataRows(const std::string& path, std::string* type) {
  const std::string text = io::ReadTextFile(path);
  io::LineScanner lines(text);
  std::string_view line;
  MetadataRows rows;
  while (lines.Next(&line)) {
    if (io::Trim(line).empty()) continue;
    const std::vector<std::string> fields = SplitCsv(line);
    const std::string& key = fields[0];
    if (kMetadataKeys.count(key) == 0) {
      throw InputError(InputErrorKind::kUnknownKey, path, lines.line_number(),
                       "unknown metadata row '" + key + "'");
    }
    if (key == "type") {
      *type = fields.size() > 1 ? fields[1] : "";
      continue;
    }
    std::vector<double> values;
    for (std::size_t i = 1; i < fields.size(); ++i) {
      if (fields[i].empty()) continue;
      values.push_back(
          ParseNumber(fields[i], path, lines.line_number(), key + " value " + std::to_string(i)));
    }
    rows[key] = {lines.line_number(), values};
  }
  return rows;
}

// The single value of row `key`, positive unless it may be any number.
double MetadataValue(const MetadataRows& rows, const std::string& key, const std::string& path,
                     bool positive) {
  const auto it = rows.find(key);
  if (it == rows.end()) {
    throw InputError(InputErrorKind::kMissingKey, path, 0, "no row '" + key + "'");
  }
  const auto& [line, values] = it->second;
  if (values.size() != 1) {
    throw InputError(InputErrorKind::kWrongColumnCount, path, line,
                     key + " needs 1 value, found " + std::to_string(values.size()));
  }
  if (positive && !(values[0] > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, line, key + " must be positive");
  }
  return values[0];
}

OptiOdomTricycleMetadata ReadMetadata(const std::string& path) {
  std::string type;
  const MetadataRows rows = ReadMetadataRows(path, &type);
  if (type != "tricyc") {
    throw InputError(InputErrorKind::kUnknownModel, path, 1,
                     "type '" + type + "' is not tricyc (this importer reads tricycles)");
  }
  OptiOdomTricycleMetadata meta;
  meta.gear_ratio = MetadataValue(rows, "ngear", path, true);
  meta.encoder_counts_per_rev = MetadataValue(rows, "encRes", path, true);
  meta.wheelbase_m = MetadataValue(rows, "Li", path, true);
  meta.diameter_m = MetadataValue(rows, "Di", path, true);
  meta.steering_offset_rad = MetadataValue(rows, "Thi", path, false);
  const double n = MetadataValue(rows, "N", path, true);
  if (n != std::floor(n)) {
    throw InputError(InputErrorKind::kBadValue, path, rows.at("N").first,
                     "N is not a whole number");
  }
  meta.num_runs = static_cast<int>(n);
  return meta;
}

OptiOdomTricycleRun ReadRun(const std::string& path, int number) {
  const std::string text = io::ReadTextFile(path);
  io::LineScanner lines(text);
  std::string_view line;
  OptiOdomTricycleRun run;
  run.number = number;
  int first_line = 0;
  while (lines.Next(&line)) {
    if (io::Trim(line).empty()) continue;
    const std::vector<std::string> fields = SplitCsv(line);
    if (fields.size() != kRunFields) {
      throw InputError(InputErrorKind::kWrongColumnCount, path, lines.line_number(),
                       "expected 6 fields (t, x, y, theta, ticks, steering), found " +
                           std::to_string(fields.size()) +
                           (fields.size() == kRunFields - 1 ? ": no steering column" : ""));
    }
    double v[kRunFields];
    for (int i = 0; i < kRunFields; ++i) {
      v[i] = ParseNumber(fields[i], path, lines.line_number(), "field " + std::to_string(i + 1));
    }
    if (!run.t_s.empty() && !(v[0] > run.t_s.back())) {
      throw InputError(InputErrorKind::kNonIncreasingTime, path, lines.line_number(),
                       "time " + fields[0] + " s is not after the previous row's");
    }
    if (first_line == 0) first_line = lines.line_number();
    run.t_s.push_back(v[0]);
    run.ground_truth.t_s.push_back(v[0]);
    run.ground_truth.world_T_robot.push_back(Pose2d{v[1], v[2], v[3]});
    run.ticks.push_back(v[4] + 0.0);  // + 0.0 turns "-0" into 0
    run.steering_rad.push_back(v[5] + 0.0);
  }
  if (run.t_s.size() < 2) {
    throw InputError(InputErrorKind::kTooFewSamples, path, 0,
                     "needs at least two rows, found " + std::to_string(run.t_s.size()));
  }
  tricycle::CheckSteeringReadings(run.steering_rad, path, first_line);
  return run;
}

}  // namespace

OptiOdomTricycleSession ReadOptiOdomTricycleSession(const std::string& directory) {
  const fs::path dir = fs::path(directory).lexically_normal();
  if (!fs::is_directory(dir)) {
    throw InputError(InputErrorKind::kMissingFile, directory, 0, "not a directory");
  }
  const fs::path named = dir.has_filename() ? dir : dir.parent_path();
  OptiOdomTricycleSession session;
  session.name = named.filename().string();
  session.path_type = named.parent_path().filename().string();
  if (session.path_type.empty()) session.path_type = "path";
  const std::string metadata_path = (dir / (session.name + "_metadata.csv")).string();
  session.metadata = ReadMetadata(metadata_path);

  const std::regex run_name(session.name + "_run-([0-9]+)\\.csv");
  std::vector<std::pair<int, std::string>> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (std::regex_match(name, m, run_name)) {
      files.emplace_back(std::stoi(m[1]), entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  if (static_cast<int>(files.size()) != session.metadata.num_runs) {
    throw InputError(InputErrorKind::kBadValue, metadata_path, 0,
                     "N = " + std::to_string(session.metadata.num_runs) +
                         " runs, but the directory holds " + std::to_string(files.size()) +
                         " run files");
  }
  for (const auto& [number, path] : files) session.runs.push_back(ReadRun(path, number));
  return session;
}

RobotModelPtr OptiOdomTricycleNominalModel(const OptiOdomTricycleMetadata& metadata) {
  Robot robot = TricycleRobotDescription("optiodom_tricycle", "traction");
  const double radius_m = 0.5 * metadata.diameter_m;
  robot.nominal.resize(K::kNumParameters);
  robot.nominal[K::kRadiusIndex] = radius_m;
  robot.nominal[K::kWheelbaseIndex] = metadata.wheelbase_m;
  robot.nominal[K::kSteeringOffsetIndex] = metadata.steering_offset_rad;
  robot.bounds.resize(K::kNumParameters);
  robot.bounds[K::kRadiusIndex] = {0.9 * radius_m, 1.1 * radius_m};
  robot.bounds[K::kWheelbaseIndex] = {0.85 * metadata.wheelbase_m, 1.15 * metadata.wheelbase_m};
  robot.bounds[K::kSteeringOffsetIndex] = {metadata.steering_offset_rad - DegToRad(10.0),
                                           metadata.steering_offset_rad + DegToRad(10.0)};
  robot.encoder = EncoderTicks{metadata.TicksPerWheelRev(), false};
  return std::make_shared<TricycleModel>(std::move(robot));
}

RunLog OptiOdomTricycleRunLog(const OptiOdomTricycleSession& session,
                              const OptiOdomTricycleRun& run, int session_repetition) {
  RunLog log;
  char id[96];
  std::snprintf(id, sizeof id, "%s_%s_run%02d", session.path_type.c_str(), session.name.c_str(),
                run.number);
  log.id = id;
  const double turn_rad =
      run.ground_truth.world_T_robot.back().theta - run.ground_truth.world_T_robot.front().theta;
  log.trajectory = session.path_type + (turn_rad < 0.0 ? "_cw" : "_ccw");
  log.repetition = session_repetition;
  const double rad_per_tick = 2.0 * M_PI / session.metadata.TicksPerWheelRev();
  log.encoders.t_s = run.t_s;
  log.encoders.samples = EncoderSamples(K::kNumChannels);
  for (std::size_t k = 1; k < run.t_s.size(); ++k) {
    const double dt = run.t_s[k] - run.t_s[k - 1];
    double values[K::kNumChannels];
    values[K::kTractionChannel] = rad_per_tick * run.ticks[k] / dt;
    values[K::kSteeringChannel] = 0.5 * (run.steering_rad[k - 1] + run.steering_rad[k]);
    log.encoders.samples.push_back(dt, values);
  }
  log.ground_truth = run.ground_truth;
  log.start_pose = run.ground_truth.world_T_robot.front();  // at rest, the start frame
  return log;
}

namespace {

// Encoder CSV as the recorder logged it: ticks per interval (row 0 zero: counts before the
// start are not part of the run) and the steering reading at t.
std::string TricycleEncoderCsv(const OptiOdomTricycleRun& run) {
  std::string out = "t,ticks_traction,steering\n";
  char line[128];
  for (std::size_t k = 0; k < run.t_s.size(); ++k) {
    const double ticks = k == 0 ? 0.0 : run.ticks[k];
    const int n = std::snprintf(line, sizeof line, "%.6f,%.10g,%.10g\n", run.t_s[k], ticks,
                                run.steering_rad[k]);
    out.append(line, static_cast<std::size_t>(n));
  }
  return out;
}

void CheckOneRobot(const std::vector<OptiOdomTricycleSession>& sessions) {
  const OptiOdomTricycleMetadata& first = sessions.front().metadata;
  for (const OptiOdomTricycleSession& s : sessions) {
    const OptiOdomTricycleMetadata& m = s.metadata;
    if (m.gear_ratio != first.gear_ratio ||
        m.encoder_counts_per_rev != first.encoder_counts_per_rev ||
        m.wheelbase_m != first.wheelbase_m || m.diameter_m != first.diameter_m ||
        m.steering_offset_rad != first.steering_offset_rad) {
      throw InputError(InputErrorKind::kBadValue, s.name + "_metadata.csv", 0,
                       "robot geometry or encoders differ from session " + sessions.front().name +
                           "'s; import sessions of one robot together");
    }
  }
}

// Repetition of each session: its place among the sessions of its path type, by name (the
// names are timestamps, so 1 = earliest).
std::vector<int> SessionRepetitions(const std::vector<OptiOdomTricycleSession>& sessions) {
  std::vector<int> repetition(sessions.size());
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    int earlier = 0;
    for (const OptiOdomTricycleSession& other : sessions) {
      earlier += other.path_type == sessions[i].path_type && other.name < sessions[i].name;
    }
    repetition[i] = earlier + 1;
  }
  return repetition;
}

}  // namespace

ImportOptiOdomTricycleSummary ImportOptiOdomTricycle(const std::vector<std::string>& sessions,
                                                     const std::string& out,
                                                     const ImportOptiOdomTricycleOptions& options) {
  if (sessions.empty()) throw std::invalid_argument("import needs at least one session");
  if (const std::string refusal =
          DirectoryOutputRefusal(out, kDatasetKind, options.force, sessions);
      !refusal.empty()) {
    throw std::runtime_error(refusal);
  }
  // Read and check everything before writing anything.
  std::vector<OptiOdomTricycleSession> read;
  for (const std::string& dir : sessions) read.push_back(ReadOptiOdomTricycleSession(dir));
  CheckOneRobot(read);
  const RobotModelPtr model = OptiOdomTricycleNominalModel(read.front().metadata);
  const std::vector<int> repetition = SessionRepetitions(read);

  ImportOptiOdomTricycleSummary summary;
  summary.num_sessions = static_cast<int>(read.size());
  std::vector<const OptiOdomTricycleRun*> sources;
  std::set<std::string> ids;
  for (std::size_t i = 0; i < read.size(); ++i) {
    for (const OptiOdomTricycleRun& run : read[i].runs) {
      summary.runs.push_back(OptiOdomTricycleRunLog(read[i], run, repetition[i]));
      sources.push_back(&run);
      if (!ids.insert(summary.runs.back().id).second) {
        throw InputError(InputErrorKind::kDuplicateRunId, out, 0,
                         "run " + summary.runs.back().id + " is imported twice");
      }
    }
  }
  summary.channel_order = CheckImportedChannelOrder(summary.runs, *model, options.skip_sign_check);
  const FinalPoseErrors nominal =
      EvaluateFinalPoseErrors(*model, model->robot().nominal, AlignRuns(summary.runs), 1);
  summary.nominal_final_error = nominal.per_run_cf;
  summary.nominal_cf = nominal.cf;

  // Whole or not at all: staged beside `out`, renamed over it once complete.
  io::StagedDirectory staged(out);
  const fs::path dir(staged.path());
  fs::create_directories(dir / "runs");
  std::vector<io::DatasetEntry> entries;
  for (std::size_t i = 0; i < summary.runs.size(); ++i) {
    const RunLog& log = summary.runs[i];
    io::DatasetEntry e{log.id, log.trajectory, log.repetition, "runs/" + log.id + "_encoders.csv",
                       "runs/" + log.id + "_ground_truth.csv"};
    io::WriteFileAtomically((dir / e.encoders).string(), TricycleEncoderCsv(*sources[i]));
    io::WriteFileAtomically((dir / e.ground_truth).string(), io::GroundTruthCsv(log.ground_truth));
    entries.push_back(e);
  }
  io::WriteFileAtomically((dir / "robot.yaml").string(),
                          model->RobotYaml(model->robot().nominal, ""));
  io::WriteFileAtomically((dir / "dataset.yaml").string(), io::DatasetYaml("robot.yaml", entries));
  CommitDirectoryOutput(staged, out, kDatasetKind, options.force, sessions);
  return summary;
}

}  // namespace fitcal::tools
