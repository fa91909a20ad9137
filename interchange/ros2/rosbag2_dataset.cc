#include <algorithm>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>

#include "interchange/ros2/rosbag2_import.h"
#include "diagnosis/import_channel_order.h"
#include "diagnosis/miswired_error.h"
#include "io/atomic_file.h"
#include "io/command_failure.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/input_registry.h"
#include "io/output_guard.h"
#include "io/staged_directory.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "validation/rate_units.h"

// The data set `import rosbag2` writes from a bag read and cut into runs (rosbag2_import.cc):
// the CSVs exact to the last bit, robot.yaml with the frame the bag adds, dataset.yaml with
// where it came from, refused unless `fit` would load it.
namespace fitcal {
namespace {

namespace fs = std::filesystem;
using io::InputError;

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
                          const RobotModelInterface& model, const std::vector<RunLog>& runs) {
  try {
    io::ReadBackStagedDataset(staged_dir, o.out, model.robot());
  } catch (const InputError& e) {
    throw InputError(e.kind(), o.bag, 0, std::string("the data set it makes would be refused: ") +
                                             e.what());
  }
  // The units check `fit` runs before fitting (calibrate/checks_before_fitting.h): odometry and
  // ground truth that travel paths of lengths no unit explains (a second body's poses interleaved
  // on the ground-truth topic made a data set `fit` refused as millimetres).
  if (const RateUnitsFinding units = CheckModelRateUnits(model, runs); units.suspicious) {
    throw InputError(InputErrorKind::kBadValue, o.bag, 0,
                     "the data set it makes would be refused: " + units.message);
  }
}

// The channel-order check of every import (diagnosis/import_channel_order.h), on the runs as
// written and the robot as it reads back: joints given to --joints in another order (left for
// right) or a wheel whose joint axis is reversed wrote a data set that `fit` then refused as
// miswired (exit 4), naming the robot YAML rather than the import's --joints.
// With --skip-mapping-check, the line that says it was written anyway (else "").
std::string RefuseJointsInAnotherOrder(const ImportRosbag2Options& o,
                                       const std::vector<RunLog>& runs,
                                       const RobotModelInterface& model) {
  try {
    const std::string line = CheckImportedChannelOrder(runs, model, o.skip_mapping_check);
    return line.find("written anyway") != std::string::npos ? line : "";
  } catch (const MiswiredError& e) {
    std::string joints;
    for (std::size_t c = 0; c < model.robot().channels.size(); ++c) {
      joints += (c == 0 ? "" : ",") +
                (o.joints.empty() ? model.robot().channels[c].name : o.joints.at(c));
    }
    throw MiswiredError(o.bag + ": read as --joints " + joints + " in the robot's channel order: " +
                        e.what());
  }
}

// Writes the data set staged and renamed over --out; returns the robot as it reads back (with the
// ground-truth frame the bag added).
RobotModelPtr WriteDataset(const ImportRosbag2Options& o, const Robot& robot,
                           Rosbag2Import& imp) {
  io::StagedDirectory staged(o.out);
  const fs::path dir(staged.path());
  fs::create_directories(dir / "runs");
  std::vector<io::DatasetEntry> entries;
  for (std::size_t i = 0; i < imp.runs.size(); ++i) {
    const RunLog& run = imp.runs[i];
    io::DatasetEntry e{run.id, run.trajectory, run.repetition, "runs/" + run.id + "_encoders.csv",
                       "runs/" + run.id + "_ground_truth.csv"};
    io::WriteFileAtomically(
        (dir / e.encoders).string(),
        EncoderCsvText(robot, imp.encoder_t_s[i], imp.encoder_values[i]).view());
    io::WriteFileAtomically((dir / e.ground_truth).string(),
                            GroundTruthCsvText(run.ground_truth).view());
    entries.push_back(std::move(e));
  }
  std::string robot_yaml = io::ReadTextFile(o.robot);
  if (!imp.robot_yaml_addition.empty()) {
    if (!robot_yaml.empty() && robot_yaml.back() != '\n') robot_yaml += '\n';
    robot_yaml += imp.robot_yaml_addition;
  }
  io::WriteFileAtomically((dir / "robot.yaml").string(), robot_yaml);
  RobotModelPtr written = ReadRobotModelFile((dir / "robot.yaml").string());  // reads back
  const std::string header =
      "# imported by fitcal import rosbag2 from " + io::YamlCommentText(o.bag) + "\n# encoders " +
      io::YamlCommentText(o.encoders) + " (" +
      (imp.streams.joints.positions ? "positions" : "velocities") + "), ground truth " +
      io::YamlCommentText(o.ground_truth) + " (" + imp.streams.pose_type + "), " + o.stamp +
      " stamps; t = 0 at " +
      std::to_string(imp.streams.start_time_ns) + " ns since the epoch\n";
  io::WriteFileAtomically((dir / "dataset.yaml").string(),
                          header + io::DatasetYaml("robot.yaml", entries));
  RefuseWhatFitRefuses(o, staged.path(), *written, imp.runs);
  if (std::string said = RefuseJointsInAnotherOrder(o, imp.runs, *written); !said.empty()) {
    imp.notes.push_back(std::move(said));
  }
  io::StopHereForTests("import-rosbag2-before-rename");
  io::CommitDirectoryOutput(staged, o.out, io::kDatasetKind, o.force, {o.bag});
  return written;
}

}  // namespace

Rosbag2Import ImportRosbag2(const ImportRosbag2Options& o) {
  if (o.out.empty()) throw UsageError("--out <data set directory> is required");
  io::RegisterInput(o.bag);  // no data set in, over or holding the bag
  if (const std::string refusal =
          io::DirectoryOutputRefusal(o.out, io::kDatasetKind, o.force, {o.bag});
      !refusal.empty()) {
    throw UsageError(refusal);  // exit 2, as every writer refuses its --out
  }
  Rosbag2Import imp = ReadRosbag2Import(o);
  const RobotModelPtr written = WriteDataset(o, ReadRobotModelFile(o.robot)->robot(), imp);
  imp.nominal = EvaluateFinalPoseErrors(*written, written->robot().nominal, AlignRuns(imp.runs));
  return imp;
}

}  // namespace fitcal
