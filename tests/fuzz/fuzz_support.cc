#include "tests/fuzz/fuzz_support.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "io/dataset.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "models/asoc/asoc_files.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/omni3/omni3_robot_model.h"
#include "cli/import_rosbag2.h"
#include "tests/asoc_robot_file.h"
#include "tests/omni3_robot.h"
#include "tests/three_wheel_files.h"

namespace fitcal::fuzz {

namespace {

namespace fs = std::filesystem;

// Valid neighbours for the data set loader: two runs (the robot is kOmni3ExampleYaml).
constexpr const char* kEncoderCsv = "t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,3\n0.02,1,2,3\n";
constexpr const char* kGroundTruthCsv = "t,x,y,theta\n0,0,0,0\n0.02,0.001,0,0\n";
// A second run of its own: one file listed for two runs is refused as a duplicated run.
constexpr const char* kEncoderCsv2 = "t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,3\n0.02,1,2,4\n";
constexpr const char* kGroundTruthCsv2 = "t,x,y,theta\n0,0,0,0\n0.02,0.002,0,0\n";

void WriteFile(const std::string& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("fuzz: cannot write " + path);
}

// One scratch directory per process, removed at exit.
class ScratchDir {
 public:
  ScratchDir() {
    std::string tmpl = (fs::temp_directory_path() / "fitcal-fuzz-XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("fuzz: mkdtemp failed");
    path_ = tmpl;
    WriteFile(path_ + "/robot.yaml", kOmni3ExampleYaml);
    WriteFile(path_ + "/enc.csv", kEncoderCsv);
    WriteFile(path_ + "/gt.csv", kGroundTruthCsv);
    // The rosbag2 seeds' robot (tests/fuzz_corpus_test.cc writes the seed bags).
    WriteFile(path_ + "/diff_drive.yaml", kDiffDriveExampleYaml);
    WriteFile(path_ + "/enc2.csv", kEncoderCsv2);
    WriteFile(path_ + "/gt2.csv", kGroundTruthCsv2);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

void FuzzEncoderCsv(const std::string& path, const std::optional<EncoderTicks>& ticks) {
  const EncoderLog log = io::ReadEncoderCsv(path, ticks);
  // Contract of a loaded log (run_log.h): one sample per interval, positive dt.
  if (log.samples.size() + 1 != log.t_s.size()) throw std::logic_error("sample count mismatch");
  for (const auto& s : log.samples) {
    if (!(s.dt_s > 0.0)) throw std::logic_error("non-positive dt accepted");
    for (int i = 0; i < log.samples.num_channels(); ++i) {
      if (!std::isfinite(s.value[i])) throw std::logic_error("non-finite wheel rate accepted");
    }
  }
}

void FuzzGroundTruth(const std::string& path) {
  const GroundTruthTrack track = io::ReadGroundTruth(path);
  if (track.t_s.size() != track.world_T_robot.size() || track.t_s.size() < 2) {
    throw std::logic_error("inconsistent ground-truth track");
  }
}

void FuzzDataset(const std::string& dir) {
  io::DatasetOptions options;
  options.num_threads = 1;
  const io::Dataset dataset = io::LoadDataset(dir, options);
  // Nothing outside the scratch directory may have been read.
  for (const RunLog& run : dataset.runs) {
    if (run.encoders.t_s.size() < 2) throw std::logic_error("run without samples accepted");
  }
}

void FuzzOmni3Robot(const std::string& path) {
  if (io::ReadRobotModel(path) != "omni3") return;
  const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(ReadOmni3Robot(path));
  // Round trip: what fitcal writes, fitcal must read back.
  const std::string again = path + ".out.yaml";
  WriteFile(again, model->RobotYaml(model->robot().nominal, ""));
  try {
    ReadOmni3Robot(again);
  } catch (const io::InputError& e) {
    throw std::logic_error(std::string("written robot YAML does not read back: ") + e.what());
  }
}

void FuzzAsocRobot(const std::string& path) {
  if (io::ReadRobotModel(path) != "asoc") return;
  const io::AsocRobot robot = io::ReadAsocRobot(path);
  const std::string again = path + ".out.yaml";
  WriteFile(again, io::AsocRobotYaml(robot));
  try {
    io::ReadAsocRobot(again);
  } catch (const io::InputError& e) {
    throw std::logic_error(std::string("written ASOC robot YAML does not read back: ") + e.what());
  }
}

// `fitcal import rosbag2` up to the data set it would write: bag file, topics, stamps, runs.
void FuzzRosbag2Import(const std::string& path, const std::string& dir) {
  ImportRosbag2Options o;
  o.bag = path;
  o.robot = dir + "/diff_drive.yaml";
  o.joints = {"right_wheel_joint", "left_wheel_joint"};
  o.ground_truth = "/mocap/pose";
  o.quiet = true;
  const Rosbag2Import imp = ReadRosbag2Import(o);
  if (imp.runs.empty() || imp.encoder_t_s.size() != imp.runs.size()) {
    throw std::logic_error("import without runs accepted");
  }
  for (std::size_t i = 0; i < imp.runs.size(); ++i) {
    const RunLog& run = imp.runs[i];
    if (run.encoders.t_s.size() < 2 || run.ground_truth.t_s.size() < 2 ||
        imp.encoder_values[i].size() != 2 * imp.encoder_t_s[i].size()) {
      throw std::logic_error("inconsistent imported run");
    }
    for (std::size_t k = 1; k < run.encoders.t_s.size(); ++k) {
      if (!(run.encoders.t_s[k] > run.encoders.t_s[k - 1])) {
        throw std::logic_error("non-increasing encoder stamps accepted");
      }
    }
    for (double v : imp.encoder_values[i]) {
      if (!std::isfinite(v)) throw std::logic_error("non-finite wheel rate accepted");
    }
  }
}

}  // namespace

std::vector<std::string> FuzzTargetNames() {
  std::vector<std::string> names;
#define FITCAL_FUZZ_TARGET(name, file, call) names.push_back(#name);
#include "tests/fuzz/loader_fuzz_targets.h"
#undef FITCAL_FUZZ_TARGET
  return names;
}

bool RunFuzzTarget(const std::string& target, std::string_view bytes) {
  static const ScratchDir scratch;
  const std::string& dir = scratch.path();
#define FITCAL_FUZZ_TARGET(name, file, call)   \
  if (target == #name) {                       \
    const std::string path = dir + "/" + file; \
    WriteFile(path, bytes);                    \
    try {                                      \
      call;                                    \
    } catch (const io::InputError&) {          \
      return false;                            \
    }                                          \
    return true;                               \
  }
#include "tests/fuzz/loader_fuzz_targets.h"
#undef FITCAL_FUZZ_TARGET
  (void)dir;
  throw std::invalid_argument("unknown fuzz target '" + target + "'");
}

}  // namespace fitcal::fuzz
