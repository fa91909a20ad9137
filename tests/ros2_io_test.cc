// ROS 2 in and out: `fitcal import rosbag2` and `fitcal export ros2-control`.
//
// Import: a simulated differential drive (sim/) is written as a bag the way a robot records
// it - sensor_msgs/msg/JointState with cumulative wheel angles (extra joint, another joint order,
// rest messages between runs) and geometry_msgs/msg/PoseStamped ground truth, header stamps, the
// recording time a few ms later - in both storage formats, compressed or not, split in two files.
// The imported data set must fit to the same parameters as the simulator's own CSV data set.
// Export: every controller's YAML parses, holds the documented keys and reads back to the
// parameters it can represent.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>

#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "fit/track_residual.h"
#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/rosbag2/bag_reader.h"
#include "tests/bags/bag_writer.h"
#include "io/rosbag2/ros_messages.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "models/omni/omni_model.h"
#include "models/omni3/omni3_robot_model.h"
#include "models/tricycle/tricycle_model.h"
#include "odometry/aligned_run.h"
#include "tests/robot_bag.h"
#include "tests/test_files.h"
#include "io/command_failure.h"
#include "cli/export_ros2_control.h"
#include "cli/import_rosbag2.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "sim/model_simulator.h"
#include "models/tricycle/tricycle_trajectories.h"

namespace fitcal {
namespace ros2_io_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

namespace fs = std::filesystem;
using namespace io::rosbag2;

using namespace testing::robot_bag;  // the simulated robot and its bag (tests/robot_bag.h)

// The export of a calibration file, as `fitcal export ros2-control` reads it: the controller and
// distribution checked before the file is read.
Ros2ControlExport ExportRos2Control(const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro = RosDistros().back()) {
  CheckControllerDistro(controller, ros_distro);
  return fitcal::ExportRos2Control(ReadRobotModelFile(calibration_path), calibration_path,
                                   controller, node_name, joints, ros_distro);
}

ImportRosbag2Options ImportOptions(const testing::TempDir& tmp, const fs::path& bag) {
  ImportRosbag2Options o;
  o.bag = bag.string();
  o.out = tmp.Path("imported");
  o.robot = tmp.Write("robot.yaml", kDiffDriveExampleYaml);
  o.joints = {"right_wheel_joint", "left_wheel_joint"};
  o.ground_truth = "/mocap/pose";
  o.quiet = true;
  return o;
}

ModelFitResult Fit(const RobotModelInterface& model, const std::vector<RunLog>& runs) {
  const ModelFitResult fit = FitModel(AlignRuns(runs), model);
  EXPECT_TRUE(fit.usable) << fit.termination << ": " << fit.message;
  EXPECT_TRUE(fit.has_covariance) << fit.covariance_message;
  return fit;
}

struct BagCase {
  const char* name;
  StorageFormat storage;
  Compression compression;
  bool split_at_rest;  // else --runs from the known spans
};

class ImportEqualsCsv : public ::testing::TestWithParam<BagCase> {};

// Tolerance: the bag holds the angles the simulator integrated (rate x dt, summed: relative
// rounding ~1e-13 of a wheel's ~1e3 rad), ns stamps (t moves by <= 0.5 ns: pose error <= 0.3 m/s
// x 0.5 ns = 1.5e-10 m) and the importer writes 17 significant digits. Against 1 mm / 0.2 deg of
// ground-truth noise these move the fit by ~1e-7 of its sigma and the CF by ~1e-10 m; 1e-3 sigma
// and 1e-9 leave room. A lost interval or run moves both far more (a wrong span did: CF +4 %);
// a swapped wheel makes the runs unexplainable (checked below).
constexpr double kSigmaFraction = 1e-3;

TEST_P(ImportEqualsCsv, SameFitAsTheSimulatorsCsv) {
  const BagCase& c = GetParam();
  testing::TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  const std::vector<sim::ModelSimulatedRun> sim_runs = SimulatedRuns(*model);
  BagWriterOptions bag_options;
  bag_options.storage = c.storage;
  bag_options.mcap.compression = c.compression;
  bag_options.mcap.chunk_bytes = 64 * 1024;
  const auto spans = WriteRobotBag(tmp.path() / "bag", sim_runs, bag_options);
  ImportRosbag2Options o = ImportOptions(tmp, tmp.path() / "bag");
  if (c.split_at_rest) {
    o.split_at_rest_s = 2.0;  // the gaps (3 s + the runs' rests), not the 0.6 s corner stops
  } else {
    char text[64];
    for (const auto& [t0, t1] : spans) {
      // Half an encoder period into the gaps: a span given in decimal seconds must not lose the
      // run's first or last stamp to rounding (the gaps hold rest messages only).
      std::snprintf(text, sizeof text, "%s%.9f:%.9f", o.runs.empty() ? "" : ",",
                    t0 - 0.5 * kEncoderPeriodS, t1 + 0.5 * kEncoderPeriodS);
      o.runs += text;
    }
  }
  const Rosbag2Import in_memory = ImportRosbag2(o);
  const io::Dataset imported = io::LoadDataset(io::ReadDatasetIndex(o.out),
                                               ReadRobotModelFile(o.out + "/robot.yaml")->robot());
  ASSERT_EQ(imported.runs.size(), sim_runs.size());
  // The CSVs read back to the importer's doubles bit for bit (t: to the ns it writes).
  ASSERT_EQ(in_memory.runs.size(), imported.runs.size());
  for (std::size_t i = 0; i < imported.runs.size(); ++i) {
    const EncoderLog& a = in_memory.runs[i].encoders;
    const EncoderLog& b = imported.runs[i].encoders;
    ASSERT_EQ(a.t_s.size(), b.t_s.size());
    for (std::size_t k = 0; k < a.t_s.size(); ++k) EXPECT_NEAR(a.t_s[k], b.t_s[k], 0.5e-9);
    for (std::size_t k = 0; k < a.samples.size(); ++k) {
      for (int j = 0; j < a.samples.num_channels(); ++j) {
        ASSERT_EQ(a.samples[k].value[j], b.samples[k].value[j]) << "run " << i << " row " << k;
      }
    }
    const GroundTruthTrack& g = in_memory.runs[i].ground_truth;
    const GroundTruthTrack& h = imported.runs[i].ground_truth;
    ASSERT_EQ(g.t_s.size(), h.t_s.size());
    for (std::size_t k = 0; k < g.t_s.size(); ++k) {
      ASSERT_EQ(g.world_T_robot[k].x, h.world_T_robot[k].x);
      ASSERT_EQ(g.world_T_robot[k].y, h.world_T_robot[k].y);
    }
  }
  std::vector<RunLog> csv;
  for (const sim::ModelSimulatedRun& r : sim_runs) csv.push_back(r.log);
  const ModelFitResult from_bag = Fit(*model, imported.runs);
  const ModelFitResult from_csv = Fit(*model, csv);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::abs(from_bag.parameters[k] - from_csv.parameters[k]),
              kSigmaFraction * from_csv.sigma[k])
        << model->robot().parameters[k].name;
    EXPECT_LT(std::abs(from_csv.parameters[k] - kTruth[k]), 5.0 * from_csv.sigma[k]);
  }
  const double cf_bag = EvaluateFinalPoseErrors(*model, kTruth, AlignRuns(imported.runs)).cf;
  const double cf_csv = EvaluateFinalPoseErrors(*model, kTruth, AlignRuns(csv)).cf;
  EXPECT_NEAR(cf_bag, cf_csv, 1e-9);

  // The same bag with the wheels' joints swapped: a different robot, many sigmas away. The
  // import refuses it as miswired (exit 4, rosbag2_cli_test) unless told to write it anyway.
  o.joints = {"left_wheel_joint", "right_wheel_joint"};
  o.force = true;
  o.skip_mapping_check = true;
  ImportRosbag2(o);
  const io::Dataset swapped = io::LoadDataset(io::ReadDatasetIndex(o.out), model->robot());
  const ModelFitResult wrong = FitModel(AlignRuns(swapped.runs), *model);
  const double cf_wrong =
      EvaluateFinalPoseErrors(*model, wrong.parameters, AlignRuns(swapped.runs)).cf;
  const double cf_right =
      EvaluateFinalPoseErrors(*model, from_bag.parameters, AlignRuns(imported.runs)).cf;
  EXPECT_GT(cf_wrong, 10.0 * cf_right);
}

INSTANTIATE_TEST_SUITE_P(
    Bags, ImportEqualsCsv,
    ::testing::Values(BagCase{"sqlite3_runs", StorageFormat::kSqlite3, Compression::kNone, false},
                      BagCase{"sqlite3_rests", StorageFormat::kSqlite3, Compression::kNone, true},
                      BagCase{"mcap_runs", StorageFormat::kMcap, Compression::kNone, false},
                      BagCase{"mcap_zstd_rests", StorageFormat::kMcap, Compression::kZstd, true},
                      BagCase{"mcap_lz4_runs", StorageFormat::kMcap, Compression::kLz4, false}),
    [](const ::testing::TestParamInfo<BagCase>& p) { return p.param.name; });

// A ground truth whose headers are stamped 0.15 s late (a motion-capture bridge's latency),
// imported as it is: the runs of one bag share its label, so `--clock-offsets session` is one
// offset for the bag, and the track fit recovers it like any other data set's (within 4 of its
// sigmas plus half an encoder period, the replay's timing convention: tests/clock_offset_test.cc).
TEST(ImportRosbag2ClockOffset, OneOffsetPerBagRecoversAPoseLatency) {
  constexpr std::int64_t kLatencyNs = 150000000;
  testing::TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  BagEdits edits;
  edits.pose = [](std::size_t, PoseStamped* p) {
    const std::int64_t ns = static_cast<std::int64_t>(p->header.stamp.sec) * 1000000000 +
                            p->header.stamp.nanosec + kLatencyNs;
    p->header.stamp = {static_cast<std::int32_t>(ns / 1000000000),
                       static_cast<std::uint32_t>(ns % 1000000000)};
  };
  WriteRobotBag(tmp.path() / "bag", SimulatedRuns(*model), BagWriterOptions{}, edits);
  ImportRosbag2Options o = ImportOptions(tmp, tmp.path() / "bag");
  o.split_at_rest_s = 2.0;
  ImportRosbag2(o);
  const io::Dataset imported = io::LoadDataset(io::ReadDatasetIndex(o.out), model->robot());
  const std::vector<AlignedRun> runs = AlignRuns(imported.runs);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : imported.runs) tracks.push_back(&log.ground_truth);
  const TrackFitData data = MakeTrackFitData(runs, tracks, ClockGrouping::kPerSession);
  ASSERT_EQ(data.clock_groups.size(), 1u);
  ModelFitOptions options;
  options.residuals = ResidualKind::kTrack;
  options.track = &data;
  options.ceres.num_threads = 1;
  const ModelFitResult fit = FitModel(runs, *model, options);
  ASSERT_TRUE(fit.usable && fit.has_covariance) << fit.termination << fit.covariance_message;
  EXPECT_NEAR(fit.clock_offsets_s[0], 1e-9 * kLatencyNs,
              4.0 * fit.clock_offset_sigma_s[0] + 0.5 * kEncoderPeriodS);
  EXPECT_LT(fit.clock_offset_sigma_s[0], 0.01);
}

// ---------------------------------------------------------------------------------------------
// Malformed bags: one line, non-zero exit, nothing written (no data set, no temporary sibling).

class CaptureStderr {
 public:
  CaptureStderr() : old_(std::cerr.rdbuf(text_.rdbuf())) {}
  ~CaptureStderr() { std::cerr.rdbuf(old_); }
  std::string str() const { return text_.str(); }

 private:
  std::ostringstream text_;
  std::streambuf* old_;
};

void ExpectRefused(const ImportRosbag2Options& o, const std::string& what) {
  int rc = 0;
  std::string err;
  {
    CaptureStderr capture;
    rc = tools::RunImportRosbag2Command(o);
    err = capture.str();
  }
  EXPECT_NE(rc, 0) << what;
  EXPECT_EQ(err.rfind("fitcal import rosbag2: ", 0), 0u) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find(what), std::string::npos) << err;
  const fs::path out(o.out);
  EXPECT_FALSE(fs::exists(out)) << what;
  for (const auto& e : fs::directory_iterator(out.parent_path())) {
    EXPECT_EQ(e.path().filename().string().rfind(out.filename().string() + ".", 0),
              std::string::npos)
        << "left behind: " << e.path();
  }
}

class MalformedImport : public ::testing::Test {
 protected:
  void SetUp() override {
    const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
    runs_ = SimulatedRuns(*model);
    runs_.resize(2);
  }
  fs::path Bag(const std::string& name, StorageFormat storage, const BagEdits& edits = {}) {
    BagWriterOptions options;
    options.storage = storage;
    WriteRobotBag(tmp_.path() / name, runs_, options, edits);
    return tmp_.path() / name;
  }
  // The bag imported (as the user would, split at the rests between runs).
  Rosbag2Import Import(const fs::path& bag, const std::string& out) {
    ImportRosbag2Options o = ImportOptions(tmp_, bag);
    o.out = tmp_.Path(out);
    o.split_at_rest_s = 2.0;
    return ImportRosbag2(o);
  }
  testing::TempDir tmp_;
  std::vector<sim::ModelSimulatedRun> runs_;
};

TEST_F(MalformedImport, TruncatedAndBadMagic) {
  for (StorageFormat storage : {StorageFormat::kMcap, StorageFormat::kSqlite3}) {
    const fs::path bag = Bag(storage == StorageFormat::kMcap ? "m" : "s", storage);
    const std::string ext = storage == StorageFormat::kMcap ? "_0.mcap" : "_0.db3";
    const fs::path file = bag / (bag.filename().string() + ext);
    const std::string bytes = testing::ReadFileBytes(file);
    testing::WriteFileBytes(file, bytes.substr(0, bytes.size() / 2));
    ExpectRefused(ImportOptions(tmp_, bag), file.string());
    std::string bad = bytes;
    bad.replace(1, 4, "XXXX");
    testing::WriteFileBytes(file, bad);
    ExpectRefused(ImportOptions(tmp_, bag), "magic");
  }
}

TEST_F(MalformedImport, TopicTypeJointAndStamps) {
  const fs::path bag = Bag("b", StorageFormat::kMcap);
  ImportRosbag2Options o = ImportOptions(tmp_, bag);
  o.ground_truth = "/vicon/pose";
  ExpectRefused(o, "topic \"/vicon/pose\" is not in the bag");
  o.ground_truth = "/chatter";
  ExpectRefused(o, "has type \"std_msgs/msg/String\"");
  o = ImportOptions(tmp_, bag);
  o.joints = {"right_wheel_joint", "rear_wheel_joint"};
  ExpectRefused(o, "joint \"rear_wheel_joint\" is not in the message");
  // Two runs written on the same clock origin: the second one's stamps go back in time.
  BagWriterOptions options;
  WriteRobotBag(tmp_.path() / "x", {runs_[0]}, options);
  {
    BagWriter twice((tmp_.path() / "twice").string(), options);
    twice.AddTopic("/joint_states", "sensor_msgs/msg/JointState");
    twice.AddTopic("/mocap/pose", "geometry_msgs/msg/PoseStamped");
    BagReader once((tmp_.path() / "x").string());
    BagMessage m;
    std::vector<std::pair<std::string, std::vector<std::uint8_t>>> all;
    std::vector<std::int64_t> times;
    while (once.ReadNext(&m)) {
      all.push_back({m.topic->name, {m.payload.data, m.payload.data + m.payload.size}});
      times.push_back(m.time_ns);
    }
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t i = 0; i < all.size(); ++i) {
        twice.Write(all[i].first, times[i] + pass * (times.back() - times.front() + 1000000),
                    ByteView(all[i].second));
      }
    }
    twice.Close();
  }
  ExpectRefused(ImportOptions(tmp_, tmp_.path() / "twice"), "is not after the previous one");
  o = ImportOptions(tmp_, tmp_.path() / "twice");
  // The recording times do increase, but the wheel angles jump back where the second copy
  // starts: a data set `fit` refuses, so the import refuses it (it used to write it).
  o.stamp = "recorded";
  ExpectRefused(o, "imported/runs/twice-01_encoders.csv:");
  ExpectRefused(o, "is not a physical wheel rate");
}

// ---------------------------------------------------------------------------------------------
// Bags as real robots record them (issue 33): each one either imported exactly as the clean bag
// or refused in one line naming where.

// Same runs, same encoder rows to 1e-9 rad/s (an unwrapped angle is the cumulative one up to
// the rounding of ~1e3 rad sums, ~1e-13 rad, over 0.05 s), same ground truth.
void ExpectSameImport(const Rosbag2Import& a, const Rosbag2Import& b) {
  ASSERT_EQ(a.runs.size(), b.runs.size());
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    ASSERT_EQ(a.encoder_t_s[i], b.encoder_t_s[i]) << "run " << i;
    ASSERT_EQ(a.encoder_values[i].size(), b.encoder_values[i].size());
    for (std::size_t k = 0; k < a.encoder_values[i].size(); ++k) {
      ASSERT_NEAR(a.encoder_values[i][k], b.encoder_values[i][k], 1e-9) << "run " << i;
    }
    ASSERT_EQ(a.runs[i].ground_truth.t_s, b.runs[i].ground_truth.t_s);
  }
}

TEST_F(MalformedImport, ZeroOrNonUnitQuaternionRefusedWithTopicAndTime) {
  for (const double scale : {0.0, 0.5}) {
    BagEdits edits;
    edits.pose = [&](std::size_t i, PoseStamped* p) {
      if (i != 17) return;
      Quaternion& q = p->pose.orientation;
      q = {q.x * scale, q.y * scale, q.z * scale, q.w * scale};
    };
    const fs::path bag = Bag(scale == 0.0 ? "zero_q" : "half_q", StorageFormat::kMcap, edits);
    const std::string what = scale == 0.0 ? "is a zero quaternion" : "is not a unit quaternion";
    ExpectRefused(ImportOptions(tmp_, bag), what);
    ExpectRefused(ImportOptions(tmp_, bag), "/mocap/pose message at ");
  }
}

TEST_F(MalformedImport, WrappedJointPositionsUnwrapped) {
  const Rosbag2Import clean = Import(Bag("clean", StorageFormat::kMcap), "clean_out");
  BagEdits edits;
  edits.joint = [](std::size_t, JointState* js) {
    for (double& angle : js->position) angle = WrapAngle(angle);
  };
  const Rosbag2Import wrapped = Import(Bag("wrapped", StorageFormat::kMcap, edits), "w");
  ExpectSameImport(clean, wrapped);
  ASSERT_EQ(wrapped.notes.size(), 2u);  // both wheels (the caster is not the robot's)
  EXPECT_NE(wrapped.notes[0].find("unwrapped"), std::string::npos) << wrapped.notes[0];
  // The other convention, [0, 2 pi).
  edits.joint = [](std::size_t, JointState* js) {
    for (double& angle : js->position) angle = WrapAngle(angle) + M_PI;
  };
  BagEdits shifted;  // the same bag with every angle + pi: the rates are unchanged
  shifted.joint = [](std::size_t, JointState* js) {
    for (double& angle : js->position) angle += M_PI;
  };
  ExpectSameImport(Import(Bag("shifted", StorageFormat::kMcap, shifted), "s"),
                   Import(Bag("wrapped_0_2pi", StorageFormat::kMcap, edits), "w2"));
  // A glitch of 2 rad in one wrapped reading: a step nobody can unwrap with confidence.
  edits.joint = [](std::size_t i, JointState* js) {
    for (double& angle : js->position) angle = WrapAngle(angle + (i == 40 ? 2.0 : 0.0));
  };
  ExpectRefused(ImportOptions(tmp_, Bag("glitch", StorageFormat::kMcap, edits)),
                "too fast to unwrap");
}

TEST_F(MalformedImport, OtherNodesJointStatesSkipped) {
  const Rosbag2Import clean = Import(Bag("clean", StorageFormat::kSqlite3), "clean_out");
  BagEdits edits;
  edits.other_node = true;
  const Rosbag2Import mixed = Import(Bag("mixed", StorageFormat::kSqlite3, edits), "m");
  ExpectSameImport(clean, mixed);
}

TEST_F(MalformedImport, RecordingClockSteppingBack) {
  for (StorageFormat storage : {StorageFormat::kMcap, StorageFormat::kSqlite3}) {
    const bool mcap = storage == StorageFormat::kMcap;
    const Rosbag2Import clean =
        Import(Bag(mcap ? "clean_m" : "clean_s", storage), mcap ? "cm" : "cs");
    BagEdits edits;
    edits.clock_step_back_ns = 1500000000;  // 1.5 s, halfway through the recording
    const fs::path bag = Bag(mcap ? "step_m" : "step_s", storage, edits);
    ImportRosbag2Options o = ImportOptions(tmp_, bag);
    o.stamp = "recorded";
    // 1.5 s less the recorder's latency jitter (0.4 ms) between the messages either side.
    ExpectRefused(o, "the recording clock steps back by 1.4");
    // The header stamps still order every stream: imported as the clean bag, with a note.
    const Rosbag2Import stepped = Import(bag, mcap ? "sm" : "ss");
    ExpectSameImport(clean, stepped);
    ASSERT_EQ(stepped.notes.size(), 1u);
    EXPECT_NE(stepped.notes[0].find("order of their header stamps"), std::string::npos);
  }
}

// A ground truth whose frame changes mid-bag (a localisation restarted in `map`) holds poses of
// two frames: refused naming the message, where it was imported without a word.
TEST_F(MalformedImport, GroundTruthFrameChangingMidBagIsRefused) {
  BagEdits edits;
  edits.pose = [](std::size_t i, PoseStamped* p) { p->header.frame_id = i < 40 ? "world" : "map"; };
  ExpectRefused(ImportOptions(tmp_, Bag("frames", StorageFormat::kMcap, edits)),
                "header.frame_id \"map\" differs from \"world\" of the topic's first message");
}

// A second tracked body's poses interleaved on the ground-truth topic: every other sample jumps
// 4 m away and back. Refused as that (the loader's ground-truth glitches), where it was written
// and `fit` then blamed millimetres.
TEST_F(MalformedImport, TwoBodiesOnTheGroundTruthTopicAreRefused) {
  BagEdits edits;
  edits.pose = [](std::size_t i, PoseStamped* p) {
    if (i % 2 == 1) p->pose.position.x += 4.0;
  };
  ExpectRefused(ImportOptions(tmp_, Bag("bodies", StorageFormat::kMcap, edits)),
                "samples are ground-truth glitches");
}

// Header stamps on another clock than the recorder's (simulated time from near 0): the data set's
// t = 0 is the first stamp, said in a note, not the recording's start 1.7e9 s later (times of
// -1.7e9 s that --runs could not name). The runs and their rows are the clean bag's.
TEST_F(MalformedImport, HeaderStampsOnAnotherClockStartAtTheFirstStamp) {
  const Rosbag2Import clean = Import(Bag("clean", StorageFormat::kSqlite3), "clean_out");
  constexpr std::int32_t kBehindS = 1'600'000'000;
  BagEdits edits;
  edits.joint = [](std::size_t, JointState* js) { js->header.stamp.sec -= kBehindS; };
  edits.pose = [](std::size_t, PoseStamped* p) { p->header.stamp.sec -= kBehindS; };
  const Rosbag2Import shifted = Import(Bag("sim_time", StorageFormat::kSqlite3, edits), "s");
  ASSERT_EQ(shifted.runs.size(), clean.runs.size());
  ASSERT_EQ(shifted.notes.size(), 1u);
  EXPECT_NE(shifted.notes[0].find("another clock than the recorder's"), std::string::npos);
  EXPECT_GE(shifted.encoder_t_s[0].front(), 0.0);
  EXPECT_LT(shifted.encoder_t_s[0].front(), 60.0);
}

// A bag given as `.` (the user inside its folder) is named after the folder: its runs were
// `.-01`, files the shell hides.
TEST_F(MalformedImport, ABagGivenAsDotIsNamedAfterItsFolder) {
  const fs::path bag = Bag("named", StorageFormat::kMcap);
  const fs::path before = fs::current_path();
  fs::current_path(bag);
  ImportRosbag2Options o = ImportOptions(tmp_, ".");
  o.out = tmp_.Path("dot_out");
  o.split_at_rest_s = 2.0;
  const Rosbag2Import imported = ImportRosbag2(o);
  fs::current_path(before);
  ASSERT_FALSE(imported.runs.empty());
  EXPECT_EQ(imported.runs[0].id.rfind("named-", 0), 0u) << imported.runs[0].id;
}

// Spans that share samples would put one motion into a training and a held-out run.
TEST_F(MalformedImport, OverlappingRunSpansAreAUsageError) {
  ImportRosbag2Options o = ImportOptions(tmp_, Bag("spans", StorageFormat::kMcap));
  o.runs = "0:10,5:20";
  EXPECT_THROW(ImportRosbag2(o), UsageError);
}

// A reader must not write next to its input: the recorder's own sqlite3 bag (WAL mode), copied
// and made read-only, is read without a byte or a file changing around it.
TEST(Rosbag2ReadOnly, BagDirectoryUnchanged) {
  testing::TempDir tmp;
  const fs::path shared = fs::path(FITCAL_SHARED_DIR) / "data/rosbag2";
  if (!fs::exists(shared)) GTEST_SKIP() << shared << " missing";
  const fs::path bag = tmp.path() / "bags";
  // Copied file by file: fs::copy would give the copies the shared tree's missing write bits
  // before their contents are in (CI lays ../shared read-only).
  for (const auto& e : fs::recursive_directory_iterator(shared)) {
    const fs::path to = bag / fs::relative(e.path(), shared);
    if (e.is_directory()) {
      fs::create_directories(to);
    } else {
      fs::create_directories(to.parent_path());
      testing::WriteFileBytes(to, testing::ReadFileBytes(e.path()));
    }
  }
  // Every path with its size and an FNV-1a 64 checksum of its bytes ("dir" for a directory).
  const auto listing = [&] {
    std::vector<std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(bag)) {
      std::string entry = fs::relative(e.path(), bag).string() + " ";
      if (e.is_regular_file()) {
        const std::string bytes = testing::ReadFileBytes(e.path());
        std::uint64_t h = 14695981039346656037ull;
        for (const char c : bytes) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
        entry += std::to_string(bytes.size()) + " " + std::to_string(h);
      } else {
        entry += "dir";
      }
      files.push_back(entry);
    }
    std::sort(files.begin(), files.end());
    return files;
  };
  for (const auto& e : fs::recursive_directory_iterator(bag)) {
    fs::permissions(e.path(), fs::perms::owner_write | fs::perms::group_write |
                                  fs::perms::others_write,
                    fs::perm_options::remove);
  }
  const auto before = listing();
  std::size_t messages = 0;
  for (const char* dir : {"sqlite3/talker", "sqlite3/cdr_test", "mcap/talker", "mcap/cdr_test"}) {
    BagReader reader((bag / dir).string());
    BagMessage m;
    while (reader.ReadNext(&m)) ++messages;
    std::string file;
    EXPECT_FALSE(reader.RecordingClockStepBack(&file)) << dir;
  }
  EXPECT_GT(messages, 10u);
  EXPECT_EQ(listing(), before);  // no -shm / -wal file, no byte changed
  for (const auto& e : fs::recursive_directory_iterator(bag)) {
    fs::permissions(e.path(), fs::perms::owner_write, fs::perm_options::add);
  }
}

// ---------------------------------------------------------------------------------------------
// Export

struct Exported {
  YAML::Node params;
  Ros2ControlExport e;
  // What the controller computes (e.model at e.parameters), by parameter name.
  double Back(const std::string& name) const {
    return e.parameters[RequireParameterIndex(e.model->robot(), name)];
  }
};

Exported ExportAndRead(const std::string& cal, const std::string& controller) {
  Exported x;
  x.e = ExportRos2Control(cal, controller, "", {});
  const YAML::Node root = YAML::Load(x.e.parameters_yaml);
  EXPECT_TRUE(root[controller]) << x.e.parameters_yaml;
  x.params = root[controller]["ros__parameters"];
  EXPECT_TRUE(x.params.IsMap()) << x.e.parameters_yaml;
  EXPECT_EQ(x.e.parameters.size(), x.e.model->robot().parameters.size());
  return x;
}

// The controller reads 12-digit decimals: 1e-11 relative.
constexpr double kRoundTrip = 1e-11;

// The tables the export reads the calibration through (models/model_interface.h,
// models/omni/omni_model.h): parameters by name, an omni robot's wheels with their fixed geometry.
TEST(ExportRos2Control, ParametersByNameAndOmniWheelsFromTheModel) {
  const RobotModelPtr diff = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  EXPECT_EQ(ParameterIndex(diff->robot(), "r_left"), 1);
  EXPECT_EQ(ParameterIndex(diff->robot(), "wheel_separation"), 2);
  EXPECT_FALSE(ParameterIndex(diff->robot(), "R_left"));
  EXPECT_THROW(RequireParameterIndex(diff->robot(), "wheelbase"), std::logic_error);
  EXPECT_FALSE(OmniWheelsOf(*diff, diff->robot().nominal));

  const RobotModelPtr mecanum = ReadRobotModel(YAML::Load(kOmniExampleYaml), "robot.yaml");
  std::vector<double> p = mecanum->robot().nominal;
  p[RequireParameterIndex(mecanum->robot(), "r_rl")] = 0.052;
  const std::vector<OmniWheel> wheels = *OmniWheelsOf(*mecanum, p);
  ASSERT_EQ(wheels.size(), 4u);
  EXPECT_EQ(wheels[2].name, "rl");
  EXPECT_EQ(wheels[2].radius_m, 0.052);
  EXPECT_NEAR(wheels[1].angle_rad, -36.86989765 * M_PI / 180, 1e-12);
  for (const OmniWheel& w : wheels) EXPECT_NEAR(w.drive_angle_rad, 0.0, 1e-12) << w.name;
  EXPECT_NEAR(wheels[1].roller_angle_rad, M_PI / 4, 1e-12);

  const RobotModelPtr omni3 = ReadRobotModel(YAML::Load(kOmni3ExampleYaml), "robot.yaml");
  const std::optional<std::vector<OmniWheel>> omni3_wheels =
      OmniWheelsOf(*omni3, omni3->robot().nominal);
  ASSERT_TRUE(omni3_wheels);
  for (const OmniWheel& w : *omni3_wheels) {
    EXPECT_EQ(w.drive_angle_rad, w.angle_rad + M_PI / 2) << w.name;  // tangential, CCW
    EXPECT_EQ(w.roller_angle_rad, 0.0);
  }
}

TEST(ExportRos2Control, DiffDriveIsExact) {
  testing::TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  const std::string cal = tmp.Write("cal.yaml", model->RobotYaml(kTruth, ""));
  const Exported x = ExportAndRead(cal, "diff_drive_controller");
  for (const char* key : {"wheel_separation", "wheel_radius", "left_wheel_radius_multiplier",
                          "right_wheel_radius_multiplier", "wheel_separation_multiplier"}) {
    EXPECT_TRUE(x.params[key]) << key;
  }
  EXPECT_EQ(x.params["left_wheel_names"][0].as<std::string>(), "left");
  EXPECT_TRUE(x.e.notes.empty());
  const double r = x.params["wheel_radius"].as<double>();
  EXPECT_NEAR(r * x.params["right_wheel_radius_multiplier"].as<double>(), kTruth[0], 1e-12);
  const char* const names[] = {"r_right", "r_left", "wheel_separation"};  // kTruth's order
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(x.Back(names[k]), kTruth[k], kRoundTrip * kTruth[k]) << names[k];
  }
  EXPECT_THROW(ExportRos2Control(cal, "tricycle_controller", "", {}), UsageError);
  EXPECT_THROW(ExportRos2Control(cal, "ackermann_controller", "", {}), UsageError);
}

TEST(ExportRos2Control, MecanumTakesMeans) {
  testing::TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kOmniExampleYaml), "robot.yaml");
  std::vector<double> p = model->robot().nominal;  // R x4, r x4, delta x4
  const double radii[] = {0.049, 0.050, 0.051, 0.0505};
  for (int i = 0; i < 4; ++i) p[4 + i] = radii[i];
  p[0] = 0.26;  // fl further out
  const std::string cal = tmp.Write("cal.yaml", model->RobotYaml(p, ""));
  const Exported x = ExportAndRead(cal, "mecanum_drive_controller");
  const YAML::Node k = x.params["kinematics"];
  ASSERT_TRUE(k["wheels_radius"] && k["sum_of_robot_center_projection_on_X_Y_axis"]);
  EXPECT_TRUE(x.params["front_left_wheel_command_joint_name"]);
  EXPECT_EQ(x.e.notes.size(), 2u);  // one radius, one lx + ly
  const double mean_r = (0.049 + 0.050 + 0.051 + 0.0505) / 4;
  EXPECT_NEAR(k["wheels_radius"].as<double>(), mean_r, 1e-12);
  // lx + ly of the nominal layout (0.2 + 0.15) with the front-left wheel at 0.26 m.
  const double fl =
      0.26 * (std::cos(36.86989765 * M_PI / 180) + std::sin(36.86989765 * M_PI / 180));
  EXPECT_NEAR(k["sum_of_robot_center_projection_on_X_Y_axis"].as<double>(), (fl + 3 * 0.35) / 4,
              1e-9);
  for (const char* wheel : {"fl", "fr", "rl", "rr"}) {
    EXPECT_NEAR(x.Back(std::string("r_") + wheel), mean_r, kRoundTrip);
  }
}

// Right wheels mounted turned round (drive direction 180 deg, as OptiOdom's omni4 records them)
// are the controller's wheels with the joint's sign turned: exported with a note to invert those
// joints (they were refused as not in the layout), and replayed as the data record them - the
// exported kinematics move the robot exactly as the calibrated ones on any wheel rates.
TEST(ExportRos2Control, MecanumWheelsDrivenBackwardsAreNotedAndReplayAsRecorded) {
  testing::TempDir tmp;
  std::string yaml = kOmniExampleYaml;
  for (const char* wheel : {"{name: fr,", "{name: rr,"}) {
    const std::size_t at = yaml.find("drive_angle_deg: 0", yaml.find(wheel));
    yaml.replace(at, 18, "drive_angle_deg: 180");
  }
  const RobotModelPtr model = ReadRobotModel(YAML::Load(yaml), "robot.yaml");
  const std::string cal = tmp.Write("cal.yaml", model->RobotYaml(model->robot().nominal, ""));
  const Exported x = ExportAndRead(cal, "mecanum_drive_controller");
  ASSERT_FALSE(x.e.notes.empty());
  EXPECT_NE(x.e.notes.front().find("joints fr, rr turn the other way"), std::string::npos)
      << x.e.notes.front();
  EncoderSamples samples(4);
  for (int k = 0; k < 200; ++k) {
    const double t = 0.01 * k;  // every wheel's rate different and changing
    samples.push_back(0.01, {3.0 + std::sin(t), -2.0 + t, 1.5 - std::cos(2 * t), -4.0 + 0.5 * t});
  }
  const Pose2d calibrated = model->ReplayFinalPose(model->robot().nominal.data(), samples, {});
  const Pose2d exported = x.e.model->ReplayFinalPose(x.e.parameters.data(), samples, {});
  EXPECT_GT(std::hypot(calibrated.x, calibrated.y), 0.1);  // it moves
  EXPECT_NEAR(exported.x, calibrated.x, 1e-9);
  EXPECT_NEAR(exported.y, calibrated.y, 1e-9);
  EXPECT_NEAR(exported.theta, calibrated.theta, 1e-9);
}

TEST(ExportRos2Control, OmniWheelsEquallySpacedAndSignNoted) {
  testing::TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kOmni3ExampleYaml), "robot.yaml");
  std::vector<double> p = model->robot().nominal;
  p[0] = 0.197;
  p[4] = 0.150;
  p[8] -= 0.01;  // wheel c 0.57 deg off, further from the x axis than a
  const std::string cal = tmp.Write("cal.yaml", model->RobotYaml(p, ""));
  const Exported x = ExportAndRead(cal, "omni_wheel_drive_controller");
  for (const char* key : {"wheel_radius", "robot_radius", "wheel_offset", "wheel_names"}) {
    EXPECT_TRUE(x.params[key]) << key;
  }
  EXPECT_EQ(x.e.notes.size(), 4u);  // radius, distance, spacing, sign convention
  // Wheels a (60 deg), b (180), c (300): a is nearest the x axis and comes first.
  EXPECT_EQ(x.params["wheel_names"][0].as<std::string>(), "a");
  const double offset = x.params["wheel_offset"].as<double>();
  // The circular mean of the angles' offsets (0, 0, -0.01 rad): -0.01 / 3 to O(0.01^3).
  EXPECT_NEAR(offset, 60 * M_PI / 180 - 0.01 / 3, 1e-6);
  const char* const wheels[] = {"a", "b", "c"};
  for (int i = 0; i < 3; ++i) {
    const std::string w = wheels[i];
    EXPECT_NEAR(x.Back("R_" + w), (0.197 + 2 * 0.195) / 3, kRoundTrip);
    EXPECT_NEAR(x.Back("r_" + w), (0.150 + 2 * 0.148) / 3, kRoundTrip);
    EXPECT_NEAR(WrapAngle(x.Back("delta_" + w) - offset - 2 * M_PI * i / 3), 0.0, 1e-9);
  }
}

TEST(ExportRos2Control, TricycleDropsTheSteeringOffset) {
  testing::TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kTricycleExampleYaml), "robot.yaml");
  const std::vector<double> p = {0.0331, 0.152, 1.5 * M_PI / 180};
  const std::string cal = tmp.Write("cal.yaml", model->RobotYaml(p, ""));
  const Exported x = ExportAndRead(cal, "tricycle_controller");
  EXPECT_NEAR(x.params["wheelbase"].as<double>(), 0.152, 1e-12);
  EXPECT_NEAR(x.params["wheel_radius"].as<double>(), 0.0331, 1e-12);
  EXPECT_EQ(x.params["steering_joint_name"].as<std::string>(), "steering");
  ASSERT_EQ(x.e.notes.size(), 1u);
  EXPECT_NE(x.e.notes[0].find("+1.500000 deg"), std::string::npos) << x.e.notes[0];
  const std::string traction = "r_" + x.e.model->robot().channels[0].name;
  EXPECT_NEAR(x.Back(traction), 0.0331, kRoundTrip);
  EXPECT_NEAR(x.Back("wheelbase"), 0.152, kRoundTrip);
  EXPECT_EQ(x.Back("steering_offset"), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Export per ROS 2 distribution: every key written is declared, with its type, by that
// distribution's controller (tests/data/ros2_controllers/<distro>/<controller>.txt: our
// extraction of the names and types from ros2_controllers' parameter definitions).

using KeyTypes = std::map<std::string, std::string>;

KeyTypes DeclaredKeys(const std::string& distro, const std::string& controller) {
  const fs::path file =
      fs::path(FITCAL_SOURCE_DIR) / "tests/data/ros2_controllers" / distro / (controller + ".txt");
  std::istringstream in(testing::ReadFileBytes(file));
  KeyTypes keys;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string key, type;
    words >> key >> type;
    keys[key] = type;
  }
  return keys;
}

// The parameters as "a.b.c" -> node (nested maps dotted, as the declarations name them).
void Flatten(const YAML::Node& map, const std::string& prefix,
             std::vector<std::pair<std::string, YAML::Node>>* out) {
  for (const auto& kv : map) {
    const std::string key = prefix + kv.first.as<std::string>();
    if (kv.second.IsMap()) {
      Flatten(kv.second, key + ".", out);
    } else {
      out->emplace_back(key, kv.second);
    }
  }
}

// What rclcpp makes of a YAML scalar: a double needs a '.' or an exponent, else it is an integer.
bool IsDoubleText(const YAML::Node& n) {
  if (!n.IsScalar() || n.Tag() == "!") return false;  // a quoted scalar is a string
  double v = 0.0;
  if (!YAML::convert<double>::decode(n, v)) return false;
  return n.Scalar().find_first_of(".eE") != std::string::npos;
}

void ExpectType(const std::string& key, const YAML::Node& n, const std::string& type) {
  if (type == "double") {
    EXPECT_TRUE(IsDoubleText(n)) << key << ": " << n;
  } else if (type == "int") {
    EXPECT_TRUE(n.IsScalar() && n.Scalar().find_first_not_of("-0123456789") == std::string::npos)
        << key << ": " << n;
  } else if (type == "string") {
    EXPECT_TRUE(n.IsScalar() && n.Tag() == "!") << key << " should be a quoted string: " << n;
  } else if (type == "string_array") {
    ASSERT_TRUE(n.IsSequence()) << key;
    for (const YAML::Node& e : n) EXPECT_EQ(e.Tag(), "!") << key << " holds a non-string";
  } else if (type == "double_array") {
    ASSERT_TRUE(n.IsSequence()) << key;
    for (const YAML::Node& e : n) EXPECT_TRUE(IsDoubleText(e)) << key << ": " << e;
  } else {
    ADD_FAILURE() << key << ": unknown declared type " << type;
  }
}

struct ControllerCase {
  const char* controller;
  std::string robot_yaml;
};

TEST(ExportRos2Control, EveryKeyDeclaredOnItsDistribution) {
  testing::TempDir tmp;
  const std::vector<ControllerCase> cases = {{"diff_drive_controller", kDiffDriveExampleYaml},
                                             {"mecanum_drive_controller", kOmniExampleYaml},
                                             {"omni_wheel_drive_controller", kOmni3ExampleYaml},
                                             {"tricycle_controller", kTricycleExampleYaml}};
  int checked = 0;
  for (const std::string& distro : RosDistros()) {
    for (const ControllerCase& c : cases) {
      SCOPED_TRACE(distro + " " + c.controller);
      const RobotModelPtr model = ReadRobotModel(YAML::Load(c.robot_yaml), "robot.yaml");
      std::vector<double> p = model->robot().nominal;
      p[0] *= 1.01;  // a calibration that differs from the nominal: every note written
      const std::string cal = tmp.Write("cal.yaml", model->RobotYaml(p, ""));
      const KeyTypes declared = DeclaredKeys(distro, c.controller);
      if (declared.empty()) {  // the distribution does not ship it: refused in one line
        EXPECT_THROW(ExportRos2Control(cal, c.controller, "", {}, distro),
                     UsageError);
        continue;
      }
      const Ros2ControlExport e = ExportRos2Control(cal, c.controller, "", {}, distro);
      OdometryCovariance covariance;  // as written with --logs
      covariance.twist_variance = {1e-4, 2e-5, 3e-4};
      covariance.pose_variance_1m = {1e-5, 2e-6, 3e-5};
      const std::string yaml =
          e.parameters_yaml + Ros2CovarianceParameters(c.controller, covariance);
      std::vector<std::pair<std::string, YAML::Node>> written;
      Flatten(YAML::Load(yaml)[c.controller]["ros__parameters"], "", &written);
      EXPECT_GE(written.size(), 4u);
      for (const auto& [key, node] : written) {
        const auto it = declared.find(key);
        if (it == declared.end()) {
          ADD_FAILURE() << key << " is not declared on " << distro;
          continue;
        }
        ExpectType(key, node, it->second);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 40);
  // The kept lists themselves: the key the issue found stale.
  EXPECT_EQ(DeclaredKeys("humble", "diff_drive_controller").count("wheels_per_side"), 1u);
  EXPECT_EQ(DeclaredKeys("jazzy", "diff_drive_controller").count("wheels_per_side"), 0u);
  EXPECT_EQ(DeclaredKeys("rolling", "diff_drive_controller").count("wheels_per_side"), 0u);
  EXPECT_THROW(
      ExportRos2Control(tmp.Path("cal.yaml"), "tricycle_controller", "", {}, "iron"),
      UsageError);
}

TEST(ExportRos2Control, TricycleOffsetStatedWithSignAndPlace) {
  testing::TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kTricycleExampleYaml), "robot.yaml");
  const double offset_rad = -2.25 * M_PI / 180;
  const std::string cal = tmp.Write("cal.yaml", model->RobotYaml({0.0331, 0.152, offset_rad}, ""));
  const Ros2ControlExport e = ExportRos2Control(cal, "tricycle_controller", "", {});
  ASSERT_EQ(e.notes.size(), 1u);
  const std::string& note = e.notes[0];
  char value[64];
  std::snprintf(value, sizeof value, "add %+.9g rad", offset_rad);
  EXPECT_NE(note.find(value), std::string::npos) << note;
  EXPECT_NE(note.find("-2.250000 deg"), std::string::npos) << note;
  EXPECT_NE(note.find("steering joint 'steering'"), std::string::npos) << note;
  EXPECT_NE(note.find("SimpleTransmission"), std::string::npos) << note;

  // The sign: the runs of a robot with this offset, their steering readings moved by the value
  // the note gives, replay with the exported parameters (no offset) exactly as with the
  // calibration; moved the other way they replay far worse.
  const std::vector<double> truth = {0.0331, 0.152, offset_rad};
  sim::SimulationOptions o;
  o.seed = 3;
  sim::TricycleTrajectoryOptions shapes;
  std::vector<AlignedRun> runs;
  for (const sim::ModelSimulatedRun& r :
       sim::SimulateRuns(*model, truth, sim::TricycleTrajectories(shapes), o)) {
    runs.push_back(AlignRun(r.log));
  }
  const double added_rad = std::stod(note.substr(note.find("add ") + 4));
  const auto moved = [&](double by_rad) {
    std::vector<AlignedRun> out = runs;
    for (AlignedRun& r : out) {
      for (std::size_t k = 0; k < r.samples.size(); ++k) r.samples[k].value[1] += by_rad;
    }
    return EvaluateFinalPoseErrors(*e.model, e.parameters, out).cf;
  };
  const double cf_exact = EvaluateFinalPoseErrors(*model, truth, runs).cf;
  EXPECT_NEAR(moved(added_rad), cf_exact, 1e-9);  // noise-free runs: both ~0
  EXPECT_GT(moved(-added_rad), 100.0 * cf_exact + 1e-3);
}

// ---------------------------------------------------------------------------------------------
// Export replayed on a data set, as a user runs it.

std::string Fitcal(const testing::TempDir& dir, const std::string& args, int expected_exit) {
  const testing::FitcalRun r = testing::RunFitcal(dir, args);
  EXPECT_EQ(r.exit_code, expected_exit) << args << "\n" << r.out << r.err;
  return r.out + r.err;
}

// Issue 30: after `fit --train-trajectories` the export filtered held-out runs by repetition,
// found none (every repetition also trains) and replayed on every run, training runs included.
// It must take the runs `report` takes: those whose id the calibration did not train on.
TEST(ExportRos2Control, HeldOutRunsAreTheOnesReportTakes) {
  testing::TempDir dir;
  const std::string data = dir.Path("data"), cal = dir.Path("cal.yaml");
  Fitcal(dir, "simulate --model diff_drive --out " + data + " --repetitions 2 --seed 4", 0);
  Fitcal(dir, "fit --logs " + data + " --train-trajectories '^square' --out " + cal, 0);
  int held_out = 0, all = 0;
  for (const YAML::Node& run : YAML::LoadFile(data + "/dataset.yaml")["runs"]) {
    ++all;
    held_out += run["trajectory"].as<std::string>().rfind("square", 0) != 0;
  }
  ASSERT_GT(held_out, 0);
  ASSERT_LT(held_out, all);
  const std::string params = dir.Path("params.yaml"), with_cov = dir.Path("cal_cov.yaml");
  const std::string out = Fitcal(dir,
                                 "export ros2-control --controller diff_drive_controller "
                                 "--calibration " +
                                     cal + " --logs " + data + " --out " + params +
                                     " --calibration-out " + with_cov,
                                 0);
  EXPECT_NE(out.find("over " + std::to_string(held_out) + " runs of " + data +
                     " held out from the calibration"),
            std::string::npos)
      << out;
  // The covariance where the controller declares it, and in a calibration every reader takes.
  const YAML::Node p = YAML::LoadFile(params)["diff_drive_controller"]["ros__parameters"];
  ASSERT_EQ(p["twist_covariance_diagonal"].size(), 6u);
  ASSERT_EQ(p["pose_covariance_diagonal"].size(), 6u);
  EXPECT_GT(p["twist_covariance_diagonal"][0].as<double>(), 0.0);
  EXPECT_GT(p["pose_covariance_diagonal"][5].as<double>(), 0.0);
  const YAML::Node block = YAML::LoadFile(with_cov)["calibration"]["odometry_covariance"];
  EXPECT_EQ(block["held_out_runs"].as<int>(), held_out);
  EXPECT_EQ(block["twist_variance"].size(), 3u);
  EXPECT_EQ(ReadRobotModelFile(with_cov)->robot().nominal, ReadRobotModelFile(cal)->robot().nominal);
  EXPECT_TRUE(io::ReadCalibrationProvenance(with_cov));
}

// Parameters that replay worse than the nominal robot: one line, exit 5, nothing written, unless
// --allow-worse.
TEST(ExportRos2Control, WorseThanNominalIsRefused) {
  testing::TempDir dir;
  const std::string data = dir.Path("data");
  Fitcal(dir, "simulate --model diff_drive --out " + data + " --repetitions 1 --seed 4", 0);
  const RobotModelPtr nominal = ReadRobotModelFile(data + "/robot.yaml");
  std::vector<double> p = nominal->robot().nominal;
  p[0] *= 1.08;  // one wheel 8 % too large: far worse than the nominal robot
  const std::string cal = dir.Write("bad.yaml", nominal->RobotYaml(p, ""));
  const std::string out = dir.Path("params.yaml");
  const std::string args = "export ros2-control --controller diff_drive_controller --calibration " +
                           cal + " --logs " + data + " --out " + out;
  const testing::FitcalRun refused = testing::RunFitcal(dir, args);
  EXPECT_EQ(refused.exit_code, 5) << refused.out << refused.err;
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_NE(refused.err.find("worse than the nominal robot"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(out));
  Fitcal(dir, args + " --allow-worse", 0);
  EXPECT_TRUE(fs::exists(out));
}

}  // namespace
}  // namespace fitcal
