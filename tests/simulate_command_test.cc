// `fitcal simulate --model <name>` end to end, through the command line: the data set of every
// model with calibration trajectories is written atomically, and `fitcal fit` on it recovers the
// true robot it names (true_robot.yaml) within the sigmas the fit derives from the data's noise.
// Without --model the flower (omni3, stepped physics) regenerates the shipped data/flower byte for
// byte.
// The models' own recovery tests (diff_drive_test, tricycle_test, omni_model_test) call the
// library; these go through the files and the commands a user runs.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "models/model_registry.h"
#include "models/omni/omni_model.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using fitcal::testing::ReadFileBytes;
using fitcal::testing::TempDir;

using Result = fitcal::testing::FitcalRun;
using fitcal::testing::RunFitcal;

struct RecoveryCase {
  const char* model;
  int seed;
  int repetitions;    // the last one validates
  const char* noise;  // simulate flags beyond the defaults
};

class SimulatedModel : public ::testing::TestWithParam<RecoveryCase> {};

// simulate --model M (the default noise of README "Simulator": 4096-tick encoders every 10 ms with
// 0.02 rad/s rate noise, ground truth every 0.2 s with 2 mm and 0.2 deg, an unrecorded random
// start pose), then fit with the defaults a user gets (Ceres, Eq. 14's 1 m = 1 rad weighting).
// The fit's sigmas are its covariance scaled by the residual variance, i.e. derived from the noise
// the data actually carry (start-pose noise included). Each free parameter must land within 4 of
// them (a false alarm 6e-5 per parameter for Gaussian errors); held parameters stay nominal
// exactly; and the truth is > 5 sigma from the nominal, so a fit that did not move would fail.
TEST_P(SimulatedModel, FitCommandRecoversTheTrueRobotWithinItsSigmas) {
  const RecoveryCase c = GetParam();
  TempDir dir;
  const std::string data = dir.Path("data"), cal = dir.Path("calibrated.yaml");
  Result r = RunFitcal(dir, std::string("simulate --model ") + c.model + " --out " + data +
                                " --seed " + std::to_string(c.seed) + " --repetitions " +
                                std::to_string(c.repetitions) + " " + c.noise);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunFitcal(dir, "fit --logs " + data + " --train-reps 1-" + std::to_string(c.repetitions - 1) +
                         " --out " + cal);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  std::printf("%s", r.out.c_str());

  const Robot truth = ReadRobotModelFile(data + "/true_robot.yaml")->robot();
  const Robot nominal = ReadRobotModelFile(data + "/robot.yaml")->robot();
  const Robot fitted = ReadRobotModelFile(cal)->robot();
  const YAML::Node block = YAML::LoadFile(cal)["calibration"];
  ASSERT_EQ(block["selected"].as<std::string>(), "ceres");
  const YAML::Node sigma = block["sigma"];
  ASSERT_TRUE(sigma.IsMap()) << "no uncertainty in " << cal;
  for (int k = 0; k < nominal.NumParameters(); ++k) {
    const ParameterInfo& info = nominal.parameters[k];
    SCOPED_TRACE(info.name);
    if (nominal.IsHeld(k)) {
      EXPECT_EQ(fitted.nominal[k], nominal.nominal[k]);
      continue;
    }
    const double s = sigma[info.KeyName()].as<double>() / info.DisplayScale();
    ASSERT_GT(s, 0.0);
    EXPECT_LT(std::abs(fitted.nominal[k] - truth.nominal[k]), 4.0 * s);
    EXPECT_GT(std::abs(nominal.nominal[k] - truth.nominal[k]), 5.0 * s);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryModel, SimulatedModel,
                         // The differential drive's default truth is UMBmark-sized (E_d 1.005,
                         // 0.25 % on the separation): a quarter of the default noise keeps it
                         // > 5 sigma from the nominal with four repetitions.
                         ::testing::Values(RecoveryCase{"diff_drive", 3, 4,
                                                        "--gt-position-sigma-m 0.0005 "
                                                        "--gt-heading-sigma-deg 0.05 "
                                                        "--wheel-rate-sigma-rad-s 0.005"},
                                           RecoveryCase{"tricycle", 3, 3, ""},
                                           RecoveryCase{"omni", 3, 3, ""}),
                         [](const auto& test) { return std::string(test.param.model); });

// The directory appears whole: a data set fitcal wrote is replaced entirely by the next run; a
// file fitcal did not write there is never deleted, --force or not (the whole directory is
// refused: io/output_guard.h); no temporary sibling is left behind.
TEST(SimulateCommand, WritesTheDataSetDirectoryAtomically) {
  TempDir dir;
  const std::string data = dir.Path("data");
  ASSERT_EQ(RunFitcal(dir, "simulate --model diff_drive --repetitions 1 --out " + data).exit_code,
            0);
  const std::string dataset = ReadFileBytes(data + "/dataset.yaml");
  fitcal::testing::WriteFileBytes(data + "/stale.txt", "left from before");
  const Result refused = RunFitcal(dir, "simulate --model tricycle --repetitions 1 --out " + data);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("--force"), std::string::npos) << refused.err;
  EXPECT_TRUE(fs::exists(data + "/stale.txt"));
  EXPECT_EQ(ReadFileBytes(data + "/dataset.yaml"), dataset);
  const Result forced =
      RunFitcal(dir, "simulate --model tricycle --repetitions 1 --force --out " + data);
  EXPECT_EQ(forced.exit_code, 2);
  EXPECT_NE(forced.err.find("stale.txt"), std::string::npos) << forced.err;
  EXPECT_EQ(ReadFileBytes(data + "/stale.txt"), "left from before");
  fs::remove(data + "/stale.txt");
  ASSERT_EQ(
      RunFitcal(dir, "simulate --model tricycle --repetitions 1 --force --out " + data).exit_code,
      0);
  EXPECT_NE(ReadFileBytes(data + "/robot.yaml").find("model: tricycle"), std::string::npos);
  for (const auto& entry : fs::directory_iterator(dir.Path(""))) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }
}

// Usage errors (exit 2, one line, nothing written): slip and injected effects outside the
// stepped physics (perfect tracking has neither), effects the robot's channels cannot show, a
// robot of another model than --model.
TEST(SimulateCommand, RefusesWhatTheModelSimulatorDoesNotTake) {
  TempDir dir;
  const std::string data = dir.Path("data");
  for (const std::string& args :
       {std::string("--model diff_drive --slip-sigma 0.01"),
        std::string("--model tricycle --inject yaw_rate_slip=0.1"),
        std::string("--model omni --robot ") + FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml",
        // Effects the three-wheeled flower robot has no channel for.
        std::string("--model omni3 --inject pivot_yaw_gain=0.01"),
        std::string("--robot ") + FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml --inject " +
            "steering_scale=0.01",
        // ASOC's castors run on perfect tracking with their own dynamics: no stepped slip.
        std::string("--model asoc --slip-sigma 0.01"),
        // A negative sigma (exit 1 before), and noise whose samples the loader refuses: a
        // ground truth 1e300 m away was written, and `fit` then refused the data set.
        std::string("--model tricycle --gt-position-sigma-m -1"),
        std::string("--model tricycle --repetitions 1 --gt-position-sigma-m 1e300"),
        std::string("--model diff_drive --repetitions 1 --wheel-rate-sigma-rad-s 1e300")}) {
    SCOPED_TRACE(args);
    const Result r = RunFitcal(dir, "simulate " + args + " --out " + data);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(data));
    if (args.find("1e300") != std::string::npos) {
      EXPECT_NE(r.err.find("a data set fit would refuse: " + data + "/runs/"), std::string::npos)
          << r.err;  // the file named as it would have been written, not the staging directory
    }
  }
}

// A truth file is its parameters: one whose fixed geometry differs (a mecanum wheel's rollers at
// -30 deg where the nominal has -45) was simulated with the nominal's and written as
// true_robot.yaml stating another robot. Refused in one line, nothing written; and a repetition
// count no memory holds (2e9 grew by 140 MB/s) is a usage error.
TEST(SimulateCommand, RefusesATruthOfAnotherGeometryAndRepetitionsBeyondMemory) {
  TempDir dir;
  const std::string data = dir.Path("data");
  std::string truth = kOmniExampleYaml;
  truth.replace(truth.find("roller_angle_deg: -45"), 21, "roller_angle_deg: -30");
  const std::string nominal_path = dir.Write("nominal.yaml", kOmniExampleYaml);
  const std::string truth_path = dir.Write("truth.yaml", truth);
  const Result other = RunFitcal(dir, "simulate --model omni --robot " + nominal_path +
                                          " --truth " + truth_path + " --out " + data);
  EXPECT_NE(other.exit_code, 0);
  EXPECT_EQ(std::count(other.err.begin(), other.err.end(), '\n'), 1) << other.err;
  EXPECT_NE(other.err.find("differs from the nominal robot in more than its parameters"),
            std::string::npos) << other.err;
  EXPECT_FALSE(fs::exists(data));
  const Result same = RunFitcal(dir, "simulate --model omni --robot " + nominal_path +
                                         " --truth " + nominal_path + " --out " + data);
  EXPECT_EQ(same.exit_code, 0) << same.err;
  const Result many = RunFitcal(dir, "simulate --model diff_drive --repetitions 2000000000 --out " +
                                         dir.Path("many"));
  EXPECT_EQ(many.exit_code, 2) << many.err;
  EXPECT_NE(many.err.find("at most 1000"), std::string::npos) << many.err;
  EXPECT_FALSE(fs::exists(dir.Path("many")));
}

// ASOC simulates on the one engine (its castor dynamics registered by the model, asoc41; before,
// `simulate --model asoc` exited 1: no scenario): the six holds, ten UMBmark circuits and
// --repetitions excursions, the true robot drawn from --seed, read back by the one loader.
TEST(SimulateCommand, AsocRunsOnTheOneEngine) {
  TempDir dir;
  const std::string data = dir.Path("data");
  const Result r = RunFitcal(dir, "simulate --model asoc --repetitions 1 --seed 4 --out " + data);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(1 excursion, seed 4)"), std::string::npos) << r.out;  // not "excursions"
  const std::string index = ReadFileBytes(data + "/dataset.yaml");
  for (const char* id : {"hold_3_ccw-rep01", "umbmark_cw-rep10", "excursion-rep01"}) {
    EXPECT_NE(index.find(id), std::string::npos) << id << "\n" << index;
  }
  EXPECT_NE(ReadFileBytes(data + "/true_robot.yaml"), ReadFileBytes(data + "/robot.yaml"));
  const Result fit = RunFitcal(dir, "fit --logs " + data + " --no-output");
  EXPECT_EQ(fit.exit_code, 0) << fit.err;
}

// The rows of a CSV after its header, as numbers.
std::vector<std::vector<double>> CsvRows(const std::string& path) {
  std::vector<std::vector<double>> rows;
  std::istringstream text(ReadFileBytes(path));
  std::string line;
  std::getline(text, line);
  while (std::getline(text, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

// `simulate --model asoc` records as Doebbler's prototype, the recorder the asoc model registers
// (models/asoc/asoc_extras.h; asoc-simulate's until it was retired): 5 excursions by default
// beside the 6 holds and 10 UMBmark circuits, encoders every 0.05 s with every wheel rate a whole
// number of 0.3 deg counts per 0.05 s, noise-free ground truth at every encoder time, each run
// from the origin; --wheel-slip-sigma reaches its wheels and --encoder-counts-per-rev replaces
// its count. Before, the generic recorder: 10 ms, 4096 counts, ground truth every 0.2 s, 10
// excursions.
TEST(SimulateCommand, AsocRecordsAsThePrototype) {
  TempDir dir;
  const auto wheel_counts = [&](const std::string& data, double counts_per_rev) {
    const double count_rate = 2.0 * M_PI / counts_per_rev / 0.05;
    double worst = 0.0;
    for (const auto& row : CsvRows(data + "/runs/umbmark_cw-rep06_encoders.csv")) {
      for (int column : {1, 2, 4, 5, 7, 8}) {
        worst = std::max(worst, std::abs(row[column] / count_rate -
                                         std::round(row[column] / count_rate)));
      }
    }
    return worst;
  };
  const std::string data = dir.Path("asoc");
  const Result r = RunFitcal(dir, "simulate --model asoc --out " + data);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The count in the scenario's unit (SimulationScenario::repetition_unit): ASOC's repetitions are
  // its excursions; the holds and the squares are driven whatever the count.
  EXPECT_TRUE(r.out.find("wrote 21 runs of the asoc robot 'example_asoc' (5 excursions, seed 1) to " +
                         data + "\n") == 0)
      << r.out;
  const std::string index = ReadFileBytes(data + "/dataset.yaml");
  EXPECT_NE(index.find("excursion-rep05"), std::string::npos) << index;
  EXPECT_EQ(index.find("excursion-rep06"), std::string::npos) << index;
  const auto encoders = CsvRows(data + "/runs/umbmark_cw-rep06_encoders.csv");
  const auto truth = CsvRows(data + "/runs/umbmark_cw-rep06_ground_truth.csv");
  ASSERT_GT(encoders.size(), 100u);
  ASSERT_EQ(truth.size(), encoders.size());
  for (std::size_t k = 0; k < encoders.size(); ++k) {
    EXPECT_NEAR(encoders[k][0], 0.05 * static_cast<double>(k), 1e-9) << k;
    EXPECT_NEAR(truth[k][0], encoders[k][0], 1e-6) << k;
  }
  EXPECT_EQ(truth[0][1], 0.0);
  EXPECT_EQ(truth[0][2], 0.0);
  EXPECT_LT(wheel_counts(data, 1200.0), 1e-6);

  const std::string slipping = dir.Path("slipping"), fine = dir.Path("fine");
  ASSERT_EQ(RunFitcal(dir, "simulate --model asoc --wheel-slip-sigma 0.05 --out " + slipping)
                .exit_code,
            0);
  EXPECT_NE(ReadFileBytes(slipping + "/runs/umbmark_cw-rep06_encoders.csv"),
            ReadFileBytes(data + "/runs/umbmark_cw-rep06_encoders.csv"));
  EXPECT_EQ(ReadFileBytes(slipping + "/runs/umbmark_cw-rep06_ground_truth.csv"),
            ReadFileBytes(data + "/runs/umbmark_cw-rep06_ground_truth.csv"));
  ASSERT_EQ(RunFitcal(dir, "simulate --model asoc --encoder-counts-per-rev 4096 --out " + fine)
                .exit_code,
            0);
  EXPECT_LT(wheel_counts(fine, 4096.0), 1e-6);
  EXPECT_GT(wheel_counts(fine, 1200.0), 0.1);
}

// The ground-truth stamps of a run, from its CSV's first column.
std::vector<double> GroundTruthTimes(const std::string& path) {
  std::vector<double> t;
  const std::string text = ReadFileBytes(path);
  for (std::size_t at = text.find('\n'); at != std::string::npos && at + 1 < text.size();
       at = text.find('\n', at + 1)) {
    t.push_back(std::strtod(text.c_str() + at + 1, nullptr));
  }
  return t;
}

// --inject and --slip-sigma reach omni3's stepped physics through --model as without it. A
// time_offset of tau stamps each ground-truth pose tau late (odometry/effects.h) and draws nothing,
// so every stamp moves by exactly tau; the stamps are written with 6 decimals, hence 1e-6.
// --slip-sigma 0 takes the slip out: the wheels roll as counted, so the ground truth moves.
TEST(SimulateCommand, TheFlowerTakesInjectedEffectsAndSlipThroughModel) {
  TempDir dir;
  const std::string plain = dir.Path("plain"), late = dir.Path("late"), grip = dir.Path("grip");
  const std::string common = " --repetitions 1 --seed 4 --out ";
  ASSERT_EQ(RunFitcal(dir, "simulate --model omni3" + common + plain).exit_code, 0);
  ASSERT_EQ(RunFitcal(dir, "simulate --model omni3 --inject time_offset=0.05" + common + late)
                .exit_code,
            0);
  ASSERT_EQ(RunFitcal(dir, "simulate --model omni3 --slip-sigma 0" + common + grip).exit_code, 0);
  const std::vector<double> t0 = GroundTruthTimes(plain + "/runs/R1-rep01_ground_truth.csv");
  const std::vector<double> t1 = GroundTruthTimes(late + "/runs/R1-rep01_ground_truth.csv");
  ASSERT_EQ(t0.size(), t1.size());
  ASSERT_GT(t0.size(), 10u);
  for (std::size_t i = 0; i < t0.size(); ++i) EXPECT_NEAR(t1[i] - t0[i], 0.05, 1e-6) << i;
  EXPECT_TRUE(ReadFileBytes(late + "/runs/R1-rep01_encoders.csv") ==
              ReadFileBytes(plain + "/runs/R1-rep01_encoders.csv"));
  EXPECT_TRUE(ReadFileBytes(grip + "/runs/R1-rep01_ground_truth.csv") !=
              ReadFileBytes(plain + "/runs/R1-rep01_ground_truth.csv"));
}

// Without --model the --robot's model is simulated: a differential drive's robot YAML gives its
// own scenario's data set (UMBmark squares and circles), the robot written as given.
TEST(SimulateCommand, WithoutModelTheRobotFileChoosesIt) {
  TempDir dir;
  const std::string example = dir.Path("example"), data = dir.Path("data");
  ASSERT_EQ(RunFitcal(dir, "simulate --model diff_drive --repetitions 1 --out " + example)
                .exit_code,
            0);
  const Result r =
      RunFitcal(dir, "simulate --robot " + example + "/robot.yaml --repetitions 1 --out " + data);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadFileBytes(data + "/robot.yaml"), ReadFileBytes(example + "/robot.yaml"));
  EXPECT_TRUE(fs::exists(data + "/runs/square-cw-rep01_encoders.csv"));
}

// data/flower was written by `fitcal simulate --out data/flower --robot data/robots/apr02.yaml
// --repetitions 10 --seed 1` (docs/simulate.md) with the omni3-only simulator this command no
// longer has; the generic simulator (the omni3 model through the seam, the flower's stepped
// physics: tests/flower_scenario.h) regenerates it. Run i draws from its own generator seeded
// by (seed, i), so two repetitions with the same seed must reproduce the first 72 runs' files,
// the robot and the first 72 entries of dataset.yaml exactly.
TEST(SimulateCommand, RegeneratesTheShippedFlowerByteForByte) {
  TempDir dir;
  const std::string data = dir.Path("flower");
  const std::string source = std::string(FITCAL_SOURCE_DIR) + "/data/";
  ASSERT_EQ(RunFitcal(dir, "simulate --out " + data + " --robot " + source +
                               "robots/apr02.yaml --repetitions 2 --seed 1")
                .exit_code,
            0);
  int files = 0;
  for (const auto& entry : fs::directory_iterator(data + "/runs")) {
    SCOPED_TRACE(entry.path().filename().string());
    EXPECT_EQ(ReadFileBytes(entry.path()),
              ReadFileBytes(source + "flower/runs/" + entry.path().filename().string()));
    ++files;
  }
  EXPECT_EQ(files, 144);
  EXPECT_EQ(ReadFileBytes(data + "/robot.yaml"), ReadFileBytes(source + "flower/robot.yaml"));
  const std::string index = ReadFileBytes(data + "/dataset.yaml");
  EXPECT_EQ(std::count(index.begin(), index.end(), '\n'), 2 + 72);
  EXPECT_EQ(index, ReadFileBytes(source + "flower/dataset.yaml").substr(0, index.size()));
  // The truth beside it (data/flower predates true_robot.yaml and is kept as shipped): Palacin
  // Table 5, as printed (R m, r m, delta deg).
  const Robot truth = ReadRobotModelFile(data + "/true_robot.yaml")->robot();
  const double table5[9] = {0.218643, 0.215735, 0.216287, 0.155068, 0.151534,
                            0.152728, 59.7397,  179.6820, 301.5735};
  ASSERT_EQ(truth.NumParameters(), 9);
  for (int k = 0; k < 9; ++k) {
    EXPECT_NEAR(truth.nominal[k] * truth.parameters[k].DisplayScale(), table5[k], 1e-9) << k;
  }
}

}  // namespace
}  // namespace fitcal
