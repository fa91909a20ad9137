#include "interchange/ros2/rosbag2_import.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "io/command_failure.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "io/ros2_parameter_yaml.h"
#include "io/rosbag2/bag_metadata.h"
#include "io/rosbag2/static_transforms.h"
#include "io/text_file.h"
#include "models/model_registry.h"
#include "odometry/text_format.h"

namespace fitcal {
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
    // Runs that share samples would put the same motion in training and held-out runs.
    for (const auto& [b0, b1] : spans) {
      if (t0 < b1 && b0 < t1) throw UsageError("--runs: '" + item + "' overlaps an earlier span");
    }
    spans.emplace_back(t0, t1);
    pos = end + 1;
  }
  return spans;
}

std::string RunLabel(const ImportRosbag2Options& o) {
  std::string label = o.label;
  if (label.empty()) {
    // absolute: a bag given as `.` or `..` is named after its folder, not the dots
    fs::path p = fs::absolute(o.bag).lexically_normal();
    if (!p.has_filename()) p = p.parent_path();
    // A bag's one storage file names its runs as the bag's directory does: the same recording
    // under two labels had its training runs judged as held out by another run id.
    const bool whole_bag_file = io::rosbag2::OwningBagOfFile(p.string()).files == 1;
    label = p.filename() == "metadata.yaml" || whole_bag_file ? p.parent_path().filename().string()
                                                               : p.stem().string();
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
// others and some step between two messages longer than pi. Each step is then taken as the shortest
// rotation, WrapAngle(step) - right while the wheel turns less than half a turn between messages. A
// wrapped step longer than kMaxUnwrappedStepRad leaves too little margin to tell the direction:
// refused, naming the joint.
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
        throw InputError(
            InputErrorKind::kBadValue, s->bag, 0,
            StrFormat("joint \"%s\": positions wrapped to one turn with a step of %.3f rad "
                      "between messages at %.9f s: too fast to unwrap unambiguously",
                      joint_names[j].c_str(), step, SecondsSinceStart(*s, s->joints.t_ns[k])));
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
      throw InputError(
          InputErrorKind::kTooFewSamples, s.bag, 0,
          StrFormat("run %g:%g s holds fewer than 2 encoder messages (the bag spans 0:%.3f s)", t0,
                    t1, SecondsSinceStart(s, s.joints.t_ns.back())));
    }
    spans.push_back(span);
  }
  return spans;
}

RunLog MakeRun(const Robot& robot, const BagStreams& s, const std::vector<double>& rows,
               const IndexSpan& span, int number, const std::string& label,
               std::vector<double>* t_out, std::vector<double>* rows_out) {
  RunLog run;
  run.id = label + StrFormat("-%02d", number);
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
    throw InputError(InputErrorKind::kNoOverlap, s.bag, 0,
                     StrFormat("run %s (%.3f:%.3f s) holds %zu ground-truth pose(s); at least 2 "
                               "needed",
                               run.id.c_str(), t0, t1, run.ground_truth.t_s.size()));
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
  r.joints = io::ChannelJointNames(robot, o.joints);
  for (const ChannelInfo& channel : robot.channels) {
    r.needs_position.push_back(channel.kind == ChannelKind::kAngle);
  }
  return r;
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
  imp->robot_yaml_addition =
      "# the ground truth's frame in " + o.base_frame +
      ", from the bag's /tf_static (fitcal import rosbag2)\n" +
      StrFormat("ground_truth_frame: {x_m: %.9g, y_m: %.9g, yaw_deg: %.9g}\n",
                clean(mount.base_T_sensor->x), clean(mount.base_T_sensor->y),
                clean(mount.base_T_sensor->theta * 180.0 / M_PI));
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

}  // namespace fitcal
