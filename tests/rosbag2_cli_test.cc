// `fitcal import rosbag2` through the command line, as docs/ros2.md documents it (issue 43).
//
// The import reads its staged data set back through fit's loader before renaming it into place;
// until that read stopped counting as an input of the command (io/input_registry.h,
// BeginStagedOutput), every import was refused at its own output marker, and the library tests
// (ros2_io_test, which calls ImportRosbag2 without the command's input guard) could not see it.
// Here the binary imports bags the project's own writer makes (tests/robot_bag.h: MCAP and
// sqlite3, split in two files or one), the written files are checked against the simulated
// recording, and `fitcal fit` calibrates the data set. The real recorder's bags in
// ../shared/data/rosbag2 hold no wheels: each is refused in one line naming the missing topic
// (skipped when ../shared is absent). A file listed in metadata.yaml is read from the bag
// directory only.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/rosbag2/static_transforms.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "tests/bench/bench_support.h"
#include "tests/robot_bag.h"
#include "tests/test_files.h"

namespace fitcal {
namespace rosbag2_cli_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

namespace fs = std::filesystem;
using testing::Has;
using testing::Lines;
using testing::RunFitcal;
using testing::TempDir;
using namespace testing::robot_bag;

constexpr int kRuns = 12;  // SimulatedRuns: 2 repetitions of 2 squares and 4 circles

std::string Quoted(const std::string& path) { return "'" + path + "'"; }

// The robot's bag and its nominal robot YAML in `tmp`; the simulated runs it holds.
std::vector<sim::ModelSimulatedRun> WriteBag(const TempDir& tmp, const std::string& name,
                                             StorageFormat storage, bool split) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  std::vector<sim::ModelSimulatedRun> runs = SimulatedRuns(*model);
  BagWriterOptions options;
  options.storage = storage;
  BagEdits edits;
  edits.split_in_two = split;
  WriteRobotBag(tmp.path() / name, runs, options, edits);
  tmp.Write("robot.yaml", kDiffDriveExampleYaml);
  return runs;
}

// The documented import (docs/ros2.md) of `bag` into `out`.
std::string ImportArgs(const TempDir& tmp, const std::string& bag, const std::string& out) {
  return "import rosbag2 " + Quoted(bag) + " --out " + Quoted(out) + " --robot " +
         Quoted(tmp.Path("robot.yaml")) +
         " --joints right_wheel_joint,left_wheel_joint --ground-truth /mocap/pose"
         " --split-at-rest 2";
}

// Nothing of a staged directory is left beside `out` (io/staged_directory.h).
void ExpectNoStagingLeft(const fs::path& out) {
  for (const auto& entry : fs::directory_iterator(out.parent_path())) {
    EXPECT_FALSE(Has(entry.path().filename().string(), "." + out.filename().string() + ".tmp-"))
        << entry.path();
  }
}

struct BagCase {
  const char* name;
  StorageFormat storage;
  bool split;
};

class ImportThroughTheCommandLine : public ::testing::TestWithParam<BagCase> {};

TEST_P(ImportThroughTheCommandLine, WritesTheDataSetFitCalibrates) {
  const BagCase& c = GetParam();
  TempDir tmp;
  const std::vector<sim::ModelSimulatedRun> sim_runs = WriteBag(tmp, "bag", c.storage, c.split);
  const fs::path out = tmp.path() / "imported";
  const testing::FitcalRun import = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), out));
  ASSERT_EQ(import.exit_code, 0) << import.err;
  EXPECT_TRUE(Has(import.out, "wrote 12 run(s) to " + out.string())) << import.out;
  ExpectNoStagingLeft(out);

  // The files: the robot as given, one encoder and one ground-truth CSV per run, the marker
  // naming every one of them (what a later --force may replace).
  EXPECT_EQ(testing::ReadFileBytes(out / "robot.yaml"), kDiffDriveExampleYaml);
  const std::string marker = testing::ReadFileBytes(out / ".fitcal-output");
  EXPECT_TRUE(Has(marker, "fitcal output: data set\n")) << marker;
  int csv_files = 0;
  for (const auto& entry : fs::directory_iterator(out / "runs")) {
    ++csv_files;
    EXPECT_TRUE(Has(marker, "runs/" + entry.path().filename().string() + "\n")) << entry.path();
  }
  EXPECT_EQ(csv_files, 2 * kRuns);

  // Read back by fit's loader: every run's ground truth is the simulator's, pose for pose (the
  // rests between runs hold no ground truth, so a cut in the middle of a rest loses none). The
  // CSV carries 17 significant digits and the bag ns stamps: 1e-9 m and rad leave room.
  const io::Dataset dataset = io::LoadDataset(
      io::ReadDatasetIndex(out.string()), ReadRobotModelFile((out / "robot.yaml").string())->robot());
  ASSERT_EQ(dataset.runs.size(), static_cast<std::size_t>(kRuns));
  for (int i = 0; i < kRuns; ++i) {
    const GroundTruthTrack& written = dataset.runs[i].ground_truth;
    const GroundTruthTrack& simulated = sim_runs[i].log.ground_truth;
    ASSERT_EQ(written.world_T_robot.size(), simulated.world_T_robot.size()) << "run " << i;
    for (std::size_t k = 0; k < written.world_T_robot.size(); k += 17) {
      EXPECT_NEAR(written.world_T_robot[k].x, simulated.world_T_robot[k].x, 1e-9);
      EXPECT_NEAR(written.world_T_robot[k].y, simulated.world_T_robot[k].y, 1e-9);
      EXPECT_NEAR(std::remainder(written.world_T_robot[k].theta -
                                     simulated.world_T_robot[k].theta, 2 * M_PI),
                  0.0, 1e-9);
    }
  }

  // `fit` calibrates it: the first repetition of every trajectory trains, the second judges, and
  // the parameters land on the simulated robot's within 5 of their reported sigmas.
  const std::string cal = tmp.Path("cal.yaml");
  const testing::FitcalRun fit =
      RunFitcal(tmp, "fit --logs " + Quoted(out.string()) + " --train-reps 1-6 --out " + cal);
  ASSERT_EQ(fit.exit_code, 0) << fit.err << fit.out;
  const RobotModelPtr calibrated = ReadRobotModelFile(cal);
  const std::optional<io::CalibrationProvenance> provenance = io::ReadCalibrationProvenance(cal);
  ASSERT_TRUE(provenance.has_value());
  ASSERT_EQ(provenance->sigma.size(), kTruth.size());
  for (std::size_t k = 0; k < kTruth.size(); ++k) {  // r_right, r_left, wheel_separation [m]
    EXPECT_NEAR(calibrated->robot().nominal[k], kTruth[k], 5.0 * provenance->sigma[k].second)
        << provenance->sigma[k].first;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Bags, ImportThroughTheCommandLine,
    ::testing::Values(BagCase{"mcap_split", StorageFormat::kMcap, true},
                      BagCase{"mcap", StorageFormat::kMcap, false},
                      BagCase{"sqlite3_split", StorageFormat::kSqlite3, true},
                      BagCase{"sqlite3", StorageFormat::kSqlite3, false}),
    [](const ::testing::TestParamInfo<BagCase>& p) { return std::string(p.param.name); });

// An import over its own previous output is replaced only with --force (the marker is what lets
// it recognise the data set as its own).
TEST(ImportThroughTheCommandLine, ReplacesItsOwnDataSetAndRefusesAForeignDirectory) {
  // The one overwrite rule (io/output_guard.h): running the import again replaces the data set
  // it wrote; a directory holding other files is never replaced, --force or not.
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kMcap, true);
  const std::string out = tmp.Path("imported");
  ASSERT_EQ(RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), out)).exit_code, 0);
  const testing::FitcalRun again = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), out));
  EXPECT_EQ(again.exit_code, 0) << again.err;
  ExpectNoStagingLeft(out);
  tmp.Write("foreign/notes.txt", "not a data set");
  const testing::FitcalRun foreign =
      RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), tmp.Path("foreign")) + " --force");
  EXPECT_EQ(foreign.exit_code, 2) << foreign.err;
  EXPECT_EQ(testing::ReadFileBytes(tmp.Path("foreign/notes.txt")), "not a data set");
}

// One file of a split bag given alone is read alone (a user may want only that part), but said:
// before, its half of the recording became the whole data set without a word.
TEST(ImportThroughTheCommandLine, OneFileOfASplitBagIsReadAloneAndSaidSo) {
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kSqlite3, true);
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(tmp.path() / "bag")) {
    if (entry.path().extension() == ".db3") files.push_back(entry.path().string());
  }
  ASSERT_EQ(files.size(), 2u);
  std::sort(files.begin(), files.end());
  const testing::FitcalRun part = RunFitcal(tmp, ImportArgs(tmp, files[0], tmp.Path("part")));
  EXPECT_EQ(part.exit_code, 0) << part.err;
  EXPECT_TRUE(Has(part.out, files[0] + ": one of the 2 files of the split bag")) << part.out;
  EXPECT_TRUE(Has(part.out, "the other is left out; give the directory")) << part.out;
  const testing::FitcalRun whole =
      RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), tmp.Path("all")));
  EXPECT_EQ(whole.exit_code, 0) << whole.err;
  EXPECT_FALSE(Has(whole.out, "files of the split bag")) << whole.out;
}

// A bag given by its one storage file is the bag: its runs carry the directory's label, so that a
// calibration fitted on one import knows its training runs in the other (they were labelled
// "bag_0" and "bag", and the training runs were judged as held out).
TEST(ImportThroughTheCommandLine, ABagByItsOneFileLabelsItsRunsAsByItsDirectory) {
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kMcap, false);
  std::string file;
  for (const auto& entry : fs::directory_iterator(tmp.path() / "bag")) {
    if (entry.path().extension() == ".mcap") file = entry.path().string();
  }
  ASSERT_FALSE(file.empty());
  ASSERT_EQ(RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), tmp.Path("by_dir"))).exit_code, 0);
  const testing::FitcalRun by_file = RunFitcal(tmp, ImportArgs(tmp, file, tmp.Path("by_file")));
  ASSERT_EQ(by_file.exit_code, 0) << by_file.err;
  EXPECT_FALSE(Has(by_file.out, "files of the split bag")) << by_file.out;
  const auto runs_of = [&](const char* out) {  // the runs, not the header naming the path given
    const std::string yaml = testing::ReadFileBytes(tmp.path() / out / "dataset.yaml");
    return yaml.substr(yaml.find("\nrobot:"));
  };
  EXPECT_TRUE(Has(runs_of("by_dir"), "{id: bag-01, trajectory: bag,")) << runs_of("by_dir");
  EXPECT_EQ(runs_of("by_file"), runs_of("by_dir"));
}

// ---- a ground truth on a mount (issue 39 item 6) ---------------------------------------------

TransformStamped StaticTransform(const char* parent, const char* child, double x, double y,
                                 double z, double yaw_deg) {
  TransformStamped t;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation = {x, y, z};
  const double half = yaw_deg * M_PI / 360.0;
  t.transform.rotation = {0.0, 0.0, std::sin(half), std::cos(half)};
  return t;
}

// The LiDAR 0.4 m ahead of the base, on /tf_static through a mount turned by 90 deg:
// base_link -> lidar_mount (0.3, 0, 0.25; yaw 90 deg) -> lidar (0, -0.1, 0.05 in the mount, yaw
// -90 deg), i.e. (0.3 + 0.1, 0, 0.3) and yaw 0 in the base by hand; an IMU beside it.
std::vector<TransformStamped> LidarTfStatic() {
  return {StaticTransform("base_link", "lidar_mount", 0.3, 0.0, 0.25, 90.0),
          StaticTransform("/lidar_mount", "lidar", 0.0, -0.1, 0.05, -90.0),
          StaticTransform("base_link", "imu", -0.05, 0.02, 0.1, 0.0)};
}

// The diff drive's bag with its ground truth from a LiDAR odometry (nav_msgs/msg/Odometry,
// child_frame_id lidar) 0.4 m ahead of the base; /tf_static as given.
void WriteLidarBag(const TempDir& tmp, std::vector<TransformStamped> tf_static) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  BagWriterOptions options;
  options.storage = StorageFormat::kMcap;
  BagEdits edits;
  edits.base_T_lidar = Pose2d{0.4, 0.0, 0.0};
  edits.tf_static = std::move(tf_static);
  WriteRobotBag(tmp.path() / "bag", SimulatedRuns(*model), options, edits);
  tmp.Write("robot.yaml", kDiffDriveExampleYaml);
}

std::string LidarImportArgs(const TempDir& tmp, const std::string& out) {
  std::string args = ImportArgs(tmp, tmp.Path("bag"), out);
  return args.replace(args.find("/mocap/pose"), 11, "/lidar/odom");
}

// Import -> fit -> export of the LiDAR bag: the import writes the mount /tf_static gives as the
// nominal ground_truth_frame and says so; fit determines it (x within 3 of its sigmas of the
// true 0.4 m, the noise being the simulator's: 1 mm and 0.2 deg on the poses, 0.01 rad/s on the
// wheels) and the wheels as the base ones (5 sigmas, as the base's import above); the exported
// controller parameters are the base's wheels, not the sensor's.
TEST(ImportALidarOnAMount, TheFrameComesFromTfStaticAndRoundTripsThroughFitAndExport) {
  TempDir tmp;
  WriteLidarBag(tmp, LidarTfStatic());
  const std::string out = tmp.Path("imported");
  const testing::FitcalRun import = RunFitcal(tmp, LidarImportArgs(tmp, out));
  ASSERT_EQ(import.exit_code, 0) << import.err;
  EXPECT_TRUE(Has(import.out, "ground truth /lidar/odom tracks frame 'lidar', not 'base_link': "
                              "ground_truth_frame: {x_m: 0.4, y_m: 0, yaw_deg: 0} from /tf_static "
                              "(base_link -> lidar_mount -> lidar) written to the robot YAML"))
      << import.out;
  const YAML::Node frame = YAML::LoadFile(out + "/robot.yaml")["ground_truth_frame"];
  ASSERT_TRUE(frame.IsMap()) << testing::ReadFileBytes(out + "/robot.yaml");
  EXPECT_NEAR(frame["x_m"].as<double>(), 0.4, 1e-12);
  EXPECT_EQ(frame["y_m"].as<double>(), 0.0);
  EXPECT_EQ(frame["yaw_deg"].as<double>(), 0.0);

  const std::string cal = tmp.Path("cal.yaml");
  const testing::FitcalRun fit =
      RunFitcal(tmp, "fit --logs " + Quoted(out) + " --train-reps 1-6 --out " + cal);
  ASSERT_EQ(fit.exit_code, 0) << fit.err << fit.out;
  EXPECT_TRUE(Has(fit.out, "ground_truth_frame: x, y and yaw determined")) << fit.out;
  const YAML::Node written = YAML::LoadFile(cal);
  const double x = written["ground_truth_frame"]["x_m"].as<double>();
  const double sigma_x = written["calibration"]["sigma"]["ground_truth_x_m"].as<double>();
  ASSERT_GT(sigma_x, 0.0);
  EXPECT_LT(std::abs(x - 0.4), 3.0 * sigma_x) << x << " +- " << sigma_x;
  std::printf("fitted ground_truth_x %.5f +- %.5f m (true 0.4)\n", x, sigma_x);
  const RobotModelPtr calibrated = ReadRobotModelFile(cal);
  const std::optional<io::CalibrationProvenance> provenance = io::ReadCalibrationProvenance(cal);
  ASSERT_TRUE(provenance.has_value());
  for (std::size_t k = 0; k < kTruth.size(); ++k) {  // r_right, r_left, wheel_separation [m]
    EXPECT_NEAR(calibrated->robot().nominal[k], kTruth[k], 5.0 * provenance->sigma[k].second)
        << provenance->sigma[k].first;
  }

  const std::string controller = tmp.Path("controller.yaml");
  const testing::FitcalRun exported = RunFitcal(
      tmp, "export ros2-control --calibration " + cal +
               " --controller diff_drive_controller --joints right_wheel_joint,left_wheel_joint"
               " --logs " + Quoted(out) + " --out " + controller);
  ASSERT_EQ(exported.exit_code, 0) << exported.err << exported.out;
  const YAML::Node p = YAML::LoadFile(controller)["diff_drive_controller"]["ros__parameters"];
  const double radius = p["wheel_radius"].as<double>();
  std::printf("exported wheel_separation %.5f wheel_radius %.5f (true %.4f, %.4f / %.4f)\n",
              p["wheel_separation"].as<double>(), radius, kTruth[2], kTruth[0], kTruth[1]);
  EXPECT_NEAR(p["wheel_separation"].as<double>() * p["wheel_separation_multiplier"].as<double>(),
              kTruth[2], 5.0 * provenance->sigma[2].second);
  EXPECT_NEAR(radius * p["right_wheel_radius_multiplier"].as<double>(), kTruth[0],
              5.0 * provenance->sigma[0].second);
  EXPECT_NEAR(radius * p["left_wheel_radius_multiplier"].as<double>(), kTruth[1],
              5.0 * provenance->sigma[1].second);
}

// Without /tf_static the frame is said in words and nothing is written for it: the data set's
// robot YAML is the one given, byte for byte.
TEST(ImportALidarOnAMount, WithoutTfStaticNothingIsWrittenForTheFrame) {
  TempDir tmp;
  WriteLidarBag(tmp, {});
  const std::string out = tmp.Path("imported");
  const testing::FitcalRun import = RunFitcal(tmp, LidarImportArgs(tmp, out));
  ASSERT_EQ(import.exit_code, 0) << import.err;
  EXPECT_TRUE(Has(import.out, "ground truth /lidar/odom tracks frame 'lidar', not 'base_link': the "
                              "bag has no /tf_static, so no ground_truth_frame is written"))
      << import.out;
  EXPECT_EQ(testing::ReadFileBytes(out + "/robot.yaml"), kDiffDriveExampleYaml);
}

// A /tf_static without a link between the two frames: said, nothing written.
TEST(ImportALidarOnAMount, ATfStaticWithoutTheFrameWritesNothingForIt) {
  TempDir tmp;
  WriteLidarBag(tmp, {StaticTransform("base_link", "imu", -0.05, 0.02, 0.1, 0.0)});
  const std::string out = tmp.Path("imported");
  const testing::FitcalRun import = RunFitcal(tmp, LidarImportArgs(tmp, out));
  ASSERT_EQ(import.exit_code, 0) << import.err;
  EXPECT_TRUE(Has(import.out, "/tf_static has no transform between them")) << import.out;
  EXPECT_EQ(testing::ReadFileBytes(out + "/robot.yaml"), kDiffDriveExampleYaml);
}

// A PoseStamped's header.frame_id is the world's: it names no tracked frame, and with /tf_static
// in the bag the import says so; --ground-truth-frames <parent>:<frame> names it, and the frame
// then comes from /tf_static as an Odometry's child frame does.
TEST(ImportALidarOnAMount, APoseStampedsFrameIsNamedByGroundTruthFrames) {
  TempDir tmp;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  BagWriterOptions options;
  options.storage = StorageFormat::kSqlite3;
  BagEdits edits;
  edits.tf_static = LidarTfStatic();
  WriteRobotBag(tmp.path() / "bag", SimulatedRuns(*model), options, edits);
  tmp.Write("robot.yaml", kDiffDriveExampleYaml);
  testing::FitcalRun r = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), tmp.Path("a")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "ground truth /mocap/pose (geometry_msgs/msg/PoseStamped) names no frame "
                         "of its own"))
      << r.out;
  EXPECT_EQ(testing::ReadFileBytes(tmp.Path("a/robot.yaml")), kDiffDriveExampleYaml);
  r = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), tmp.Path("b")) +
                         " --ground-truth-frames world:lidar");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "tracks frame 'lidar', not 'base_link': ground_truth_frame: {x_m: 0.4"))
      << r.out;
  EXPECT_NEAR(YAML::LoadFile(tmp.Path("b/robot.yaml"))["ground_truth_frame"]["x_m"].as<double>(),
              0.4, 1e-12);
}

// The composition through a common ancestor, by hand: base_footprint -> base_link (0, 0, 0.1)
// and base_footprint -> laser (0.5, 0.2, 0.3; yaw 30 deg) put the laser at (0.5, 0.2) and 30 deg
// in base_link; a laser under base_link turned 30 deg, then a camera 0.2 m along its x, sits at
// (0.1 + 0.2 cos 30, 0.2 sin 30) and 30 + 45 deg. Frames in two trees are not linked.
TEST(StaticTransforms, ComposeAlongTheTreeInThreeDimensions) {
  const auto between = [](const std::vector<TransformStamped>& t, const char* a, const char* b) {
    return io::rosbag2::StaticTransformBetween(t, a, b);
  };
  io::rosbag2::StaticMount m =
      between({StaticTransform("base_footprint", "base_link", 0.0, 0.0, 0.1, 0.0),
               StaticTransform("base_footprint", "laser", 0.5, 0.2, 0.3, 30.0)},
              "base_link", "laser");
  ASSERT_TRUE(m.base_T_sensor.has_value());
  EXPECT_NEAR(m.base_T_sensor->x, 0.5, 1e-12);
  EXPECT_NEAR(m.base_T_sensor->y, 0.2, 1e-12);
  EXPECT_NEAR(m.base_T_sensor->theta, 30.0 * M_PI / 180.0, 1e-12);
  EXPECT_EQ(m.chain, "base_link -> base_footprint -> laser");
  m = between({StaticTransform("base_link", "laser", 0.1, 0.0, 0.2, 30.0),
               StaticTransform("laser", "camera", 0.2, 0.0, 0.0, 45.0)},
              "base_link", "camera");
  ASSERT_TRUE(m.base_T_sensor.has_value());
  EXPECT_NEAR(m.base_T_sensor->x, 0.1 + 0.2 * std::cos(M_PI / 6), 1e-12);
  EXPECT_NEAR(m.base_T_sensor->y, 0.2 * std::sin(M_PI / 6), 1e-12);
  EXPECT_NEAR(m.base_T_sensor->theta, 75.0 * M_PI / 180.0, 1e-12);
  EXPECT_FALSE(between({StaticTransform("base_link", "imu", 0, 0, 0, 0),
                        StaticTransform("odom", "laser", 0, 0, 0, 0)},
                       "base_link", "laser")
                   .base_T_sensor.has_value());
  // A ground truth of base_footprint, 0.1 m under base_link: the base in the plane, no frame.
  io::rosbag2::BagStreams streams;
  streams.pose_type = "nav_msgs/msg/Odometry";
  streams.pose_frame = "base_footprint";
  streams.has_tf_static = true;
  streams.static_transforms = {StaticTransform("base_link", "base_footprint", 0, 0, -0.1, 0)};
  const io::rosbag2::GroundTruthMountFromBag mount =
      io::rosbag2::MountFromTfStatic(streams, "/odom", "base_link");
  EXPECT_FALSE(mount.base_T_sensor.has_value());
  EXPECT_TRUE(Has(mount.note, "the ground truth tracks the base, no ground_truth_frame written"))
      << mount.note;
}

// The bags ROS 2's own recorder wrote (../shared/data/rosbag2, README there): no JointState
// topic, so each is refused in one line naming the topic, exit 1, nothing written - read through
// the same path as a robot's bag, both storage formats.
TEST(ImportThroughTheCommandLine, TheRecordersOwnBagsHoldNoWheelsAndAreRefusedInOneLine) {
  const fs::path root = fs::path(FITCAL_SHARED_DIR) / "data" / "rosbag2";
  if (!fs::is_directory(root)) GTEST_SKIP() << root << " is absent (a clone without ../shared)";
  TempDir tmp;
  tmp.Write("robot.yaml", kDiffDriveExampleYaml);
  int bags = 0;
  for (const char* storage : {"sqlite3", "mcap"}) {
    for (const auto& bag : fs::directory_iterator(root / storage)) {
      ++bags;
      const std::string out = tmp.Path(std::string(storage) + "_" + bag.path().filename().string());
      const testing::FitcalRun r = RunFitcal(tmp, ImportArgs(tmp, bag.path().string(), out));
      EXPECT_EQ(r.exit_code, 1) << bag.path() << ": " << r.err;
      EXPECT_EQ(Lines(r.err), 1) << r.err;
      EXPECT_TRUE(Has(r.err, "/joint_states")) << r.err;
      EXPECT_FALSE(Has(r.err, ".fitcal-output")) << r.err;
      EXPECT_FALSE(fs::exists(out)) << out;
      ExpectNoStagingLeft(out);
    }
  }
  EXPECT_EQ(bags, 4);  // cdr_test and talker in each format (README there)
}

// The bag directory holds what metadata.yaml lists: a file missing there is not looked for
// beside the bag (another recording's file of the same name lives there), whatever the
// metadata version.
TEST(BagFilesFromTheBagOnly, AMissingFileIsRefusedNotReadFromTheParentDirectory) {
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kMcap, false);
  fs::rename(tmp.path() / "bag" / "bag_0.mcap", tmp.path() / "bag_0.mcap");
  const std::string out = tmp.Path("imported");
  const testing::FitcalRun r = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), out));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "metadata.yaml")) << r.err;
  EXPECT_TRUE(Has(r.err, "\"bag_0.mcap\", which is not in the bag directory")) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// A file listed twice in metadata.yaml would be read twice (every message repeated): refused
// naming the list, not as a clock that does not advance in the bag's first file. One joint named
// for both wheels is refused before the bag is read (exit 2), as export refuses it.
TEST(BagFilesFromTheBagOnly, AFileListedTwiceOrOneJointForTwoWheelsIsRefused) {
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kSqlite3, true);
  const fs::path metadata = tmp.path() / "bag" / "metadata.yaml";
  std::string text = testing::ReadFileBytes(metadata);
  const std::string second = "- bag_1.db3";
  ASSERT_NE(text.find(second), std::string::npos) << text;
  text.replace(text.find(second), second.size(), "- bag_0.db3");
  testing::WriteFileBytes(metadata, text);
  const std::string out = tmp.Path("imported");
  const testing::FitcalRun twice = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), out));
  EXPECT_EQ(twice.exit_code, 1) << twice.out;
  EXPECT_EQ(Lines(twice.err), 1) << twice.err;
  EXPECT_TRUE(Has(twice.err, "metadata.yaml: lists file \"bag_0.db3\" twice")) << twice.err;
  EXPECT_FALSE(fs::exists(out));

  std::string args = ImportArgs(tmp, tmp.Path("bag"), out);
  const std::string joints = "right_wheel_joint,left_wheel_joint";
  args.replace(args.find(joints), joints.size(), "right_wheel_joint,right_wheel_joint");
  const testing::FitcalRun one_joint = RunFitcal(tmp, args);
  EXPECT_EQ(one_joint.exit_code, 2) << one_joint.out;
  EXPECT_EQ(Lines(one_joint.err), 1) << one_joint.err;
  EXPECT_TRUE(Has(one_joint.err, "--joints names 'right_wheel_joint' twice")) << one_joint.err;
  EXPECT_FALSE(fs::exists(out));
}

// probe45: the wheels' joints given to --joints in the other order (left for right) wrote a data
// set, exit 0, that `fit` then refused as miswired (exit 4) naming the robot YAML. Now the import
// runs the channel-order check every import runs: exit 4, one line naming the bag and the
// --joints order, nothing written; --skip-mapping-check writes it and says so.
TEST(ImportThroughTheCommandLine, JointsInTheOtherOrderAreRefusedAsMiswired) {
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kMcap, false);
  const std::string out = tmp.Path("imported");
  std::string args = ImportArgs(tmp, tmp.Path("bag"), out);
  const std::string joints = "right_wheel_joint,left_wheel_joint";
  args.replace(args.find(joints), joints.size(), "left_wheel_joint,right_wheel_joint");
  const testing::FitcalRun swapped = RunFitcal(tmp, args);
  EXPECT_EQ(swapped.exit_code, 4) << swapped.out << swapped.err;
  EXPECT_EQ(Lines(swapped.err), 1) << swapped.err;
  EXPECT_TRUE(Has(swapped.err, "read as --joints left_wheel_joint,right_wheel_joint")) << swapped.err;
  EXPECT_TRUE(Has(swapped.err, "columns w_right and w_left swapped")) << swapped.err;
  EXPECT_FALSE(fs::exists(out));
  ExpectNoStagingLeft(out);

  const testing::FitcalRun anyway = RunFitcal(tmp, args + " --skip-mapping-check");
  EXPECT_EQ(anyway.exit_code, 0) << anyway.err;
  EXPECT_TRUE(Has(anyway.out, "channel order check: ")) << anyway.out;
  EXPECT_TRUE(Has(anyway.out, "written anyway")) << anyway.out;
  EXPECT_TRUE(fs::exists(fs::path(out) / "dataset.yaml"));
}

// A metadata version rosbag2 has not written (1-9 so far) is a layout fitcal does not know:
// refused at its line, not read as if it were version 5.
TEST(BagFilesFromTheBagOnly, AnUnknownMetadataVersionIsRefusedAtItsLine) {
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kSqlite3, false);
  const fs::path metadata = tmp.path() / "bag" / "metadata.yaml";
  std::string text = testing::ReadFileBytes(metadata);
  const std::size_t at = text.find("version: 5");
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, 10, "version: 99");
  testing::WriteFileBytes(metadata, text);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  const std::string out = tmp.Path("imported");
  const testing::FitcalRun r = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), out));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "metadata.yaml:" + std::to_string(line) + ": version 99")) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// metadata.yaml as a version 1-3 recorder wrote it: every file as "<bag directory>/<file>".
void MakeVersion3(const fs::path& bag, const std::string& recorded_name) {
  const fs::path metadata = bag / "metadata.yaml";
  YAML::Node root = YAML::LoadFile(metadata.string());
  YAML::Node info = root["rosbag2_bagfile_information"];
  info["version"] = 3;
  info.remove("files");  // from version 5 on
  for (std::size_t i = 0; i < info["relative_file_paths"].size(); ++i) {
    info["relative_file_paths"][i] = recorded_name + "/" + info["relative_file_paths"][i].as<std::string>();
  }
  YAML::Emitter out;
  out << root;
  testing::WriteFileBytes(metadata, out.c_str());
}

// A version 3 bag names its directory in every path; copied under another name it is still read
// from its own directory, and a file of that name beside it is not read.
TEST(BagFilesFromTheBagOnly, AVersion3BagIsReadFromItsOwnDirectoryUnderAnyName) {
  TempDir tmp;
  WriteBag(tmp, "bag", StorageFormat::kSqlite3, true);
  MakeVersion3(tmp.path() / "bag", "rosbag2_2019_11_18");
  const testing::FitcalRun r = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), tmp.Path("v3")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "wrote 12 run(s)")) << r.out;

  fs::create_directories(tmp.path() / "rosbag2_2019_11_18");
  fs::rename(tmp.path() / "bag" / "bag_1.db3", tmp.path() / "rosbag2_2019_11_18" / "bag_1.db3");
  const testing::FitcalRun missing = RunFitcal(tmp, ImportArgs(tmp, tmp.Path("bag"), tmp.Path("v3b")));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(Has(missing.err, "\"rosbag2_2019_11_18/bag_1.db3\", which is not in the bag directory"))
      << missing.err;
  EXPECT_FALSE(fs::exists(tmp.path() / "v3b"));
}

}  // namespace
}  // namespace fitcal
