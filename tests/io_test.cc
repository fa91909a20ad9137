// Loaders and writers of io/: the data set format round trip, TUM ground truth, and every bad
// input case of the core issue with its error kind, file and line.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "io/calibration_block.h"
#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/test_files.h"
#include "tests/omni3_robot.h"
#include "tests/three_wheel_files.h"

namespace fitcal::io {
namespace {

using fitcal::testing::TempDir;

const char* kEncoders = "t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,3\n0.02,1,2,3\n";
const char* kGroundTruth = "t,x,y,theta\n0,0,0,0\n0.02,0.1,0.2,0.3\n";

// Expects `fn` to throw an InputError of `kind` naming `file` at `line`.
template <typename Fn>
void ExpectInputError(Fn fn, InputErrorKind kind, const std::string& file, int line) {
  try {
    fn();
    ADD_FAILURE() << "no error; expected kind " << static_cast<int>(kind);
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    EXPECT_EQ(e.file(), file) << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
  }
}

TEST(EncoderCsv, ReadsRatesAndIntervals) {
  TempDir dir;
  const EncoderLog log =
      ReadEncoderCsv(dir.Write("e.csv", "t,w_a,w_b,w_c\n1.0,9,9,9\n1.01,1,-2,3.5\n1.03,4,5,6\n"));
  ASSERT_EQ(log.t_s.size(), 3u);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_NEAR(log.samples[0].dt_s, 0.01, 1e-15);  // row 0 only sets the start time
  EXPECT_EQ(log.samples[0].value[1], -2.0);
  EXPECT_NEAR(log.samples[1].dt_s, 0.02, 1e-15);
  EXPECT_EQ(log.samples[1].value[2], 6.0);
}

// Cumulative counts that run on between runs: row 0's count is each wheel's absolute angle (mod
// one revolution), kept per run; increments and rate columns carry none.
TEST(EncoderCsv, CumulativeTicksCarryTheAbsoluteStartAngle) {
  TempDir dir;
  const std::string text = "t,ticks_a,ticks_b,ticks_c\n0,1000,-100,4096\n0.01,1010,-90,4100\n";
  const EncoderLog log = ReadEncoderCsv(dir.Write("c.csv", text), EncoderTicks{4096.0, true});
  ASSERT_EQ(log.start_angle_rad.size(), 3u);
  const double rad_per_tick = 2.0 * M_PI / 4096.0;
  EXPECT_NEAR(log.start_angle_rad[0], 1000 * rad_per_tick, 1e-12);
  EXPECT_NEAR(log.start_angle_rad[1], 2.0 * M_PI - 100 * rad_per_tick, 1e-12);  // in [0, 2 pi)
  EXPECT_NEAR(log.start_angle_rad[2], 0.0, 1e-12);                              // one full turn
  EXPECT_NEAR(log.samples[0].value[0], 10 * rad_per_tick / 0.01, 1e-9);
  const EncoderLog increments =
      ReadEncoderCsv(dir.Write("i.csv", text), EncoderTicks{4096.0, false});
  EXPECT_TRUE(increments.start_angle_rad.empty());
  EXPECT_TRUE(ReadEncoderCsv(dir.Write("r.csv", kEncoders)).start_angle_rad.empty());
}

TEST(EncoderCsv, BadInputs) {
  TempDir dir;
  const auto check = [&](const std::string& text, InputErrorKind kind, int line) {
    const std::string path = dir.Write("bad.csv", text);
    ExpectInputError([&] { ReadEncoderCsv(path); }, kind, path, line);
  };
  ExpectInputError([&] { ReadEncoderCsv(dir.Path("missing.csv")); }, InputErrorKind::kMissingFile,
                   dir.Path("missing.csv"), 0);
  check("", InputErrorKind::kEmptyFile, 1);
  check("t,w_a,w_b\n0,1,2\n", InputErrorKind::kBadHeader, 1);
  check("time,w_a,w_b,w_c\n0,1,2,3\n", InputErrorKind::kBadHeader, 1);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,x,3\n", InputErrorKind::kNonNumeric, 3);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,nan,3\n", InputErrorKind::kNonFinite, 3);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,inf\n", InputErrorKind::kNonFinite, 3);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,1e999\n", InputErrorKind::kNonFinite, 3);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2\n", InputErrorKind::kWrongColumnCount, 3);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,3,4\n", InputErrorKind::kWrongColumnCount, 3);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,3\n0.01,1,2,3\n", InputErrorKind::kNonIncreasingTime, 4);
  check("t,w_a,w_b,w_c\n0,0,0,0\n0.02,1,2,3\n0.01,1,2,3\n", InputErrorKind::kNonIncreasingTime, 4);
  check("t,w_a,w_b,w_c\n0,0,0,0\n", InputErrorKind::kTooFewSamples, 0);
}

TEST(GroundTruth, ReadsCsvAndTum) {
  TempDir dir;
  const GroundTruthTrack csv = ReadGroundTruth(dir.Write("gt.csv", kGroundTruth));
  ASSERT_EQ(csv.t_s.size(), 2u);
  EXPECT_EQ(csv.world_T_robot[1].theta, 0.3);
  // TUM: yaw from the quaternion of a rotation of 2 rad about z.
  const double yaw = 2.0;
  const std::string tum = "# t x y z qx qy qz qw\n0 1 2 0 0 0 " +
                          std::to_string(std::sin(yaw / 2)) + " " +
                          std::to_string(std::cos(yaw / 2)) + "\n0.2 1.5 2 0.1 0 0 0 1\n";
  const GroundTruthTrack t = ReadGroundTruth(dir.Write("gt.tum", tum));
  ASSERT_EQ(t.t_s.size(), 2u);
  EXPECT_NEAR(t.world_T_robot[0].theta, yaw, 1e-6);  // printed with 6 decimals
  EXPECT_EQ(t.world_T_robot[0].x, 1.0);
  EXPECT_EQ(t.world_T_robot[1].theta, 0.0);
}

TEST(GroundTruth, BadInputs) {
  TempDir dir;
  const auto check = [&](const std::string& text, InputErrorKind kind, int line) {
    const std::string path = dir.Write("bad_gt.csv", text);
    ExpectInputError([&] { ReadGroundTruth(path); }, kind, path, line);
  };
  check("t,x,y\n0,0,0\n", InputErrorKind::kBadHeader, 1);
  check("t,x,y,theta\n0,0,0,0\n1,0,abc,0\n", InputErrorKind::kNonNumeric, 3);
  check("t,x,y,theta\n0,0,0,0\n1,0,0,NaN\n", InputErrorKind::kNonFinite, 3);
  check("t,x,y,theta\n0,0,0,0\n0,0,0,0\n", InputErrorKind::kNonIncreasingTime, 3);
  check("t,x,y,theta\n0,0,0,0\n", InputErrorKind::kTooFewSamples, 0);
  check("0 1 2 0 0 0 0 1\n1 1 2 0 0 0\n", InputErrorKind::kWrongColumnCount, 2);
  check("t,x,y,theta\n0,0,0,0\n1,0,0,1e300\n", InputErrorKind::kImplausibleValue, 3);
}

// A track of a robot at 0.5 m/s sampled at 10 Hz, n samples, one pose moved by `jump` (m, rad).
std::string TrackText(int n, int moved, double jump_m, double jump_rad) {
  std::string text = "t,x,y,theta\n";
  for (int k = 0; k < n; ++k) {
    const double x = 0.05 * k + (k == moved ? jump_m : 0.0);
    const double theta = 0.01 * k + (k == moved ? jump_rad : 0.0);
    text += std::to_string(0.1 * k) + "," + std::to_string(x) + ",0," + std::to_string(theta) +
            "\n";
  }
  return text;
}

// One pose of a motion capture 2 m off (a marker swapped for a sample) is dropped with a warning
// naming its line, and so is a heading flipped by pi; the track is otherwise the file's. More
// than 1 % of them is two bodies on one track: refused. A sparse track whose samples lie far apart
// in time is no glitch (a pose every half loop).
TEST(GroundTruth, AGlitchIsDroppedAndNamedAndManyAreRefused) {
  TempDir dir;
  for (const auto& [jump_m, jump_rad] : {std::pair{2.0, 0.0}, std::pair{0.0, M_PI}}) {
    const GroundTruthTrack t =
        ReadGroundTruth(dir.Write("one.csv", TrackText(200, 50, jump_m, jump_rad)));
    ASSERT_EQ(t.t_s.size(), 199u);
    EXPECT_EQ(t.t_s[50], 5.1);  // the sample of line 52 is gone
    const GroundTruthTrack clean =
        ReadGroundTruth(dir.Write("clean.csv", TrackText(200, -1, 0, 0)));
    EXPECT_EQ(clean.t_s.size(), 200u);
  }
  std::string two_bodies = "t,x,y,theta\n";
  for (int k = 0; k < 200; ++k) {
    two_bodies += std::to_string(0.01 * k) + "," + std::to_string(0.005 * k + (k % 2) * 3.0) +
                  ",0,0\n";
  }
  const std::string path = dir.Write("two.csv", two_bodies);
  ExpectInputError([&] { ReadGroundTruth(path); }, InputErrorKind::kImplausibleValue, path, 3);
  const GroundTruthTrack sparse =
      ReadGroundTruth(dir.Write("sparse.csv", "t,x,y,theta\n0,0,0,0\n10,2,0,3\n20,0.01,0,6.2\n"));
  EXPECT_EQ(sparse.t_s.size(), 3u);
}

// The calibrated YAML an omni3 model writes (its schema + the generic calibration block) reads back
// as the same robot.
TEST(RobotYaml, RoundTripsThroughTheCalibratedSchema) {
  TempDir dir;
  const Omni3Robot robot = ReadOmni3Robot(dir.Write("robot.yaml", kOmni3ExampleYaml));
  EXPECT_EQ(robot.name, "example_omni3");
  EXPECT_NEAR(robot.nominal.angle_rad[1], M_PI, 1e-15);
  const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(robot);
  // The named view and the model's are one robot both ways.
  const Omni3Robot same = Omni3RobotOf(*model);
  EXPECT_EQ(same.wheel_names, robot.wheel_names);
  EXPECT_EQ(same.nominal.ToArray(), robot.nominal.ToArray());
  EXPECT_EQ(same.ParameterBounds()[7].hi, robot.ParameterBounds()[7].hi);
  EXPECT_EQ(same.bounds.angle_offset_rad.lo, robot.bounds.angle_offset_rad.lo);
  CalibrationBlock record;
  record.method = "ceres";
  record.has_uncertainty = true;
  record.sigma.assign(omni3::kNumParameters, 1e-4);
  record.correlation = Eigen::MatrixXd::Identity(omni3::kNumParameters, omni3::kNumParameters);
  const Omni3Robot back = ReadOmni3Robot(dir.Write(
      "calibrated.yaml",
      model->RobotYaml(model->robot().nominal, CalibrationBlockYaml(record, model->robot()))));
  EXPECT_EQ(back.name, robot.name);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(back.nominal.distance_m[i], robot.nominal.distance_m[i], 1e-10);
    EXPECT_NEAR(back.nominal.angle_rad[i], robot.nominal.angle_rad[i], 1e-9);
  }
  EXPECT_NEAR(back.bounds.angle_offset_rad.lo, robot.bounds.angle_offset_rad.lo, 1e-12);
}

// What `fit` records about its training runs reads back for the report
// (io/calibration_yaml.h); a plain robot YAML records nothing; a malformed list names its line.
TEST(RobotYaml, CalibrationProvenanceRoundTrips) {
  TempDir dir;
  const RobotModelPtr model = ReadRobotModelFile(dir.Write("robot.yaml", kOmni3ExampleYaml));
  EXPECT_FALSE(ReadCalibrationProvenance(dir.Path("robot.yaml")).has_value());
  CalibrationBlock record;
  record.method = "ceres";
  record.termination = "NO_CONVERGENCE";
  record.training_repetitions = {1, 2};
  record.training_run_ids = {"R1-rep01", "G1-rep02"};
  record.training_trajectories = "^[RG]";
  record.training_fingerprint = "0123456789012345";  // digits only: must stay a string
  record.at_bound = {"R_a"};
  record.cf_training_after = 0.0125;
  record.has_uncertainty = true;
  record.sigma.assign(omni3::kNumParameters, 1e-4);
  record.correlation = Eigen::MatrixXd::Identity(omni3::kNumParameters, omni3::kNumParameters);
  const std::string path = dir.Write(
      "calibrated.yaml",
      model->RobotYaml(model->robot().nominal, CalibrationBlockYaml(record, model->robot())));
  const std::optional<CalibrationProvenance> p = ReadCalibrationProvenance(path);
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->termination, "NO_CONVERGENCE");
  EXPECT_EQ(p->training_repetitions, (std::vector<int>{1, 2}));
  EXPECT_EQ(p->training_run_ids, record.training_run_ids);
  EXPECT_EQ(p->training_trajectories, "^[RG]");
  EXPECT_EQ(p->training_fingerprint, "0123456789012345");
  EXPECT_EQ(p->at_bound, record.at_bound);
  ASSERT_TRUE(p->has_training_cf);
  EXPECT_DOUBLE_EQ(p->cf_training_after, 0.0125);
  ASSERT_EQ(p->sigma.size(), 9u);  // one per parameter, named with its unit
  EXPECT_EQ(p->sigma[3].first, "r_a_m");
  EXPECT_DOUBLE_EQ(p->sigma[3].second, 1e-4);
  EXPECT_EQ(p->correlation.size(), 9u);
  // The omni3 layout before the model seam (one list of three per quantity) still reads.
  const std::string legacy = dir.Write(
      "legacy.yaml", std::string(kOmni3ExampleYaml) +
                         "calibration:\n  training_repetitions: [1]\n"
                         "  sigma: {distance_m: [1e-4, 1e-4, 1e-4], radius_m: [2e-4, 2e-4, 2e-4],"
                         " angle_deg: [0.1, 0.1, 0.1]}\n");
  const std::optional<CalibrationProvenance> old = ReadCalibrationProvenance(legacy);
  ASSERT_TRUE(old.has_value());
  ASSERT_EQ(old->sigma.size(), 9u);
  EXPECT_EQ(old->sigma[3].first, "radius_m[0]");
  EXPECT_DOUBLE_EQ(old->sigma[3].second, 2e-4);
  const std::string uneven =
      dir.Write("uneven.yaml", std::string(kOmni3ExampleYaml) +
                                   "calibration:\n  training_repetitions: [1]\n"
                                   "  sigma: {r_m: 0.001, b_m: 0.002}\n"
                                   "  correlation:\n    - [1, 0.5]\n    - [0.5]\n");
  const int robot_lines = fitcal::testing::Lines(kOmni3ExampleYaml);
  ExpectInputError([&] { ReadCalibrationProvenance(uneven); }, InputErrorKind::kBadValue, uneven,
                   robot_lines + 6);
  const std::string bad = dir.Write("bad.yaml", std::string(kOmni3ExampleYaml) +
                                                    "calibration:\n  training_repetitions: [1]\n"
                                                    "  training_run_ids: 5\n");
  ExpectInputError([&] { ReadCalibrationProvenance(bad); }, InputErrorKind::kWrongYamlType, bad,
                   robot_lines + 3);
}

TEST(RobotYaml, BadInputs) {
  TempDir dir;
  const auto check = [&](const std::string& text, InputErrorKind kind, int line) {
    const std::string path = dir.Write("bad_robot.yaml", text);
    ExpectInputError([&] { ReadOmni3Robot(path); }, kind, path, line);
  };
  std::string robot = kOmni3ExampleYaml;
  const auto replace = [&](const std::string& from, const std::string& to) {
    std::string s = robot;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  check(replace("model: omni3", "model: tricycle"), InputErrorKind::kUnknownModel, 1);
  check(replace("name: example_omni3", "name: [a, b]"), InputErrorKind::kWrongYamlType, 2);
  check(replace("wheels:\n", "wheels: 3\nx:\n"), InputErrorKind::kWrongYamlType, 3);
  check(replace("radius_m: 0.148, angle_deg: 180.0", "radius_m: abc, angle_deg: 180.0"),
        InputErrorKind::kNonNumeric, 5);
  check(replace("distance_m: [0.170, 0.220]", "distance_m: [0.220, 0.170]"),
        InputErrorKind::kBadValue, 8);
  // The nominal is the fit's start and must lie inside the bounds (angle bounds are relative).
  check(replace("radius_m: 0.148, angle_deg: 300.0", "radius_m: 0.160, angle_deg: 300.0"),
        InputErrorKind::kBadValue, 6);
  check(replace("name: example_omni3", "name: example_omni3\ncolour: red"),
        InputErrorKind::kUnknownKey, 3);
  check(replace("name: example_omni3\n", ""), InputErrorKind::kMissingKey, 1);
  check("model: omni3\nwheels: [\n", InputErrorKind::kYamlSyntax, 3);
}

// A one-run data set in `dir`, with `dataset_yaml` as its index.
void WriteDataset(const TempDir& dir, const std::string& dataset_yaml) {
  dir.Write("robot.yaml", kOmni3ExampleYaml);
  dir.Write("runs/e.csv", kEncoders);
  dir.Write("runs/g.csv", kGroundTruth);
  dir.Write("dataset.yaml", dataset_yaml);
}

const char* kDatasetYaml = R"(robot: robot.yaml
runs:
  - {id: r1, trajectory: R1, repetition: 1, encoders: runs/e.csv, ground_truth: runs/g.csv}
)";

TEST(Dataset, LoadsRunsAndStartPose) {
  TempDir dir;
  // A second run of its own (one file listed for two runs is refused as a duplicated run).
  dir.Write("runs/e2.csv", "t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,3\n0.02,1,2,4\n");
  dir.Write("runs/g2.csv", "t,x,y,theta\n0,0,0,0\n0.02,0.1,0.2,0.4\n");
  WriteDataset(dir, std::string(kDatasetYaml) +
                        "  - {id: r2, trajectory: R1, repetition: 2, encoders: runs/e2.csv, "
                        "ground_truth: runs/g2.csv, start_pose: [1, 2, 0.5]}\n");
  const Dataset d = LoadDataset(dir.path().string());
  ASSERT_EQ(d.runs.size(), 2u);
  EXPECT_EQ(d.runs[1].repetition, 2);
  ASSERT_TRUE(d.runs[1].start_pose.has_value());
  EXPECT_EQ(d.runs[1].start_pose->theta, 0.5);
  EXPECT_FALSE(d.runs[0].start_pose.has_value());
  EXPECT_EQ(d.runs[0].encoders.samples.size(), 2u);
}

TEST(Dataset, BadInputs) {
  const auto check = [](const std::string& yaml, InputErrorKind kind, int line,
                        const std::string& bad_file = "dataset.yaml") {
    TempDir dir;
    WriteDataset(dir, yaml);
    if (bad_file == "runs/g_late.csv") dir.Write(bad_file, "t,x,y,theta\n5,0,0,0\n6,0,0,0\n");
    ExpectInputError([&] { LoadDataset(dir.path().string()); }, kind, dir.Path(bad_file), line);
  };
  const std::string run =
      "  - {id: r1, trajectory: R1, repetition: 1, encoders: runs/e.csv, ground_truth: "
      "runs/g.csv}\n";
  check("robot: robot.yaml\nruns:\n" + run + run, InputErrorKind::kDuplicateRunId, 4);
  check("robot: robot.yaml\nruns: {a: 1}\n", InputErrorKind::kWrongYamlType, 2);
  check("- a\n- b\n", InputErrorKind::kWrongYamlType, 1);
  check(
      "robot: robot.yaml\nruns:\n  - {id: r1, trajectory: R1, repetition: 1.5, encoders: "
      "runs/e.csv, ground_truth: runs/g.csv}\n",
      InputErrorKind::kBadValue, 3);
  check(
      "robot: robot.yaml\nruns:\n  - {id: r1, trajectory: R1, repetition: 1, encoders: "
      "runs/e.csv}\n",
      InputErrorKind::kMissingKey, 3);
  check(
      "robot: robot.yaml\nruns:\n  - {id: r1, trajectory: R1, repetition: 1, encoders: ../e.csv, "
      "ground_truth: runs/g.csv}\n",
      InputErrorKind::kBadPath, 3);
  check("robot: /etc/robot.yaml\nruns:\n" + run, InputErrorKind::kBadPath, 1);
  check("robot: nothere.yaml\nruns:\n" + run, InputErrorKind::kMissingFile, 1);
  check(
      "robot: robot.yaml\nruns:\n  - {id: r1, trajectory: R1, repetition: 1, encoders: runs/e.csv, "
      "ground_truth: runs/g_late.csv}\n",
      InputErrorKind::kNoOverlap, 0, "runs/g_late.csv");
  check(
      "robot: robot.yaml\nruns:\n  - {id: r1, trajectory: R1, repetition: 1, encoders: runs/e.csv, "
      "ground_truth: runs/g.csv, start_pose: [1, 2]}\n",
      InputErrorKind::kBadValue, 3);
  check(
      "robot: robot.yaml\nruns:\n  - {id: r1, trajectory: R1, repetition: 1, encoders: runs/e.csv, "
      "ground_truth: runs/g.csv, start_pose: [1e308, 0, 0]}\n",
      InputErrorKind::kImplausibleValue, 3);
  {
    TempDir dir;
    WriteDataset(dir, std::string(kDatasetYaml)
                          .replace(std::string(kDatasetYaml).find("runs/e.csv"), 10, "runs/x.csv"));
    ExpectInputError([&] { LoadDataset(dir.path().string()); }, InputErrorKind::kMissingFile,
                     dir.Path("runs/x.csv"), 0);
  }
}

}  // namespace
}  // namespace fitcal::io
