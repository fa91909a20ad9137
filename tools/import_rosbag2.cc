#include "tools/import_rosbag2.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string_view>

#include "fit/final_pose_errors.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/input_registry.h"
#include "io/log_files.h"
#include "io/rosbag2/static_transforms.h"
#include "io/staged_directory.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "io/command_failure.h"
#include "tools/dataset_command.h"
#include "tools/output_guard.h"

namespace fitcal::tools {
namespace {

namespace fs = std::filesystem;
using io::InputError;
using io::InputErrorKind;
using io::rosbag2::BagStreams;

struct IndexSpan {
  std::size_t first = 0;  // encoder stamps first..last, inclusive
  std::size_t last = 0;
};

double ParseSeconds(const std::string& text, const std::string& what) {
  double v = 0.0;
  bool finite = true;
  if (!io::ParseDouble(io::Trim(text), &v, &finite) || !finite) {
    throw UsageError(what + ": '" + text + "' is not a number of seconds");
  }
  return v;
}

// "t0:t1,t2:t3" -> spans in seconds since the bag's start.
std::vector<std::pair<double, double>> ParseRunSpans(const std::string& text) {
  std::vector<std::pair<double, double>> spans;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, end - pos);
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos) {
      throw UsageError("--runs: '" + item + "' is not t0:t1");
    }
    const double t0 = ParseSeconds(item.substr(0, colon), "--runs");
    const double t1 = ParseSeconds(item.substr(colon + 1), "--runs");
    if (!(t1 > t0)) throw UsageError("--runs: '" + item + "' does not end after it starts");
    spans.emplace_back(t0, t1);
    pos = end + 1;
  }
  return spans;
}

std::string RunLabel(const ImportRosbag2Options& o) {
  std::string label = o.label;
  if (label.empty()) {
    fs::path p = fs::path(o.bag).lexically_normal();
    if (!p.has_filename()) p = p.parent_path();
    label =
        p.filename() == "metadata.yaml" ? p.parent_path().filename().string() : p.stem().string();
  }
  for (char& c : label) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  return label.empty() ? "bag" : label;
}

double SecondsSinceStart(const BagStreams& s, std::int64_t t_ns) {
  return static_cast<double>(t_ns - s.start_time_ns) * 1e-9;
}

// What the encoder CSV holds at each stamp, robot channel order: a wheel's mean rate over the
// interval ending at the stamp (0 at stamp 0: row 0 only sets the start), an angle as read.
// Row-major, one row of robot.channels.size() values per stamp.
std::vector<double> ChannelRows(const Robot& robot, const BagStreams& s) {
  const std::size_t n = s.joints.t_ns.size(), c = robot.channels.size();
  const std::vector<double>& v = s.joints.values;
  std::vector<double> rows(n * c, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double dt = k == 0 ? 0.0
                             : SecondsSinceStart(s, s.joints.t_ns[k]) -
                                   SecondsSinceStart(s, s.joints.t_ns[k - 1]);
    for (std::size_t j = 0; j < c; ++j) {
      const double now = v[k * c + j];
      if (robot.channels[j].kind == ChannelKind::kAngle) {
        rows[k * c + j] = now;
      } else if (k > 0) {
        const double before = v[(k - 1) * c + j];
        rows[k * c + j] = s.joints.positions ? (now - before) / dt : 0.5 * (before + now);
      }
    }
  }
  return rows;
}

// Joint positions wrapped to one turn (a driver that reports a wheel's angle modulo a turn, in
// [-pi, pi) or [0, 2 pi), not cumulatively): every reading of the wheel within one turn of the
// others and some step between two messages longer than pi. Each step is then taken as the shortest rotation, WrapAngle(step) - right
// while the wheel turns less than half a turn between messages. A wrapped step longer than
// kMaxUnwrappedStepRad leaves too little margin to tell the direction: refused, naming the joint.
constexpr double kMaxUnwrappedStepRad = 0.5 * M_PI;

std::vector<std::string> UnwrapWrappedWheels(const Robot& robot,
                                             const std::vector<std::string>& joint_names,
                                             BagStreams* s) {
  std::vector<std::string> notes;
  if (!s->joints.positions) return notes;
  const std::size_t n = s->joints.t_ns.size(), c = robot.channels.size();
  std::vector<double>& v = s->joints.values;
  for (std::size_t j = 0; j < c; ++j) {
    if (robot.channels[j].kind != ChannelKind::kWheelRate) continue;
    double lo = v[j], hi = v[j];
    bool jumps = false;
    for (std::size_t k = 1; k < n; ++k) {
      lo = std::min(lo, v[k * c + j]);
      hi = std::max(hi, v[k * c + j]);
      jumps = jumps || std::abs(v[k * c + j] - v[(k - 1) * c + j]) > M_PI;
    }
    if (hi - lo > 2.0 * M_PI + 1e-9 || !jumps) continue;
    int wraps = 0;
    double previous_raw = v[j];
    for (std::size_t k = 1; k < n; ++k) {
      const double raw = v[k * c + j];
      const double step = WrapAngle(raw - previous_raw);
      if (std::abs(step) > kMaxUnwrappedStepRad) {
        char what[240];
        std::snprintf(what, sizeof what,
                      "joint \"%s\": positions wrapped to one turn with a step of %.3f rad "
                      "between messages at %.9f s: too fast to unwrap unambiguously",
                      joint_names[j].c_str(), step, SecondsSinceStart(*s, s->joints.t_ns[k]));
        throw InputError(InputErrorKind::kBadValue, s->bag, 0, what);
      }
      wraps += std::abs(raw - previous_raw) > M_PI;
      previous_raw = raw;
      v[k * c + j] = v[(k - 1) * c + j] + step;
    }
    notes.push_back("joint \"" + joint_names[j] + "\": positions wrapped to one turn unwrapped (" +
                    std::to_string(wraps) + " wraps)");
  }
  return notes;
}

bool IntervalAtRest(const Robot& robot, const double* row, double rest_rate) {
  for (std::size_t j = 0; j < robot.channels.size(); ++j) {
    if (robot.channels[j].kind == ChannelKind::kWheelRate && std::abs(row[j]) > rest_rate) {
      return false;
    }
  }
  return true;
}

// Cuts at the middle stamp of every rest of at least min_rest_s and keeps the pieces in which
// some wheel turns.
std::vector<IndexSpan> SplitAtRests(const Robot& robot, const BagStreams& s,
                                    const std::vector<double>& rows,
                                    const ImportRosbag2Options& o) {
  const std::size_t c = robot.channels.size(), n = s.joints.t_ns.size();
  const auto row = [&](std::size_t k) { return rows.data() + k * c; };
  std::vector<std::size_t> cuts = {0};
  std::size_t k = 1;
  while (k < n) {
    if (!IntervalAtRest(robot, row(k), o.rest_rate_rad_s)) {
      ++k;
      continue;
    }
    const std::size_t begin = k - 1;  // the rest starts at the stamp before its first interval
    while (k < n && IntervalAtRest(robot, row(k), o.rest_rate_rad_s)) ++k;
    const std::size_t end = k - 1;
    const double length_s =
        SecondsSinceStart(s, s.joints.t_ns[end]) - SecondsSinceStart(s, s.joints.t_ns[begin]);
    if (length_s >= o.split_at_rest_s) {
      // The first stamp at or after the rest's middle in time (stamps need not be uniform).
      const std::int64_t middle_ns =
          s.joints.t_ns[begin] + (s.joints.t_ns[end] - s.joints.t_ns[begin]) / 2;
      std::size_t cut = begin;
      while (s.joints.t_ns[cut] < middle_ns) ++cut;
      cuts.push_back(cut);
    }
  }
  cuts.push_back(n - 1);
  std::vector<IndexSpan> spans;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    bool moves = false;
    for (std::size_t j = cuts[i] + 1; j <= cuts[i + 1] && !moves; ++j) {
      moves = !IntervalAtRest(robot, row(j), o.rest_rate_rad_s);
    }
    if (moves) spans.push_back({cuts[i], cuts[i + 1]});
  }
  return spans;
}

std::vector<IndexSpan> SpansFromTimes(const BagStreams& s, const ImportRosbag2Options& o) {
  std::vector<IndexSpan> spans;
  for (const auto& [t0, t1] : ParseRunSpans(o.runs)) {
    IndexSpan span{s.joints.t_ns.size(), 0};
    for (std::size_t k = 0; k < s.joints.t_ns.size(); ++k) {
      const double t = SecondsSinceStart(s, s.joints.t_ns[k]);
      if (t < t0 || t > t1) continue;
      span.first = std::min(span.first, k);
      span.last = k;
    }
    if (span.first >= span.last) {
      char what[160];
      std::snprintf(what, sizeof what,
                    "run %g:%g s holds fewer than 2 encoder messages (the bag spans 0:%.3f s)", t0,
                    t1, SecondsSinceStart(s, s.joints.t_ns.back()));
      throw InputError(InputErrorKind::kTooFewSamples, s.bag, 0, what);
    }
    spans.push_back(span);
  }
  return spans;
}

RunLog MakeRun(const Robot& robot, const BagStreams& s, const std::vector<double>& rows,
               const IndexSpan& span, int number, const std::string& label,
               std::vector<double>* t_out, std::vector<double>* rows_out) {
  RunLog run;
  char id[32];
  std::snprintf(id, sizeof id, "-%02d", number);
  run.id = label + id;
  run.trajectory = label;
  run.repetition = number;
  const std::size_t c = robot.channels.size(), count = span.last - span.first + 1;
  io::EncoderRowConverter converter(robot);
  converter.Reserve(count);
  t_out->reserve(count);
  rows_out->assign(rows.begin() + static_cast<std::ptrdiff_t>(span.first * c),
                   rows.begin() + static_cast<std::ptrdiff_t>((span.last + 1) * c));
  for (std::size_t j = 0; j < c; ++j) {  // the run's row 0 only sets its start
    if (robot.channels[j].kind == ChannelKind::kWheelRate) (*rows_out)[j] = 0.0;
  }
  for (std::size_t k = span.first; k <= span.last; ++k) {
    const double t = SecondsSinceStart(s, s.joints.t_ns[k]);
    converter.Add(t, rows_out->data() + (k - span.first) * c);
    t_out->push_back(t);
  }
  run.encoders = converter.Take();
  const double t0 = t_out->front(), t1 = t_out->back();
  for (std::size_t k = 0; k < s.poses.t_ns.size(); ++k) {
    const double t = SecondsSinceStart(s, s.poses.t_ns[k]);
    if (t < t0 || t > t1) continue;
    run.ground_truth.t_s.push_back(t);
    run.ground_truth.world_T_robot.push_back(s.poses.world_T_robot[k]);
  }
  if (run.ground_truth.t_s.size() < 2) {
    char what[160];
    std::snprintf(what, sizeof what,
                  "run %s (%.3f:%.3f s) holds %zu ground-truth pose(s); at "
                  "least 2 needed",
                  run.id.c_str(), t0, t1, run.ground_truth.t_s.size());
    throw InputError(InputErrorKind::kNoOverlap, s.bag, 0, what);
  }
  return run;
}

io::rosbag2::BagStreamRequest MakeRequest(const ImportRosbag2Options& o, const Robot& robot) {
  io::rosbag2::BagStreamRequest r;
  r.joint_topic = o.encoders;
  r.pose_topic = o.ground_truth;
  if (o.stamp != "header" && o.stamp != "recorded") {
    throw UsageError("--stamp must be header or recorded, not '" + o.stamp + "'");
  }
  r.stamp =
      o.stamp == "header" ? io::rosbag2::StampSource::kHeader : io::rosbag2::StampSource::kRecorded;
  if (!o.ground_truth_frames.empty()) {
    const std::size_t colon = o.ground_truth_frames.find(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == o.ground_truth_frames.size()) {
      throw UsageError("--ground-truth-frames must be parent:child, e.g. world:base_link");
    }
    r.parent_frame = o.ground_truth_frames.substr(0, colon);
    r.child_frame = o.ground_truth_frames.substr(colon + 1);
    for (std::string* f : {&r.parent_frame, &r.child_frame}) {
      if ((*f)[0] == '/') f->erase(0, 1);
    }
  }
  if (!o.joints.empty() && o.joints.size() != robot.channels.size()) {
    throw UsageError("--joints names " + std::to_string(o.joints.size()) + " joints; robot '" +
                     robot.name + "' has " + std::to_string(robot.channels.size()) + " channels");
  }
  for (std::size_t j = 0; j < robot.channels.size(); ++j) {
    r.joints.push_back(o.joints.empty() ? robot.channels[j].name : o.joints[j]);
    r.needs_position.push_back(robot.channels[j].kind == ChannelKind::kAngle);
  }
  return r;
}

// The CSVs are built in one buffer: t with ns resolution (std::to_chars fixed, 9 decimals: the
// bytes printf's %.9f gives), every other value as the shortest text that reads back to the same
// double (std::to_chars): exact on read-back (io::ParseDouble uses std::from_chars), and several
// times faster than printf.
class CsvBuffer {
 public:
  // Not zero-filled: the text of a long run is megabytes, and each byte is written once.
  explicit CsvBuffer(std::size_t expected_bytes)
      : text_(new char[expected_bytes]), capacity_(expected_bytes) {}
  void Append(std::string_view s) {
    Room(s.size());
    std::memcpy(text_.get() + size_, s.data(), s.size());
    size_ += s.size();
  }
  void Char(char c) {
    Room(1);
    text_[size_++] = c;
  }
  // %.9f; a fixed-point double needs at most 309 + 1 + 9 + sign characters.
  void Seconds(double t) {
    Room(330);
    End(std::to_chars(Next(), text_.get() + capacity_, t, std::chars_format::fixed, 9));
  }
  // Shortest round trip: at most 24 characters ("-2.2250738585072014e-308").
  void Value(double v) {
    Room(32);
    End(std::to_chars(Next(), text_.get() + capacity_, v));
  }
  std::string_view view() const { return {text_.get(), size_}; }

 private:
  char* Next() { return text_.get() + size_; }
  void End(const std::to_chars_result& r) { size_ = static_cast<std::size_t>(r.ptr - text_.get()); }
  void Room(std::size_t n) {
    if (capacity_ - size_ >= n) return;
    const std::size_t capacity = std::max(2 * capacity_, size_ + n);
    std::unique_ptr<char[]> bigger(new char[capacity]);
    std::memcpy(bigger.get(), text_.get(), size_);
    text_ = std::move(bigger);
    capacity_ = capacity;
  }
  std::unique_ptr<char[]> text_;
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
};

CsvBuffer EncoderCsvText(const Robot& robot, const std::vector<double>& t_s,
                         const std::vector<double>& rows) {
  const std::size_t c = robot.channels.size();
  CsvBuffer out(64 + t_s.size() * (24 + 26 * c));
  out.Char('t');
  for (const ChannelInfo& ch : robot.channels) {
    out.Char(',');
    out.Append(ch.rate_column);
  }
  out.Char('\n');
  const double* row = rows.data();
  for (std::size_t k = 0; k < t_s.size(); ++k, row += c) {
    out.Seconds(t_s[k]);
    for (std::size_t j = 0; j < c; ++j) {
      out.Char(',');
      out.Value(row[j]);
    }
    out.Char('\n');
  }
  return out;
}

// io::GroundTruthCsv rounds to 1 um and 1e-7 rad; a bag's poses are kept to the last bit.
CsvBuffer GroundTruthCsvText(const GroundTruthTrack& track) {
  CsvBuffer out(16 + track.t_s.size() * 96);
  out.Append("t,x,y,theta\n");
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const Pose2d& p = track.world_T_robot[k];
    out.Seconds(track.t_s[k]);
    for (double v : {p.x, p.y, p.theta}) {
      out.Char(',');
      out.Value(v);
    }
    out.Char('\n');
  }
  return out;
}

// The staged data set read back by the loader `fit` uses (io/dataset.h: physical limits of
// rates, angles and times, clock steps and gaps while the wheels turn, runs that move): a data
// set the import writes is one `fit` accepts. A refusal names the bag and the file as it would
// be under --out.
void RefuseWhatFitRefuses(const ImportRosbag2Options& o, const std::string& staged_dir,
                          const Robot& robot) {
  try {
    io::LoadDataset(io::ReadDatasetIndex(staged_dir), robot);
  } catch (const InputError& e) {
    std::string what = e.what();
    for (std::size_t at = what.find(staged_dir); at != std::string::npos;
         at = what.find(staged_dir, at + o.out.size())) {
      what.replace(at, staged_dir.size(), o.out);
    }
    throw InputError(e.kind(), o.bag, 0, "the data set it makes would be refused: " + what);
  }
}

void WriteDataset(const ImportRosbag2Options& o, const Robot& robot, const Rosbag2Import& imp) {
  io::StagedDirectory staged(o.out);
  const fs::path dir(staged.path());
  fs::create_directories(dir / "runs");
  std::vector<io::DatasetEntry> entries;
  for (std::size_t i = 0; i < imp.runs.size(); ++i) {
    io::DatasetEntry e;
    e.id = imp.runs[i].id;
    e.trajectory = imp.runs[i].trajectory;
    e.repetition = imp.runs[i].repetition;
    e.encoders = "runs/" + e.id + "_encoders.csv";
    e.ground_truth = "runs/" + e.id + "_ground_truth.csv";
    io::WriteFileAtomically(
        (dir / e.encoders).string(),
        EncoderCsvText(robot, imp.encoder_t_s[i], imp.encoder_values[i]).view());
    io::WriteFileAtomically((dir / e.ground_truth).string(),
                            GroundTruthCsvText(imp.runs[i].ground_truth).view());
    entries.push_back(std::move(e));
  }
  std::string robot_yaml = io::ReadTextFile(o.robot);
  if (!imp.robot_yaml_addition.empty()) {
    if (!robot_yaml.empty() && robot_yaml.back() != '\n') robot_yaml += '\n';
    robot_yaml += imp.robot_yaml_addition;
  }
  io::WriteFileAtomically((dir / "robot.yaml").string(), robot_yaml);
  ReadRobotModelFile((dir / "robot.yaml").string());  // the robot with its frame reads back
  const std::string header =
      "# imported by fitcal import rosbag2 from " + io::YamlCommentText(o.bag) + "\n# encoders " +
      io::YamlCommentText(o.encoders) + " (" +
      (imp.streams.joints.positions ? "positions" : "velocities") + "), ground truth " +
      io::YamlCommentText(o.ground_truth) + " (" + imp.streams.pose_type + "), " + o.stamp +
      " stamps; t = 0 at " +
      std::to_string(imp.streams.start_time_ns) + " ns since the epoch\n";
  io::WriteFileAtomically((dir / "dataset.yaml").string(),
                          header + io::DatasetYaml("robot.yaml", entries));
  RefuseWhatFitRefuses(o, staged.path(), robot);
  io::StopHereForTests("import-rosbag2-before-rename");
  CommitDirectoryOutput(staged, o.out, kDatasetKind, o.force, {o.bag});
}

bool DeclaresGroundTruthFrame(const Robot& robot) {
  return std::any_of(robot.parameters.begin(), robot.parameters.end(),
                     [](const ParameterInfo& p) { return p.name == "ground_truth_x"; });
}

// The nominal ground_truth_frame from the bag's /tf_static, and the line that says so.
void AddGroundTruthFrame(const ImportRosbag2Options& o, const Robot& robot, Rosbag2Import* imp) {
  const io::rosbag2::GroundTruthMountFromBag mount =
      io::rosbag2::MountFromTfStatic(imp->streams, o.ground_truth, o.base_frame);
  if (mount.note.empty()) return;
  if (mount.base_T_sensor && DeclaresGroundTruthFrame(robot)) {
    imp->notes.push_back(mount.note.substr(0, mount.note.find(": ground_truth_frame")) +
                         ": the robot YAML's own ground_truth_frame kept (/tf_static not used)");
    return;
  }
  imp->notes.push_back(mount.note);
  if (!mount.base_T_sensor) return;
  // Rounding of the 3-D composition (1e-17 m where a chain cancels) printed as the 0 it is.
  const auto clean = [](double v) { return std::abs(v) < 5e-13 ? 0.0 : v; };
  char line[200];
  std::snprintf(line, sizeof line, "ground_truth_frame: {x_m: %.9g, y_m: %.9g, yaw_deg: %.9g}\n",
                clean(mount.base_T_sensor->x), clean(mount.base_T_sensor->y),
                clean(mount.base_T_sensor->theta * 180.0 / M_PI));
  imp->robot_yaml_addition = "# the ground truth's frame in " + o.base_frame +
                             ", from the bag's /tf_static (fitcal import rosbag2)\n" + line;
}

}  // namespace

Rosbag2Import ReadRosbag2Import(const ImportRosbag2Options& o) {
  if (o.split_at_rest_s > 0.0 && !o.runs.empty()) {
    throw UsageError("--runs and --split-at-rest exclude each other");
  }
  if (o.ground_truth.empty()) throw UsageError("--ground-truth <topic> is required");
  const RobotModelPtr model = ReadRobotModelFile(o.robot);
  const Robot& robot = model->robot();
  Rosbag2Import imp;
  const io::rosbag2::BagStreamRequest request = MakeRequest(o, robot);
  imp.streams = io::rosbag2::ReadBagStreams(o.bag, request);
  imp.notes = imp.streams.notes;
  AddGroundTruthFrame(o, robot, &imp);
  for (std::string& note : UnwrapWrappedWheels(robot, request.joints, &imp.streams)) {
    imp.notes.push_back(std::move(note));
  }
  const std::vector<double> rows = ChannelRows(robot, imp.streams);
  std::vector<IndexSpan> spans;
  if (!o.runs.empty()) {
    spans = SpansFromTimes(imp.streams, o);
  } else if (o.split_at_rest_s > 0.0) {
    spans = SplitAtRests(robot, imp.streams, rows, o);
    if (spans.empty()) {
      throw InputError(InputErrorKind::kTooFewSamples, o.bag, 0,
                       "the wheels never turn faster than --rest-rate: no run to cut");
    }
  } else {
    spans = {{0, imp.streams.joints.t_ns.size() - 1}};
  }
  const std::string label = RunLabel(o);
  for (std::size_t i = 0; i < spans.size(); ++i) {
    imp.encoder_t_s.emplace_back();
    imp.encoder_values.emplace_back();
    imp.runs.push_back(MakeRun(robot, imp.streams, rows, spans[i], static_cast<int>(i) + 1, label,
                               &imp.encoder_t_s.back(), &imp.encoder_values.back()));
  }
  return imp;
}

Rosbag2Import ImportRosbag2(const ImportRosbag2Options& o) {
  if (o.out.empty()) throw UsageError("--out <data set directory> is required");
  io::RegisterInputDirectory(o.bag);  // no data set in, over or holding the bag
  if (const std::string refusal = DirectoryOutputRefusal(o.out, kDatasetKind, o.force, {o.bag});
      !refusal.empty()) {
    throw UsageError(refusal);  // exit 2, as every writer refuses its --out
  }
  Rosbag2Import imp = ReadRosbag2Import(o);
  WriteDataset(o, ReadRobotModelFile(o.robot)->robot(), imp);
  return imp;
}

void AddImportRosbag2Options(CLI::App& app, ImportRosbag2Options& o) {
  app.add_option("bag", o.bag, "Bag directory, its metadata.yaml, or one .db3 / .mcap file")
      ->required();
  app.add_option("--out", o.out, "Output data set directory (written atomically)")->required();
  app.add_option("--robot", o.robot, "Robot YAML (any model); copied into the data set")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--encoders", o.encoders, "sensor_msgs/msg/JointState topic")
      ->capture_default_str();
  app.add_option("--joints", o.joints,
                 "Joint names in the robot's channel order (default: the channel names)")
      ->delimiter(',');
  app.add_option("--ground-truth", o.ground_truth,
                 "Ground-truth topic: geometry_msgs/msg/PoseStamped, nav_msgs/msg/Odometry or "
                 "tf2_msgs/msg/TFMessage")
      ->required();
  app.add_option("--ground-truth-frames", o.ground_truth_frames,
                 "For a TFMessage topic: parent:child of the transform, e.g. world:base_link; for "
                 "a PoseStamped: the child names the frame it tracks");
  app.add_option("--base-frame", o.base_frame,
                 "The robot's base frame in /tf_static: a ground truth tracking another frame "
                 "gets its nominal ground_truth_frame from there")
      ->capture_default_str();
  app.add_option("--stamp", o.stamp,
                 "header (default: when the driver measured; the recording time adds each "
                 "topic's own transport latency and jitter) or recorded")
      ->capture_default_str();
  app.add_option("--runs", o.runs, "Cut runs at these spans: t0:t1,t2:t3 (s since the bag start)");
  app.add_option("--split-at-rest", o.split_at_rest_s,
                 "Cut runs in the middle of every rest at least this long (s)")
      ->check(CLI::PositiveNumber);
  app.add_option("--rest-rate", o.rest_rate_rad_s, "A wheel slower than this is at rest (rad/s)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--label", o.label, "Trajectory label of the runs (default: the bag's name)");
  app.add_flag("--force", o.force, kForceDirectoryHelp);
}

int RunImportRosbag2Command(const ImportRosbag2Options& o) {
  return RunReportingErrors("fitcal import rosbag2", [&]() -> int {
    const Rosbag2Import imp = ImportRosbag2(o);
    if (!o.quiet) {
      for (const std::string& note : imp.notes) std::printf("%s\n", note.c_str());
      const RobotModelPtr model = ReadRobotModelFile((fs::path(o.out) / "robot.yaml").string());
      const FinalPoseErrors nominal =
          EvaluateFinalPoseErrors(*model, model->robot().nominal, AlignRuns(imp.runs));
      std::printf(
          "wrote %zu run(s) to %s (%.1f MB of bag, %zu encoder and %zu ground-truth "
          "samples); nominal CF (Eq. 14) %.4f\n",
          imp.runs.size(), o.out.c_str(), static_cast<double>(imp.streams.bytes) * 1e-6,
          imp.streams.joints.t_ns.size(), imp.streams.poses.t_ns.size(), nominal.cf);
    }
    return 0;
  });
}

}  // namespace fitcal::tools
