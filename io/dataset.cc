#include "io/dataset.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <string_view>

#include "io/input_error.h"
#include "io/input_registry.h"
#include "io/log_files.h"
#include "io/yaml_reader.h"
#include "io/yaml_text.h"
#include "odometry/parallel_for.h"
#include "odometry/text_format.h"

namespace fitcal::io {

namespace fs = std::filesystem;

namespace {

// Whether `dir` or a folder up to two levels below it holds a file whose name ends with `suffix`
// (recordings a newcomer passes as --logs before importing them).
bool HoldsFileEndingIn(const fs::path& dir, const std::string& suffix, int depth = 2) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file(ec) && name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      return true;
    }
    if (depth > 0 && entry.is_directory(ec) && HoldsFileEndingIn(entry.path(), suffix, depth - 1)) {
      return true;
    }
  }
  return false;
}

// What to do about a --logs directory without dataset.yaml: import the recordings it holds first.
std::string NoDatasetHint(const fs::path& dir) {
  if (HoldsFileEndingIn(dir, "_metadata.csv")) {
    return "these look like OptiOdom recordings: import them first (fitcal import optiodom "
           "<session folders> --out <data set>) and pass the data set as --logs";
  }
  if (HoldsFileEndingIn(dir, ".db3", 0) || HoldsFileEndingIn(dir, ".mcap", 0)) {
    return "this looks like a ROS 2 bag: import it first (fitcal import rosbag2 <bag> --robot "
           "<robot YAML> --out <data set>) and pass the data set as --logs";
  }
  return "--logs takes a data set directory: dataset.yaml, a robot YAML and the runs' logs "
         "(docs/dataset-format.md)";
}

// Resolves a path from dataset.yaml against the data set directory, refusing absolute paths and
// '..' escapes unless allowed: a data set is a self-contained directory.
std::string ResolvePath(const std::string& directory, const std::string& relative,
                        const DatasetOptions& options, const std::string& yaml_path,
                        const YAML::Node& node) {
  const fs::path p(relative);
  if (!options.allow_paths_outside) {
    if (p.is_absolute()) {
      throw InputError(InputErrorKind::kBadPath, yaml_path, LineOf(node),
                       "path '" + relative + "' is absolute; paths are relative to the data set "
                                             "directory (--allow-outside-paths to permit)");
    }
    for (const auto& part : p) {
      if (part == "..") {
        throw InputError(InputErrorKind::kBadPath, yaml_path, LineOf(node),
                         "path '" + relative +
                             "' leaves the data set directory (--allow-outside-paths to permit)");
      }
    }
  }
  return p.is_absolute() ? p.string() : (fs::path(directory) / p).string();
}

// The file's identity for duplicate detection: the canonical path (symlinks and "a/../a"
// resolved) when the OS can give it, the normalised text otherwise.
std::string FileIdentity(const std::string& path) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  return ec ? fs::path(path).lexically_normal().string() : canonical.string();
}

// One file listed for two runs (a copy-paste slip, or a data set that lists one pair 100,000
// times) would count one recording as several: refused before anything is read.
class SameFileCheck {
 public:
  explicit SameFileCheck(std::string yaml_path) : yaml_path_(std::move(yaml_path)) {}
  void Add(const std::string& path, const char* role, const DatasetIndexEntry& entry,
           const YAML::Node& node) {
    const auto [it, fresh] = seen_.emplace(FileIdentity(path), Use{entry.id, LineOf(node)});
    if (fresh) return;
    throw InputError(InputErrorKind::kDuplicateRun, yaml_path_, LineOf(node),
                     "run '" + entry.id + "' lists the " + role + " file '" + path + "' of run '" +
                         it->second.id + "' (line " + std::to_string(it->second.line) +
                         "): a duplicated run");
  }

 private:
  struct Use {
    std::string id;
    int line = 0;
  };
  std::string yaml_path_;
  std::map<std::string, Use> seen_;
};

}  // namespace

DatasetIndex ReadDatasetIndex(const std::string& directory, const DatasetOptions& options) {
  DatasetIndex index;
  index.directory = directory;
  index.yaml_path = (fs::path(directory) / "dataset.yaml").string();
  const std::string& yaml_path = index.yaml_path;
  // error_code overloads: a path the OS refuses (too long, no permission) is bad input, not a
  // std::filesystem_error escaping the loader (found by tests/fuzz, dataset_yaml).
  std::error_code fs_error;
  if (!fs::is_directory(directory, fs_error)) {
    throw InputError(InputErrorKind::kMissingFile, directory, 0, "not a directory");
  }
  RegisterInput(directory);  // no output inside the data set (io/input_registry.h)
  if (!fs::exists(yaml_path, fs_error)) {
    throw InputError(InputErrorKind::kMissingFile, yaml_path, 0,
                     "no such file: not a data set; " + NoDatasetHint(directory));
  }
  const YAML::Node root = LoadYamlFile(yaml_path);
  YamlMap top(root, yaml_path, "dataset");
  const YAML::Node robot_node = top.Required("robot");
  index.robot_path = ResolvePath(directory, YamlString(robot_node, yaml_path, "dataset.robot"),
                                 options, yaml_path, robot_node);
  if (!fs::exists(index.robot_path, fs_error)) {
    throw InputError(InputErrorKind::kMissingFile, yaml_path, LineOf(robot_node),
                     "robot file '" + index.robot_path + "' does not exist");
  }
  top.Optional("name");
  top.Optional("description");
  const YAML::Node runs = top.Required("runs");
  ExpectYamlType(runs, YAML::NodeType::Sequence, yaml_path, "dataset.runs");
  if (runs.size() == 0) {
    throw InputError(InputErrorKind::kTooFewSamples, yaml_path, LineOf(runs), "no runs listed");
  }
  top.RejectUnread();

  index.runs.resize(runs.size());
  std::set<std::string> ids;
  SameFileCheck same_file(yaml_path);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const YAML::Node node = runs[i];
    YamlMap run(node, yaml_path, "run " + std::to_string(i + 1));
    DatasetIndexEntry& entry = index.runs[i];
    entry.id = run.Name("id");
    if (!ids.insert(entry.id).second) {
      throw InputError(InputErrorKind::kDuplicateRunId, yaml_path, LineOf(node),
                       "run id '" + entry.id + "' is used twice");
    }
    entry.trajectory = run.Name("trajectory");
    entry.repetition = run.Int("repetition");
    if (entry.repetition < 0) {
      throw InputError(InputErrorKind::kBadValue, yaml_path, LineOf(node["repetition"]),
                       "run '" + entry.id + "': repetition " + std::to_string(entry.repetition) +
                           " is negative; repetitions count 0, 1, 2, ...");
    }
    entry.encoders_path =
        ResolvePath(directory, run.String("encoders"), options, yaml_path, node["encoders"]);
    entry.ground_truth_path = ResolvePath(directory, run.String("ground_truth"), options, yaml_path,
                                          node["ground_truth"]);
    same_file.Add(entry.encoders_path, "encoder", entry, node);
    same_file.Add(entry.ground_truth_path, "ground-truth", entry, node);
    const YAML::Node start = run.Optional("start_pose");
    if (start) {
      ExpectYamlType(start, YAML::NodeType::Sequence, yaml_path, "start_pose");
      if (start.size() != 3) {
        throw InputError(InputErrorKind::kBadValue, yaml_path, LineOf(start),
                         "start_pose must be [x, y, theta] (m, m, rad)");
      }
      entry.start_pose = Pose2d{YamlDouble(start[0], yaml_path, "start_pose x"),
                                YamlDouble(start[1], yaml_path, "start_pose y"),
                                YamlDouble(start[2], yaml_path, "start_pose theta")};
      // As a ground-truth sample's (io/log_files.cc): no map is larger.
      if (!(std::hypot(entry.start_pose->x, entry.start_pose->y) <= 1e7)) {
        throw InputError(InputErrorKind::kImplausibleValue, yaml_path, LineOf(start),
                         "start_pose position is beyond any map (limit 1e7 m; wrong units or a "
                         "corrupted field?)");
      }
      // A heading beyond a full turn is degrees written where radians are meant.
      if (std::abs(entry.start_pose->theta) > 2.0 * M_PI + 1e-9) {
        throw InputError(InputErrorKind::kImplausibleValue, yaml_path, LineOf(start[2]),
                         "start_pose theta " + start[2].Scalar() +
                             " is beyond a full turn in rad: degrees? theta is in radians");
      }
    }
    run.RejectUnread();
  }
  return index;
}

namespace {

// Throws kNoOverlap when the ground truth does not share time with [enc_begin_s, enc_end_s].
void CheckGroundTruthOverlap(const GroundTruthTrack& ground_truth, double enc_begin_s,
                             double enc_end_s, const std::string& ground_truth_path) {
  const double gt_begin = ground_truth.t_s.front(), gt_end = ground_truth.t_s.back();
  if (gt_end <= enc_begin_s || gt_begin >= enc_end_s) {
    std::ostringstream msg;
    msg << "ground truth [" << gt_begin << ", " << gt_end << "] s does not overlap the encoder "
        << "span [" << enc_begin_s << ", " << enc_end_s << "] s (different clocks or wrong file?)";
    throw InputError(InputErrorKind::kNoOverlap, ground_truth_path, 0, msg.str());
  }
  // A ground truth that spans the encoder log many times over and puts at most one sample inside
  // it is on another time scale (ms or us where s are meant) or another run's: the run's poses
  // would be interpolated between samples far outside it, and a closed loop's ends would agree by
  // accident (one run's times in ms fitted without a word). Start and end poses alone, or a sparse
  // ground truth of about the run's span, are not this.
  const std::size_t inside = static_cast<std::size_t>(
      std::count_if(ground_truth.t_s.begin(), ground_truth.t_s.end(),
                    [&](double t) { return t >= enc_begin_s && t <= enc_end_s; }));
  constexpr double kMaxSpanRatio = 10.0;
  if (ground_truth.t_s.size() >= 3 && inside < 2 &&
      gt_end - gt_begin > kMaxSpanRatio * (enc_end_s - enc_begin_s)) {
    std::ostringstream msg;
    msg << "only " << inside << " of the ground truth's " << ground_truth.t_s.size()
        << " samples lies inside the encoder span [" << enc_begin_s << ", " << enc_end_s
        << "] s, which the ground truth's [" << gt_begin << ", " << gt_end << "] s spans "
        << std::setprecision(3) << (gt_end - gt_begin) / (enc_end_s - enc_begin_s)
        << " times over: times in ms or us instead of s, or another run's file?";
    throw InputError(InputErrorKind::kNoOverlap, ground_truth_path, 0, msg.str());
  }
}

// Bytes of a vector of doubles, for hashing and comparing logs exactly.
template <typename T>
std::string_view Bytes(const std::vector<T>& v) {
  return {reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T)};
}

std::size_t LogHash(const std::string_view& a, const std::string_view& b) {
  const std::hash<std::string_view> hash;
  return hash(a) ^ (hash(b) * 0x9e3779b97f4a7c15ULL);
}

// Two runs whose encoder logs (or ground-truth tracks) are equal to the bit are one recording
// copied: no two drives produce the same timestamps and rates. Counted twice they would weigh one
// run double and, when all are copies, leave nine parameters to three residuals; the copy is
// named as what it is, not blamed on the wiring.
void RejectCopiedRuns(const DatasetIndex& index, const std::vector<RunLog>& runs) {
  for (int part = 0; part < 2; ++part) {
    std::unordered_multimap<std::size_t, std::size_t> seen;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const RunLog& r = runs[i];
      const std::string_view a = part == 0 ? Bytes(r.encoders.t_s) : Bytes(r.ground_truth.t_s);
      const std::string_view b =
          part == 0 ? std::string_view(reinterpret_cast<const char*>(r.encoders.samples.data()),
                                       r.encoders.samples.size() *
                                           static_cast<std::size_t>(r.encoders.samples.stride()) *
                                           sizeof(double))
                    : Bytes(r.ground_truth.world_T_robot);
      const std::size_t h = LogHash(a, b);
      const auto range = seen.equal_range(h);
      for (auto it = range.first; it != range.second; ++it) {
        const RunLog& o = runs[it->second];
        const bool same = part == 0 ? (o.encoders.t_s == r.encoders.t_s &&
                                       o.encoders.samples == r.encoders.samples)
                                    : (o.ground_truth.t_s == r.ground_truth.t_s &&
                                       Bytes(o.ground_truth.world_T_robot) == b);
        if (!same) continue;
        const DatasetIndexEntry& e = index.runs[i];
        const DatasetIndexEntry& f = index.runs[it->second];
        throw InputError(InputErrorKind::kDuplicateRun,
                         part == 0 ? e.encoders_path : e.ground_truth_path, 0,
                         std::string("run '") + e.id + "' has the same " +
                             (part == 0 ? "encoder log" : "ground truth") + " as run '" + f.id +
                             "' (" + (part == 0 ? f.encoders_path : f.ground_truth_path) +
                             "): a duplicated run (a copied file?)");
      }
      seen.emplace(h, i);
    }
  }
}

// A calibration needs motion: when no wheel turns in any run (or no ground truth moves), every
// parameter is undetermined and a fit would return the nominal with sigma 0.
constexpr double kMovedM = 1e-4;          // below any ground truth's noise

bool AnyWheelTurns(const EncoderSamples& samples, const Robot& robot) {
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (WheelsTurn(samples, k, robot)) return true;
  }
  return false;
}

// How far the ground truth gets from its first pose (m).
double GroundTruthReach(const GroundTruthTrack& track) {
  double reach_m = 0.0;
  const Pose2d& first = track.world_T_robot.front();
  for (const Pose2d& p : track.world_T_robot) {
    reach_m = std::max(reach_m, std::hypot(p.x - first.x, p.y - first.y));
  }
  return reach_m;
}

void RejectDataSetWithoutMotion(const DatasetIndex& index, const std::vector<RunLog>& runs,
                                const Robot& robot) {
  bool wheels = false, ground_truth = false;
  for (const RunLog& run : runs) {
    wheels = wheels || AnyWheelTurns(run.encoders.samples, robot);
    ground_truth = ground_truth || GroundTruthReach(run.ground_truth) > kMovedM;
  }
  const std::string n = std::to_string(runs.size());
  if (!wheels) {
    // Counts over intervals 1000x too long turn 1000x too slowly (times in ms read as s).
    const double interval_s = TypicalEncoderInterval(runs);
    const std::string slow_clock =
        interval_s > 1.0 ? StrFormat(" (its samples lie %.3g s apart: times in ms or us, not s?)",
                                     interval_s)
                         : "";
    throw InputError(InputErrorKind::kNoMotion, index.yaml_path, 0,
                     "no run moves: no wheel turns faster than 0.01 rad/s in any of the " + n +
                         " runs" + slow_clock + "; nothing to calibrate");
  }
  if (!ground_truth) {
    throw InputError(InputErrorKind::kNoMotion, index.yaml_path, 0,
                     "no run moves: the ground truth of none of the " + n +
                         " runs moves by more than 0.1 mm; nothing to calibrate");
  }
}

// A run whose ground truth travels while no wheel turns recorded nothing of its motion (encoders
// unplugged, a log of another run's idle phase, the robot pushed): fitted, it pulls every
// parameter towards a robot that does not move; judged, it fails any calibration. 0.2 m is two
// orders above any motion capture's noise and below every calibration path.
constexpr double kTravelWithoutWheelsM = 0.2;

void RejectRunsWithoutWheelMotion(const DatasetIndex& index, const std::vector<RunLog>& runs,
                                  const Robot& robot) {
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (AnyWheelTurns(runs[i].encoders.samples, robot)) continue;
    const double reach_m = GroundTruthReach(runs[i].ground_truth);
    if (reach_m <= kTravelWithoutWheelsM) continue;
    throw InputError(InputErrorKind::kNoMotion, index.runs[i].encoders_path, 0,
                     "no wheel turns faster than 0.01 rad/s in run '" + runs[i].id +
                         "', while its ground truth moves " + StrFormat("%.2f m", reach_m) +
                         " from its start: the encoders recorded none of the motion (unplugged, "
                         "or the robot pushed); fix or remove the run");
  }
}

// A model may record its encoders in a format of its own (Robot::read_own_encoder_file: ASOC's
// cumulative wheel angles and pivot readings), converted to the model's channels there, so that
// every command sees the same runs. Any other file goes through the generic reader.
EncoderLog ReadRunEncoders(const std::string& path, const Robot& robot) {
  EncoderLog log;
  if (robot.read_own_encoder_file && robot.read_own_encoder_file(path, &log)) return log;
  return ReadEncoderCsv(path, robot);
}

}  // namespace

Dataset LoadDataset(const DatasetIndex& index, const Robot& robot, const DatasetOptions& options) {
  Dataset dataset;
  dataset.directory = index.directory;
  dataset.robot_path = index.robot_path;
  dataset.runs.resize(index.runs.size());
  ParallelFor(index.runs.size(), options.num_threads, [&](std::size_t i) {
    const DatasetIndexEntry& entry = index.runs[i];
    RunLog& log = dataset.runs[i];
    log.id = entry.id;
    log.trajectory = entry.trajectory;
    log.repetition = entry.repetition;
    log.start_pose = entry.start_pose;
    log.encoders = ReadRunEncoders(entry.encoders_path, robot);
    log.ground_truth = ReadGroundTruth(entry.ground_truth_path);
    log.ground_truth_path = entry.ground_truth_path;
    CheckGroundTruthOverlap(log.ground_truth, log.encoders.t_s.front(), log.encoders.t_s.back(),
                            entry.ground_truth_path);
  });
  RejectDataSetWithoutMotion(index, dataset.runs, robot);  // first: still runs are all alike
  RejectRunsWithoutWheelMotion(index, dataset.runs, robot);
  RejectCopiedRuns(index, dataset.runs);
  return dataset;
}

void ReadBackStagedDataset(const std::string& staged_dir, const std::string& out,
                           const Robot& robot) {
  try {
    LoadDataset(ReadDatasetIndex(staged_dir), robot);
  } catch (const InputError& e) {
    const auto as_out = [&](std::string text) {
      for (std::size_t at = text.find(staged_dir); at != std::string::npos;
           at = text.find(staged_dir, at + out.size())) {
        text.replace(at, staged_dir.size(), out);
      }
      return text;
    };
    const std::string what = e.what();
    const std::size_t prefix = FileLineText(e.file(), e.line(), "").size();
    throw InputError(e.kind(), as_out(e.file()), e.line(),
                     as_out(what.substr(std::min(prefix, what.size()))));
  }
}

std::string DatasetYaml(const std::string& robot_path, const std::vector<DatasetEntry>& runs) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "robot" << YAML::Value << YamlText(robot_path);
  out << YAML::Key << "runs" << YAML::Value << YAML::BeginSeq;
  for (const DatasetEntry& run : runs) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "id" << YAML::Value << YamlText(run.id);
    out << YAML::Key << "trajectory" << YAML::Value << YamlText(run.trajectory);
    out << YAML::Key << "repetition" << YAML::Value << run.repetition;
    out << YAML::Key << "encoders" << YAML::Value << YamlText(run.encoders);
    out << YAML::Key << "ground_truth" << YAML::Value << YamlText(run.ground_truth);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void AppendFixed(std::string* out, double v, int precision) {
  char buffer[400];  // %.9f of the largest double fits
  const auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::fixed, precision);
  out->append(buffer, ec == std::errc() ? end : buffer);
}

void AppendGeneral(std::string* out, double v, int precision) {
  char buffer[64];
  const auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::general, precision);
  out->append(buffer, ec == std::errc() ? end : buffer);
}

std::string GroundTruthCsv(const GroundTruthTrack& track) {
  std::string out = "t,x,y,theta\n";
  out.reserve(48 * track.t_s.size() + out.size());
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const Pose2d& p = track.world_T_robot[k];
    // Text of "%.6f,%.6f,%.6f,%.7f\n".
    AppendFixed(&out, track.t_s[k], 6);
    out += ',';
    AppendFixed(&out, p.x, 6);
    out += ',';
    AppendFixed(&out, p.y, 6);
    out += ',';
    AppendFixed(&out, p.theta, 7);
    out += '\n';
  }
  return out;
}

}  // namespace fitcal::io
