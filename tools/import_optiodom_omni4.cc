#include "tools/import_optiodom_omni4.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <regex>

#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/staged_directory.h"
#include "io/text_file.h"
#include "models/omni/omni_model.h"
#include "models/pose_errors.h"
#include "odometry/parallel_for.h"
#include "tools/import_channel_order.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

namespace fs = std::filesystem;
using io::InputError;
using io::InputErrorKind;

namespace {

constexpr int kWheels = 4;
// Our wheels for the authors' 1..4 and their geometry (header): position signs of (L1/2, L2/2),
// drive direction and roller angle.
constexpr struct {
  const char* name;
  double x_sign, y_sign, drive_angle_deg, roller_angle_deg;
} kLayout[kWheels] = {
    {"fl", 1, 1, 0, -45}, {"fr", 1, -1, 180, 45}, {"rl", -1, 1, 0, 45}, {"rr", -1, -1, 180, -45}};
constexpr int kFieldsPerRow = 4 + kWheels;
// The box the fit may search. Palacin Eq. 16's (R +- 0.025 m, r +- 6.8 %, delta +- 2 deg) is too
// tight for these mecanum wheels: regressing the ground truth's steps on the counts gives a
// translation 8 % above the nominal radius (header), and a fit in Eq. 16's box rests on the r and
// delta bounds. Rollers make the effective radius of a mecanum wheel uncertain: +-15 %, +-5 deg.
constexpr double kDistanceBound_m = 0.025;
constexpr double kRadiusBound = 0.15;
constexpr double kAngleBound_deg = 5.0;

// Parses one number at p (std::from_chars: no locale, no allocation); advances p past it and one
// separator. False when the field is not a number.
bool NextNumber(const char*& p, const char* end, double* value) {
  while (p < end && (*p == ' ' || *p == '\t')) ++p;
  if (p < end && *p == '+') ++p;
  const auto [next, ec] = std::from_chars(p, end, *value);
  if (ec != std::errc() || !std::isfinite(*value)) return false;
  p = next;
  while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
  if (p < end && *p == ',') ++p;
  return true;
}

OptiOdomOmni4Metadata ReadMetadata(const std::string& path) {
  const std::string text = io::ReadTextFile(path);
  std::map<std::string, std::pair<int, std::vector<double>>> rows;  // key -> (line, values)
  std::string type;
  int line_number = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    const std::string line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_number;
    const std::size_t comma = line.find(',');
    const std::string key(io::Trim(line.substr(0, comma)));
    if (key.empty()) continue;
    std::vector<double> values;
    std::size_t at = comma == std::string::npos ? line.size() : comma + 1;
    while (at < line.size()) {
      std::size_t next = line.find(',', at);
      if (next == std::string::npos) next = line.size();
      const std::string field(io::Trim(line.substr(at, next - at)));
      at = next + 1;
      if (field.empty()) continue;  // rows are padded to the widest one
      if (key == "type") {
        type = field;
        continue;
      }
      double v = 0.0;
      const char* p = field.data();
      if (!NextNumber(p, field.data() + field.size(), &v) || p != field.data() + field.size()) {
        throw InputError(InputErrorKind::kNonNumeric, path, line_number,
                         key + " holds '" + field + "', not a finite number");
      }
      values.push_back(v);
    }
    rows[key] = {line_number, values};
  }
  if (type != "omni4") {
    throw InputError(InputErrorKind::kUnknownModel, path, 1, "type '" + type + "' is not omni4");
  }
  const auto get = [&](const std::string& key, std::size_t count) {
    const auto it = rows.find(key);
    if (it == rows.end()) throw InputError(InputErrorKind::kMissingKey, path, 0, "no row " + key);
    const std::vector<double>& v = it->second.second;
    if (v.size() != count || *std::min_element(v.begin(), v.end()) <= 0.0) {
      throw InputError(InputErrorKind::kBadValue, path, it->second.first,
                       key + " needs " + std::to_string(count) + " positive value(s)");
    }
    return v;
  };
  OptiOdomOmni4Metadata meta;
  meta.gear_ratio = get("ngear", 1)[0];
  meta.encoder_counts_per_rev = get("encRes", 1)[0];
  const std::vector<double> l = get("Li", 2);
  std::copy(l.begin(), l.end(), meta.length_m.begin());
  const std::vector<double> d = get("Di", kWheels);
  std::copy(d.begin(), d.end(), meta.diameter_m.begin());
  const double n = get("N", 1)[0];
  if (n != std::floor(n)) {
    throw InputError(InputErrorKind::kBadValue, path, rows["N"].first, "N is not a whole number");
  }
  meta.num_runs = static_cast<int>(n);
  return meta;
}

// One run file as a RunLog: wheel rates w_i = 2 pi enc_i / (counts per rev dt) over the interval
// ending at each row, ground truth from the same rows.
RunLog ReadRun(const std::string& path, const OptiOdomOmni4Metadata& meta) {
  const std::string text = io::ReadTextFile(path);
  RunLog log;
  log.encoders.samples = EncoderSamples(kWheels);
  const std::size_t rows_estimate = text.size() / 60 + 1;
  log.encoders.t_s.reserve(rows_estimate);
  log.encoders.samples.reserve(rows_estimate);
  log.ground_truth.t_s.reserve(rows_estimate);
  log.ground_truth.world_T_robot.reserve(rows_estimate);
  const double rad_per_count = 2.0 * M_PI / meta.CountsPerWheelRev();
  const char* p = text.data();
  const char* end = p + text.size();
  int line = 0;
  while (p < end) {
    ++line;
    const char* eol = std::find(p, end, '\n');
    if (eol == p || (eol == p + 1 && *p == '\r')) {
      p = eol + 1;
      continue;
    }
    double v[kFieldsPerRow];
    for (int f = 0; f < kFieldsPerRow; ++f) {
      if (p >= eol || !NextNumber(p, eol, &v[f])) {
        throw InputError(InputErrorKind::kNonNumeric, path, line,
                         "field " + std::to_string(f + 1) + " of " + std::to_string(kFieldsPerRow) +
                             " is missing or not a number");
      }
    }
    if (p != eol) {
      throw InputError(InputErrorKind::kWrongColumnCount, path, line,
                       "more than " + std::to_string(kFieldsPerRow) + " fields");
    }
    p = eol + 1;
    std::vector<double>& t = log.encoders.t_s;
    if (!t.empty()) {
      const double dt = v[0] - t.back();
      if (!(dt > 0.0)) {
        throw InputError(InputErrorKind::kNonIncreasingTime, path, line,
                         "time is not after the previous row's");
      }
      double w[kWheels];
      for (int i = 0; i < kWheels; ++i) w[i] = rad_per_count * v[4 + i] / dt + 0.0;  // "-0" -> 0
      log.encoders.samples.push_back(dt, w);
    }
    t.push_back(v[0]);
    log.ground_truth.t_s.push_back(v[0]);
    log.ground_truth.world_T_robot.push_back(Pose2d{v[1], v[2], v[3]});
  }
  if (log.encoders.t_s.size() < 2) {
    throw InputError(InputErrorKind::kTooFewSamples, path, 0, "needs at least two rows");
  }
  // The ground truth is in the robot's start frame and the robot is at rest at the start.
  log.start_pose = log.ground_truth.world_T_robot.front();
  return log;
}

// The value most sessions declare (ties: the first session's).
template <typename T>
T MostCommon(const std::vector<T>& values) {
  std::size_t best = 0, best_count = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const auto count =
        static_cast<std::size_t>(std::count(values.begin(), values.end(), values[i]));
    if (count > best_count) best = i, best_count = count;
  }
  return values[best];
}

void AppendNumber(std::string* out, double v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);  // shortest exact
  out->append(buffer, end);
}

std::string EncoderCsvText(const RunLog& log, const Robot& robot) {
  std::string out = "t";
  for (const ChannelInfo& c : robot.channels) out += "," + c.rate_column;
  out += "\n";
  out.reserve(log.encoders.t_s.size() * 64);
  for (std::size_t k = 0; k < log.encoders.t_s.size(); ++k) {
    AppendNumber(&out, log.encoders.t_s[k]);
    for (int i = 0; i < kWheels; ++i) {
      out += ',';
      AppendNumber(&out, k == 0 ? 0.0 : log.encoders.samples[k - 1].value[i]);
    }
    out += '\n';
  }
  return out;
}

std::string GroundTruthCsvText(const GroundTruthTrack& track) {
  std::string out = "t,x,y,theta\n";
  out.reserve(track.t_s.size() * 64);
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const Pose2d& pose = track.world_T_robot[k];
    for (double v : {track.t_s[k], pose.x, pose.y, pose.theta}) {
      AppendNumber(&out, v);
      out += ',';
    }
    out.back() = '\n';
  }
  return out;
}

}  // namespace

OptiOdomOmni4Session ReadOptiOdomOmni4Session(const std::string& directory) {
  const fs::path dir = fs::path(directory).lexically_normal();
  if (!fs::is_directory(dir)) {
    throw InputError(InputErrorKind::kMissingFile, directory, 0, "not a directory");
  }
  const fs::path named = dir.has_filename() ? dir : dir.parent_path();
  OptiOdomOmni4Session session;
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
    if (std::regex_match(name, m, run_name)) files.emplace_back(std::stoi(m[1]), entry.path());
  }
  std::sort(files.begin(), files.end());
  if (static_cast<int>(files.size()) != session.metadata.num_runs) {
    throw InputError(InputErrorKind::kBadValue, metadata_path, 0,
                     "N = " + std::to_string(session.metadata.num_runs) +
                         " runs, but the directory holds " + std::to_string(files.size()));
  }
  session.runs.resize(files.size());
  ParallelFor(files.size(), 0, [&](std::size_t i) {
    RunLog& log = session.runs[i];
    log = ReadRun(files[i].second, session.metadata);
    char id[96];
    std::snprintf(id, sizeof id, "%s_%s_run%02d", session.path_type.c_str(), session.name.c_str(),
                  files[i].first);
    log.id = id;
    log.trajectory = session.path_type + "_" + session.name;
    log.repetition = files[i].first;
  });
  return session;
}

RobotModelPtr OptiOdomOmni4NominalModel(const OptiOdomOmni4Metadata& metadata) {
  const double half_l1_m = 0.5 * metadata.length_m[0];
  const double half_l2_m = 0.5 * metadata.length_m[1];
  std::vector<OmniWheel> wheels;
  for (int i = 0; i < kWheels; ++i) {
    OmniWheel w;
    w.name = kLayout[i].name;
    const double x_m = kLayout[i].x_sign * half_l1_m;
    const double y_m = kLayout[i].y_sign * half_l2_m;
    w.distance_m = std::hypot(x_m, y_m);
    w.angle_rad = std::atan2(y_m, x_m);
    w.radius_m = 0.5 * metadata.diameter_m[i];
    w.drive_angle_rad = DegToRad(kLayout[i].drive_angle_deg);
    w.roller_angle_rad = DegToRad(kLayout[i].roller_angle_deg);
    wheels.push_back(w);
  }
  const auto [r_min, r_max] =
      std::minmax_element(metadata.diameter_m.begin(), metadata.diameter_m.end());
  const double distance_m = wheels[0].distance_m;
  OmniBounds bounds;
  bounds.distance_m = {distance_m - kDistanceBound_m, distance_m + kDistanceBound_m};
  bounds.radius_m = {0.5 * *r_min * (1.0 - kRadiusBound), 0.5 * *r_max * (1.0 + kRadiusBound)};
  bounds.angle_offset_rad = {DegToRad(-kAngleBound_deg), DegToRad(kAngleBound_deg)};
  return MakeOmniModel("optiodom_omni4", wheels, bounds);
}

Omni4ImportResult ImportOptiOdomOmni4(const std::vector<std::string>& session_dirs,
                                      const std::string& out_dir, bool force,
                                      bool skip_mapping_check) {
  if (session_dirs.empty()) throw std::invalid_argument("no OptiOdom omni4 session to import");
  if (const std::string refusal =
          DirectoryOutputRefusal(out_dir, kDatasetKind, force, session_dirs);
      !refusal.empty()) {
    throw std::runtime_error(refusal);
  }
  std::vector<OptiOdomOmni4Session> sessions;
  for (const std::string& dir : session_dirs) sessions.push_back(ReadOptiOdomOmni4Session(dir));
  std::vector<OptiOdomOmni4Metadata> declared;
  for (const auto& s : sessions) declared.push_back(s.metadata);
  const OptiOdomOmni4Metadata nominal = MostCommon(declared);
  Omni4ImportResult result;
  for (const auto& s : sessions) {
    if (!(s.metadata == nominal)) {
      result.notes.push_back("session " + s.name +
                             " declares other nominal lengths or diameters (perturbed starting "
                             "values, same robot): the common ones are used");
    }
  }
  const RobotModelPtr model = OptiOdomOmni4NominalModel(nominal);
  std::vector<RunLog> all_runs;
  for (const auto& s : sessions) all_runs.insert(all_runs.end(), s.runs.begin(), s.runs.end());
  result.channel_order = CheckImportedChannelOrder(all_runs, *model, skip_mapping_check);
  std::vector<const RunLog*> logs;
  for (const auto& s : sessions) {
    for (const RunLog& log : s.runs) logs.push_back(&log);
  }
  const std::vector<double>& p = model->robot().nominal;
  std::vector<double> cf(logs.size());
  std::vector<io::DatasetEntry> entries(logs.size());
  // Whole or not at all: staged beside out_dir, renamed over it once complete.
  io::StagedDirectory staged(out_dir);
  fs::create_directories(fs::path(staged.path()) / "runs");
  ParallelFor(logs.size(), 0, [&](std::size_t i) {
    const RunLog& log = *logs[i];
    const Pose2d final_pose =
        model->ReplayFinalPose(p.data(), log.encoders.samples, *log.start_pose);
    double r[3];
    FinalPoseError(final_pose, log.ground_truth.world_T_robot.back(), ResidualWeights{}, r);
    cf[i] = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    io::DatasetEntry& e = entries[i];
    e.id = log.id;
    e.trajectory = log.trajectory;
    e.repetition = log.repetition;
    e.encoders = "runs/" + e.id + "_encoders.csv";
    e.ground_truth = "runs/" + e.id + "_ground_truth.csv";
    const fs::path out(staged.path());
    io::WriteFileAtomically((out / e.encoders).string(), EncoderCsvText(log, model->robot()));
    io::WriteFileAtomically((out / e.ground_truth).string(), GroundTruthCsvText(log.ground_truth));
  });
  io::WriteFileAtomically((fs::path(staged.path()) / "robot.yaml").string(),
                          model->RobotYaml(p, ""));
  io::WriteFileAtomically((fs::path(staged.path()) / "dataset.yaml").string(),
                          io::DatasetYaml("robot.yaml", entries));
  CommitDirectoryOutput(staged, out_dir, kDatasetKind, force, session_dirs);
  result.num_sessions = static_cast<int>(sessions.size());
  result.num_runs = static_cast<int>(logs.size());
  for (double c : cf) result.nominal_mean_cf += c / static_cast<double>(cf.size());
  return result;
}

}  // namespace fitcal::tools
