// Issue 39's end-to-end measure through the command line, as a user runs it: a simulated robot
// whose pose source is a sensor mounted at (1.5 m, -0.2 m, 5 deg), declared in the robot YAML as
// `ground_truth_frame` with a nominal guess 0.3 m, 0.2 m and 5 deg off; wheel guesses far off
// (radii 5 % to 10 %, separation / wheelbase 20 %, the tricycle's steering gain 2.5x); encoders
// recorded as 32-bit running totals that wrap, steering as counts of an absolute encoder, three
// counter glitches (tests/recorded_counts.h). `fit` with its defaults must exit 0, land every
// parameter and the mount within 3 of its written sigmas of the truth, and predict held-out
// drift per 1 m as the true model does (both replayed by `report --calibration`).

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>

#include "models/model_registry.h"
#include "tests/recorded_counts.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

using testing::Has;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;
using testing::WriteFileBytes;

constexpr const char* kTrueFrame = "ground_truth_frame: {x_m: 1.5, y_m: -0.2, yaw_deg: 5.0}\n";
constexpr const char* kGuessedFrame = "ground_truth_frame: {x_m: 1.2, y_m: 0.0, yaw_deg: 0.0}\n";

struct RecordedCase {
  const char* name;
  const char* model;
  const char* nominal;  // the maker's guess, bounds wide enough to hold the truth
  const char* truth;
  std::set<std::string> angle_columns;  // read as counts of an absolute encoder
  const char* known_failure;            // measured numbers and cause; empty when it passes
  const char* fit_says;                 // a line fit must print ("" for none in particular)
  // The mount's nominal guess. A robot that moves sideways holds the mount's x and y at the guess
  // by design (models/mounted_model.h): its guess is right there, only the yaw is off.
  const char* frame_guess = kGuessedFrame;
};

constexpr const char* kDiffDriveGuess =
    "model: diff_drive\nname: d\nwheels:\n  - {name: right, radius_m: 0.042}\n"
    "  - {name: left, radius_m: 0.042}\nwheel_separation_m: 0.200\n"
    "bounds: {radius_m: [0.030, 0.060], wheel_separation_m: [0.150, 0.300]}\n";
constexpr const char* kTricycleGuess =
    "model: tricycle\nname: t\ntraction_wheel: {radius_m: 0.0325}\nwheelbase_m: 0.15\n"
    "steering_offset_deg: 0.0\nsteering_gain: 1.0\n"
    "bounds: {radius_m: [0.025, 0.045], wheelbase_m: [0.12, 0.25], "
    "steering_offset_deg: [-10.0, 10.0]}\n";
// Palacin's APR-02 (data/robots/apr02.yaml), the three-wheeled omni robot `simulate` drives on
// the flower (no --model).
constexpr const char* kOmni3Guess =
    "model: omni3\nname: o\nwheels:\n"
    "  - {name: a, distance_m: 0.195, radius_m: 0.148, angle_deg: 60.0}\n"
    "  - {name: b, distance_m: 0.195, radius_m: 0.148, angle_deg: 180.0}\n"
    "  - {name: c, distance_m: 0.195, radius_m: 0.148, angle_deg: 300.0}\n"
    "bounds: {distance_m: [0.170, 0.220], radius_m: [0.138, 0.158], angle_offset_deg: [-2.0, 2.0]}\n";

// The same maker's guess with the steering gain 5x the true 0.4 below (its default box [0.2, 20]).
constexpr const char* kTricycleGuessGain2 =
    "model: tricycle\nname: t\ntraction_wheel: {radius_m: 0.0325}\nwheelbase_m: 0.15\n"
    "steering_offset_deg: 0.0\nsteering_gain: 2.0\n"
    "bounds: {radius_m: [0.025, 0.045], wheelbase_m: [0.12, 0.25], "
    "steering_offset_deg: [-10.0, 10.0]}\n";

constexpr const char* kMecanumGuess =
    "model: omni\nname: m\nwheels:\n"
    "  - {name: fl, distance_m: 0.25, angle_deg: 36.86989765, radius_m: 0.05, "
    "drive_angle_deg: 0, roller_angle_deg: -45}\n"
    "  - {name: fr, distance_m: 0.25, angle_deg: -36.86989765, radius_m: 0.05, "
    "drive_angle_deg: 0, roller_angle_deg: 45}\n"
    "  - {name: rl, distance_m: 0.25, angle_deg: 143.13010235, radius_m: 0.05, "
    "drive_angle_deg: 0, roller_angle_deg: 45}\n"
    "  - {name: rr, distance_m: 0.25, angle_deg: -143.13010235, radius_m: 0.05, "
    "drive_angle_deg: 0, roller_angle_deg: -45}\n"
    "bounds: {distance_m: [0.22, 0.28], radius_m: [0.045, 0.055], "
    "angle_offset_deg: [-2.0, 2.0]}\n";

// Bounds are the user's (documented keys), wide enough for a 20 % error; the steering gain's
// are the default (a factor of 10 either way of the nominal). The tricycle's true gain is the
// issue's 0.4 guessed 5x (2.0), and 2.5 and 2 guessed 1. A gain of 0.4 reads a wheel at 90 deg
// as 225 deg at the column, past what an absolute encoder holds: simulate drives that robot's
// squares on arcs at the largest readable steering (61 deg here) instead of turning in place.
const RecordedCase kCases[] = {
    {"diff_drive_10pct", "diff_drive", kDiffDriveGuess,
     "model: diff_drive\nname: d\nwheels:\n  - {name: right, radius_m: 0.046}\n"
     "  - {name: left, radius_m: 0.040}\nwheel_separation_m: 0.220\n"
     "bounds: {radius_m: [0.030, 0.060], wheel_separation_m: [0.150, 0.300]}\n",
     {}, "", ""},
    {"diff_drive_20pct", "diff_drive", kDiffDriveGuess,
     "model: diff_drive\nname: d\nwheels:\n  - {name: right, radius_m: 0.046}\n"
     "  - {name: left, radius_m: 0.040}\nwheel_separation_m: 0.240\n"
     "bounds: {radius_m: [0.030, 0.060], wheel_separation_m: [0.150, 0.300]}\n",
     {}, "",
     "global start: the fit from the guess left residuals far above the noise"},
    {"tricycle_gain_2", "tricycle", kTricycleGuess,
     "model: tricycle\nname: t\ntraction_wheel: {radius_m: 0.0357}\nwheelbase_m: 0.18\n"
     "steering_offset_deg: 3.0\nsteering_gain: 2.0\n"
     "bounds: {radius_m: [0.025, 0.045], wheelbase_m: [0.12, 0.25], "
     "steering_offset_deg: [-10.0, 10.0]}\n",
     {"steering"}, "", ""},
    {"tricycle_gain_0_4_guessed_5x", "tricycle", kTricycleGuessGain2,
     "model: tricycle\nname: t\ntraction_wheel: {radius_m: 0.0357}\nwheelbase_m: 0.18\n"
     "steering_offset_deg: 3.0\nsteering_gain: 0.4\n"
     "bounds: {radius_m: [0.025, 0.045], wheelbase_m: [0.12, 0.25], "
     "steering_offset_deg: [-10.0, 10.0]}\n",
     {"steering"}, "", ""},
    {"tricycle_gain_2_5", "tricycle", kTricycleGuess,
     "model: tricycle\nname: t\ntraction_wheel: {radius_m: 0.0357}\nwheelbase_m: 0.18\n"
     "steering_offset_deg: 3.0\nsteering_gain: 2.5\n"
     "bounds: {radius_m: [0.025, 0.045], wheelbase_m: [0.12, 0.25], "
     "steering_offset_deg: [-10.0, 10.0]}\n",
     {"steering"}, "", ""},
    // A mecanum robot (the example wheels of models/omni/omni_model.h): the runs leave one
    // direction undetermined besides the model's gauge (R_rr, delta_rl, delta_rr) and the mount's
    // x and y; it is held at the nominal and the parameters that move along it are written with
    // the bounds' sigma along it (fit/model_fit.h, "Uncertainty"). Before that, R_fl missed by
    // -3.5 of its sigmas and ground_truth_yaw by +4.9.
    {"mecanum", "omni", kMecanumGuess,
     "model: omni\nname: m\nwheels:\n"
     "  - {name: fl, distance_m: 0.27, angle_deg: 36.86989765, radius_m: 0.053, "
     "drive_angle_deg: 0, roller_angle_deg: -45}\n"
     "  - {name: fr, distance_m: 0.25, angle_deg: -36.86989765, radius_m: 0.05, "
     "drive_angle_deg: 0, roller_angle_deg: 45}\n"
     "  - {name: rl, distance_m: 0.25, angle_deg: 143.13010235, radius_m: 0.05, "
     "drive_angle_deg: 0, roller_angle_deg: 45}\n"
     "  - {name: rr, distance_m: 0.25, angle_deg: -143.13010235, radius_m: 0.047, "
     "drive_angle_deg: 0, roller_angle_deg: -45}\n"
     "bounds: {distance_m: [0.22, 0.28], radius_m: [0.045, 0.055], "
     "angle_offset_deg: [-2.0, 2.0]}\n",
     {}, "", "NOT DETERMINED: the training runs leave a direction",
     "ground_truth_frame: {x_m: 1.5, y_m: -0.2, yaw_deg: 0.0}\n"},
    // The three-wheeled omni robot on the flower: its runs do not turn the body while they
    // translate, so a common turn of the wheel angles and the mount's yaw are one direction (and
    // the distances R with it), held and written NOT DETERMINED. Before, the gate selected the
    // fit without holds, which ran delta_a onto its bound (sigma 14 deg) with exit 0.
    {"omni3", "omni3", kOmni3Guess,
     "model: omni3\nname: o\nwheels:\n"
     "  - {name: a, distance_m: 0.200, radius_m: 0.152, angle_deg: 61.0}\n"
     "  - {name: b, distance_m: 0.190, radius_m: 0.146, angle_deg: 179.2}\n"
     "  - {name: c, distance_m: 0.195, radius_m: 0.148, angle_deg: 300.0}\n"
     "bounds: {distance_m: [0.170, 0.220], radius_m: [0.138, 0.158], "
     "angle_offset_deg: [-2.0, 2.0]}\n",
     {}, "", "ran onto a bound along the undetermined directions",
     "ground_truth_frame: {x_m: 1.5, y_m: -0.2, yaw_deg: 0.0}\n"},
};

std::string CountsYaml(const RecordedCase& c) {
  std::string yaml = testing::kCountsEncoderYaml;
  for (const std::string& a : c.angle_columns) {
    yaml += a + "_encoder: {ticks_per_rev: 8192, zero_tick: 5000}\n";
  }
  return yaml;
}

// Rewrites the simulated data set in `data` as recorded counts; three glitches in the second
// run (a training run), or the first after it whose first wheel drives forward long enough (the
// flower's first runs turn omni3's wheel a backwards). Returns the glitch lines as `fit` names
// them.
std::vector<std::string> RecordAsCounts(const RecordedCase& c, const std::string& data) {
  const YAML::Node index = YAML::LoadFile(data + "/dataset.yaml");
  const std::string robot_file = data + "/" + index["robot"].as<std::string>();
  WriteFileBytes(robot_file, ReadFileBytes(robot_file) + CountsYaml(c));
  std::vector<std::string> named;
  for (std::size_t i = 0; i < index["runs"].size(); ++i) {
    const std::string file = data + "/" + index["runs"][i]["encoders"].as<std::string>();
    testing::Glitches glitches;
    WriteFileBytes(file, testing::AsCounts(ReadFileBytes(file), c.angle_columns,
                                           i >= 1 && named.empty() ? &glitches : nullptr));
    for (int line : glitches.lines) {
      named.push_back(file + ":" + std::to_string(line) + ": counter glitch");
    }
  }
  return named;
}

// Held-out drift per 1 m (translation %) of `calibration` replayed on the runs `fit` held out.
double HeldOutDriftPerMetre(const TempDir& dir, const std::string& data,
                            const std::string& calibration, const std::string& out) {
  const auto r = RunFitcal(dir, "report --logs " + data + " --calibration " + calibration +
                                    " --train-reps 1-5 --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // The window lengths the report chose for the runs (short runs start at 0.25 m): the 1 m one.
  for (const YAML::Node& window : YAML::LoadFile(out + "/metrics.json")["drift"]) {
    if (window["length_m"].as<double>() == 1.0) {
      return window["translation_percent"]["after"].as<double>();
    }
  }
  ADD_FAILURE() << out << ": no drift over 1 m windows";
  return 0.0;
}

class RecordedRobot : public ::testing::TestWithParam<RecordedCase> {};

TEST_P(RecordedRobot, DefaultFitRecoversWheelsAndMountFromCountsFarFromTheGuess) {
  const RecordedCase c = GetParam();
  if (*c.known_failure != '\0') GTEST_SKIP() << c.known_failure;
  TempDir dir;
  const std::string data = dir.Path("data"), cal = dir.Path("calibrated.yaml");
  WriteFileBytes(dir.Path("nominal.yaml"), std::string(c.nominal) + c.frame_guess);
  WriteFileBytes(dir.Path("truth.yaml"), std::string(c.truth) + kTrueFrame);
  // simulate's default noise (docs/simulate.md): ground truth 2 mm and 0.2 deg, encoder rates
  // 0.02 rad/s; 6 repetitions: fit's default --train-reps 1-5 fits, the 6th is held out.
  // omni3 is simulated on the flower, simulate's default without --model.
  const std::string model_flag =
      std::string(c.model) == "omni3" ? "" : std::string("--model ") + c.model;
  auto r = RunFitcal(dir, "simulate " + model_flag + " --robot " +
                              dir.Path("nominal.yaml") + " --truth " + dir.Path("truth.yaml") +
                              " --out " + data + " --seed 5 --repetitions 6");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> glitches = RecordAsCounts(c, data);
  ASSERT_EQ(glitches.size(), 3u);
  WriteFileBytes(dir.Path("truth_counts.yaml"), std::string(c.truth) + kTrueFrame + CountsYaml(c));

  r = RunFitcal(dir, "fit --logs " + data + " --out " + cal);
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  for (const std::string& g : glitches) EXPECT_TRUE(Has(r.err, g)) << g;
  EXPECT_TRUE(Has(r.out, c.fit_says)) << c.fit_says;
  EXPECT_TRUE(Has(r.out, "encoder glitches: 3 intervals in 1 run dropped from the fit")) << r.out;

  // Every parameter, the mount's three numbers included, within 3 of its written sigmas (the
  // fit's covariance scaled by its residual variance, i.e. derived from the noise above); the
  // guess more than 3 of them away (a fit that did not move fails).
  const Robot fitted = ReadRobotModelFile(cal)->robot();
  const Robot truth = ReadRobotModelFile(dir.Path("truth_counts.yaml"))->robot();
  const Robot guess = ReadRobotModelFile(dir.Path("nominal.yaml"))->robot();
  // Parameters held by design (a gauge, the mecanum's mount x and y) are written at the guess with
  // sigma 0, and the guess is the truth there: equal to the YAML's 10 significant digits. A
  // parameter the case leaves at the truth is not asked to have moved, nor one written as not
  // determined (its sigma is the bounds', which the guess lies well inside).
  const YAML::Node block = YAML::LoadFile(cal)["calibration"];
  const YAML::Node sigma = block["sigma"];
  std::set<std::string> held, not_determined;
  for (const YAML::Node& name : block["held"]) held.insert(name.as<std::string>());
  for (const YAML::Node& name : block["not_determined"])
    not_determined.insert(name.as<std::string>());
  ASSERT_EQ(fitted.NumParameters(), truth.NumParameters());
  for (int k = 0; k < fitted.NumParameters(); ++k) {
    const ParameterInfo& info = fitted.parameters[k];
    ASSERT_TRUE(sigma[info.KeyName()].IsDefined()) << info.name;
    const double s = sigma[info.KeyName()].as<double>() / info.DisplayScale();
    if (held.count(info.name) > 0) {
      EXPECT_NEAR(fitted.nominal[k], truth.nominal[k], 1e-9 * std::abs(truth.nominal[k]))
          << info.name;
      continue;
    }
    ASSERT_GT(s, 0.0) << info.name;
    const double miss = (fitted.nominal[k] - truth.nominal[k]) / s;
    std::printf("%-20s truth %.6g fitted %.6g: %+.2f sigma\n", info.name.c_str(),
                truth.nominal[k], fitted.nominal[k], miss);
    EXPECT_LT(std::abs(miss), 3.0) << info.name;
    // A parameter the runs did not determine carries the bounds' sigma: it need not have moved.
    if (guess.nominal[k] != truth.nominal[k] && not_determined.count(info.name) == 0) {
      EXPECT_GT(std::abs(guess.nominal[k] - truth.nominal[k]), 3.0 * s) << info.name;
    }
  }

  // Held-out drift per 1 m: the true model's is the noise floor (measured 0.47 % for both
  // models: ground-truth noise over 1 m windows); a calibration within its sigmas may add at most
  // as much again (3 sigma of a radius is ~0.3 % of scale, under that floor).
  const double fit_drift = HeldOutDriftPerMetre(dir, data, cal, dir.Path("report_fit"));
  const double true_drift =
      HeldOutDriftPerMetre(dir, data, dir.Path("truth_counts.yaml"), dir.Path("report_true"));
  std::printf("held-out drift per 1 m: fitted %.3f %%, true model %.3f %%\n", fit_drift,
              true_drift);
  EXPECT_LT(fit_drift, 2.0 * true_drift);
}

INSTANTIATE_TEST_SUITE_P(Models, RecordedRobot, ::testing::ValuesIn(kCases),
                         [](const auto& test) { return std::string(test.param.name); });

// A diff drive guessed with radii of 0.042 m and a separation of 0.2 m (nominal.yaml in `dir`)
// and its truth (truth.yaml), both in the sweep's box.
void WriteGuessAndTruth(const TempDir& dir, double r_right, double r_left, double separation) {
  const auto yaml = [](double right, double left, double sep) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "model: diff_drive\nname: d\nwheels:\n  - {name: right, radius_m: %.10g}\n"
                  "  - {name: left, radius_m: %.10g}\nwheel_separation_m: %.10g\n"
                  "bounds: {radius_m: [0.025, 0.060], wheel_separation_m: [0.120, 0.300]}\n",
                  right, left, sep);
    return std::string(text);
  };
  WriteFileBytes(dir.Path("nominal.yaml"), yaml(0.042, 0.042, 0.2));
  WriteFileBytes(dir.Path("truth.yaml"), yaml(r_right, r_left, separation));
}

// Two noisy squares (the first two runs of one repetition, 3.8x simulate's default noise) of a
// diff drive guessed 9-18 % off: the track fit from the guess ended in a local minimum that held
// the common scale of wheels and track (and one more direction) as undetermined, training CF 1.95
// against 0.03, written with exit 0 inside the bounds' wide sigmas (found by a randomized sweep,
// stop 65). A track fit holding a direction now tries the global start (fit/model_fit.cc,
// ReasonToStartAcrossTheBox). Every parameter determined and within 3 of its sigmas of the truth.
TEST(FarFromTheGuessOnTracks, AHeldDirectionOfATrackFitTriesTheGlobalStart) {
  TempDir dir;
  WriteGuessAndTruth(dir, 0.0483777644, 0.0343787927, 0.181986811);
  const std::string data = dir.Path("data"), cal = dir.Path("cal.yaml");
  const auto sim = RunFitcal(
      dir, "simulate --model diff_drive --robot " + dir.Path("nominal.yaml") + " --truth " +
               dir.Path("truth.yaml") + " --seed 133127 --repetitions 1 --gt-position-sigma-m " +
               "0.007557715 --gt-heading-sigma-deg 0.7557715 --wheel-rate-sigma-rad-s " +
               "0.07557715 --out " + data);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  std::istringstream index(ReadFileBytes(data + "/dataset.yaml"));
  std::string line, kept;
  for (int runs = 0; std::getline(index, line);) {
    if (line.rfind("  - {id:", 0) == 0 && ++runs > 2) continue;
    kept += line + "\n";
  }
  WriteFileBytes(data + "/dataset.yaml", kept);
  const auto r = RunFitcal(dir, "fit --logs " + data + " --out " + cal);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const YAML::Node block = YAML::LoadFile(cal)["calibration"];
  EXPECT_FALSE(block["not_determined"].IsDefined() && block["not_determined"].size() > 0)
      << r.out;
  const Robot fitted = ReadRobotModelFile(cal)->robot();
  const Robot truth = ReadRobotModelFile(dir.Path("truth.yaml"))->robot();
  for (int k = 0; k < truth.NumParameters(); ++k) {
    const ParameterInfo& info = fitted.parameters[k];
    const double sigma = block["sigma"][info.KeyName()].as<double>() / info.DisplayScale();
    EXPECT_LT(std::abs(fitted.nominal[k] - truth.nominal[k]), 3.0 * sigma) << info.name;
  }
}

// Keeps the rows of a CSV (header kept) whose first column is at most t_max.
void CutCsvAt(const std::string& file, double t_max) {
  std::istringstream in(ReadFileBytes(file));
  std::string line, kept;
  for (bool header = true; std::getline(in, line); header = false) {
    if (header || std::stod(line.substr(0, line.find(','))) <= t_max) kept += line + "\n";
  }
  WriteFileBytes(file, kept);
}

// --residuals auto on a diff drive guessed far off (a radius 24 % off, every run cut to 55.6 % of
// its encoder time): the final pose's fit from the guess alone ends in a local minimum - training
// CF 1.64 against 0.007, r_left -34 % - and was written with exit 0 when the choice picked the
// final pose (found by a randomized sweep of `simulate` and `fit`, stop 65); a chosen final pose
// is now fitted from the track's fit too (FitFromGuessAndFrom, calibrate/choice_by_transfer.cc).
// Since the checkpoints sit on the ground truth's samples (stop 73, D-F1) the track's fit is
// unbiased here and chosen itself. Either way the fit written must be the truth: 1 % separates
// it, which the fit reaches within 0.05 %, from that minimum (and from swapped wheels: 0.032
// against 0.045).
TEST(ResidualKindChoice, AFitFarFromTheGuessOnCutRunsIsWrittenAtTheTruth) {
  TempDir dir;
  WriteGuessAndTruth(dir, 0.0319256392, 0.0449456803, 0.224940094);
  const std::string data = dir.Path("data"), cal = dir.Path("cal.yaml");
  const auto sim = RunFitcal(dir, "simulate --model diff_drive --robot " +
                                     dir.Path("nominal.yaml") + " --truth " +
                                     dir.Path("truth.yaml") + " --seed 905725 --out " + data);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  for (const YAML::Node& run : YAML::LoadFile(data + "/dataset.yaml")["runs"]) {
    const std::string encoders = data + "/" + run["encoders"].as<std::string>();
    std::istringstream rows(ReadFileBytes(encoders));
    std::string row, last;
    while (std::getline(rows, row)) last = row;
    const double t_max = 0.5559 * std::stod(last.substr(0, last.find(',')));
    CutCsvAt(encoders, t_max);
    CutCsvAt(data + "/" + run["ground_truth"].as<std::string>(), t_max);
  }
  // 1-99: nothing held out, the halves judge; each half is fitted from the guess and from the
  // whole fit (of the track or the final pose, as the choice goes). From the guess alone they
  // ended in local minima (halves' CF 3.08 -> 2.46) and the calibration was refused as "the runs
  // do not determine the parameters".
  const Robot truth = ReadRobotModelFile(dir.Path("truth.yaml"))->robot();
  // An explicit final pose, fitted from the guess alone, ended in that minimum too (radii 0.0445
  // and 0.0276 m, exit 0): it is fitted from the track's fit as well now
  // (FitAskedFinalPoseFromTheTrackToo, calibrate/choice_by_transfer.cc).
  for (const std::string training : {"1-9", "1-99", "1-9 --residuals final-pose"}) {
    const auto r = RunFitcal(dir, "fit --logs " + data + " --train-reps " + training + " --out " +
                                      cal);
    ASSERT_EQ(r.exit_code, 0) << training << r.out << r.err;
    const Robot fitted = ReadRobotModelFile(cal)->robot();
    for (int k = 0; k < truth.NumParameters(); ++k) {
      EXPECT_NEAR(fitted.nominal[k], truth.nominal[k], 0.01 * truth.nominal[k])
          << training << " " << truth.parameters[k].name;
    }
    // Validated on nothing, it records no validation figures (it wrote zeros).
    EXPECT_EQ(YAML::LoadFile(cal)["calibration"]["cf_validation"].IsDefined(), training != "1-99");
  }
}

}  // namespace
}  // namespace fitcal
