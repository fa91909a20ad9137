// Flags that no test ran through the command line before (issue 43 item 5), each checked for its
// effect on what the command writes, not only for its exit status.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "models/asoc/asoc_files.h"
#include "models/model_registry.h"
#include "odometry/pose2.h"
#include "tests/asoc_robot_file.h"
#include "tests/dataset_edit.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::Csv;
using testing::FitcalRun;
using testing::Has;
using testing::ReadCsv;
using testing::ReadFileBytes;
using testing::RunFiles;
using testing::RunFitcal;
using testing::Runs;
using testing::SimulateDiffDrive;
using testing::TempDir;
using testing::WriteCsv;

const std::string kFlower = std::string(FITCAL_SOURCE_DIR) + "/data/flower";

// fit --hold: the held parameters are written at their nominal values, bit for bit as the robot
// YAML gives them (the YAML holds degrees: a round trip through radians may move the last of 17
// digits, hence 1e-12 rad), while the free ones move (without the hold every delta moves too: the
// flower's true angles differ from the nominal by up to 1.6 deg, README).
TEST(FitHold, HeldParametersStayAtTheNominalAndTheOthersMove) {
  TempDir tmp;
  const std::string held = tmp.Path("held.yaml"), free = tmp.Path("free.yaml");
  const testing::FitcalRun h =
      RunFitcal(tmp, "fit --logs " + kFlower + " --hold delta_a,delta_b,delta_c --out " + held);
  ASSERT_EQ(h.exit_code, 0) << h.err;
  const testing::FitcalRun f = RunFitcal(tmp, "fit --logs " + kFlower + " --out " + free);
  ASSERT_EQ(f.exit_code, 0) << f.err;
  const Robot nominal = ReadRobotModelFile(kFlower + "/robot.yaml")->robot();
  const Robot with_hold = ReadRobotModelFile(held)->robot();
  const Robot without = ReadRobotModelFile(free)->robot();
  for (const char* name : {"delta_a", "delta_b", "delta_c"}) {
    const int k = RequireParameterIndex(nominal, name);
    EXPECT_NEAR(with_hold.nominal[k], nominal.nominal[k], 1e-12) << name;
    EXPECT_GT(std::abs(without.nominal[k] - nominal.nominal[k]), 1e-4) << name;
  }
  for (const char* name : {"R_a", "R_b", "R_c"}) {
    const int k = RequireParameterIndex(nominal, name);
    EXPECT_GT(std::abs(with_hold.nominal[k] - nominal.nominal[k]), 1e-3) << name;
  }
}

// The numbers of the first line of `text` matching `pattern` (a regex with capture groups).
std::vector<double> Captured(const std::string& text, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern))) return {};
  std::vector<double> out;
  for (std::size_t k = 1; k < m.size(); ++k) out.push_back(std::stod(m[k].str()));
  return out;
}

// ---------------------------------------------------------------------------------------------
// fit --closed-form-only (asoc-geometric until asoc41) and paper-tables --model asoc (asoc-tables).

// fit --closed-form-only (the closed form alone, through fit's gate) writes the closed form with a
// sigma for every parameter it measures, and each estimate is within 4 sigma of the simulator's
// truth (true_robot.yaml; asoc_calibration_test checks the coverage over 90 vehicles: 99 % within 3
// sigma, so 4 holds for these 18 on seed 3), and much closer to it than the nominal for the wheel
// radii (drawn up to 4 % off). `fit` writes the same kind of sigma for r_c and beta when its gate
// selects the closed form (before: 0). Seed 1: on seed 3 the Ceres fit of the six holds beats the
// closed form on the UMBmark circuits (CF 0.0046 against 0.0056) and the gate selects it.
TEST(AsocCommands, GeometricWritesEstimatesWithinTheirSigmasOfTheTruth) {
  TempDir tmp;
  const std::string data = tmp.Path("asoc"), out = tmp.Path("geo.yaml");
  ASSERT_EQ(
      RunFitcal(tmp, "simulate --model asoc --out " + data + " --repetitions 0 --seed 1").exit_code,
      0);
  const FitcalRun r = RunFitcal(tmp, "fit --closed-form-only --logs " + data + " --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "no fit: the robot's closed forms alone against the nominal")) << r.out;
  EXPECT_TRUE(Has(r.out, "result gate, CF on held-out runs (10):")) << r.out;
  const io::AsocRobot truth = io::ReadAsocRobot(data + "/true_robot.yaml");
  const io::AsocRobot nominal = io::ReadAsocRobot(data + "/robot.yaml");
  const io::AsocRobot calibrated = io::ReadAsocRobot(out);
  const YAML::Node sigma = YAML::LoadFile(out)["calibration"]["sigma"];
  ASSERT_TRUE(sigma.IsMap()) << ReadFileBytes(out);
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    const std::string c = std::to_string(i + 1);
    SCOPED_TRACE("castor " + c);
    const asoc::CastorParameters& t = truth.nominal.castors[i];
    const asoc::CastorParameters& e = calibrated.nominal.castors[i];
    const double s_rc = sigma["r_c_" + c + "_m"].as<double>();
    const double s_beta = DegToRad(sigma["beta_" + c + "_deg"].as<double>());
    EXPECT_GT(s_rc, 0.0);
    EXPECT_GT(s_beta, 0.0);
    EXPECT_LE(std::abs(e.offset_m - t.offset_m), 4.0 * s_rc);
    EXPECT_LE(std::abs(WrapAngle(e.encoder_bias_rad - t.encoder_bias_rad)), 4.0 * s_beta);
    for (int k = 0; k < 2; ++k) {
      const std::string w = std::to_string(k + 1);
      const double s_rw = sigma["r_w" + w + "_" + c + "_m"].as<double>();
      const double s_d = sigma["d_" + w + "_" + c + "_m"].as<double>();
      EXPECT_GT(s_rw, 0.0);
      EXPECT_GT(s_d, 0.0);
      EXPECT_LE(std::abs(e.wheel_radius_m[k] - t.wheel_radius_m[k]), 4.0 * s_rw);
      EXPECT_LE(std::abs(e.wheel_offset_m[k] - t.wheel_offset_m[k]), 4.0 * s_d);
      EXPECT_LT(std::abs(e.wheel_radius_m[k] - t.wheel_radius_m[k]),
                0.1 * std::abs(nominal.nominal.castors[i].wheel_radius_m[k] - t.wheel_radius_m[k]));
    }
  }
  const std::string cal = tmp.Path("fit.yaml");
  const FitcalRun fit = RunFitcal(tmp, "fit --logs " + data + " --out " + cal);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const YAML::Node record = YAML::LoadFile(cal)["calibration"];
  ASSERT_EQ(record["selected"].as<std::string>(), "asoc-geometric") << ReadFileBytes(cal);
  const io::AsocRobot written = io::ReadAsocRobot(cal);
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    const std::string c = std::to_string(i + 1);
    const double s_rc = record["sigma"]["r_c_" + c + "_m"].as<double>();
    const double s_beta = DegToRad(record["sigma"]["beta_" + c + "_deg"].as<double>());
    EXPECT_GT(s_rc, 0.0) << c;
    EXPECT_GT(s_beta, 0.0) << c;
    EXPECT_LE(std::abs(written.nominal.castors[i].offset_m - truth.nominal.castors[i].offset_m),
              4.0 * s_rc)
        << c;
    EXPECT_LE(std::abs(WrapAngle(written.nominal.castors[i].encoder_bias_rad -
                                 truth.nominal.castors[i].encoder_bias_rad)),
              4.0 * s_beta)
        << c;
  }
}

// fit --closed-form-only goes through fit's gate: a closed form that does not beat the nominal on the
// held-out runs is not written. The nominal here is the simulator's truth (true_robot.yaml as
// robot.yaml), which the estimate from quantised hold runs does not beat on the UMBmark circuits
// held out on seed 5 (CF 0.0033 against the closed form's 0.0054; on seeds 1-3 the closed form's
// errors happen to offset the truth's 20 Hz update error); before the gate it was written.
TEST(AsocCommands, GeometricRefusesAClosedFormThatDoesNotBeatTheNominal) {
  TempDir tmp;
  const std::string data = tmp.Path("asoc"), out = tmp.Path("geo.yaml");
  ASSERT_EQ(
      RunFitcal(tmp, "simulate --model asoc --out " + data + " --repetitions 0 --seed 5").exit_code,
      0);
  std::filesystem::copy_file(data + "/true_robot.yaml", data + "/robot.yaml",
                             std::filesystem::copy_options::overwrite_existing);
  const FitcalRun r = RunFitcal(tmp, "fit --closed-form-only --logs " + data + " --out " + out);
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_EQ(r.err,
            "fitcal: no calibration beats the nominal robot on the held-out runs (10); nothing "
            "written\n");
  EXPECT_FALSE(std::filesystem::exists(out));
}

// A robot whose model registers no closed form (the omni3 flower) has nothing for
// --closed-form-only to judge: one line naming the model and those that have one, exit 2, before
// any run is read (here the runs are missing) and nothing written. A flag only a fit uses is
// refused beside it the same way. Before (asoc-geometric), the runs were read and fitcal exited 1.
TEST(AsocCommands, ClosedFormOnlyRefusesAModelWithoutOneBeforeReadingRuns) {
  TempDir tmp;
  const std::string data = tmp.Path("flower"), out = tmp.Path("cal.yaml");
  std::filesystem::create_directories(data);
  for (const char* file : {"/dataset.yaml", "/robot.yaml"}) {
    std::filesystem::copy_file(kFlower + file, data + file);
  }
  const FitcalRun without = RunFitcal(tmp, "fit --logs " + data + " --out " + out);
  EXPECT_EQ(without.exit_code, 1) << without.err;  // the runs are missing
  const FitcalRun r = RunFitcal(tmp, "fit --closed-form-only --logs " + data + " --out " + out);
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_EQ(r.err,
            "fitcal: --closed-form-only: the omni3 model computes no closed form (models that "
            "do: asoc: asoc-geometric; diff_drive: umbmark)\n");
  const FitcalRun method =
      RunFitcal(tmp, "fit --closed-form-only --method crs2lm --logs " + kFlower + " --no-output");
  EXPECT_EQ(method.exit_code, 2) << method.err;
  EXPECT_EQ(method.err, "fitcal: --closed-form-only runs no fit, so it cannot take --method\n");
  EXPECT_FALSE(std::filesystem::exists(out));
}

// paper-tables --model asoc (Doebbler's Tables I and II): Table I's calibrated errors far below the uncalibrated ones (the drawn errors are
// 2 % for r_w and 8 deg for beta; the closed form's are set by the 0.07 deg pivot step: beta
// within q/2 = 0.035 deg), Table II's calibrated E_max 10x below the uncalibrated for every
// algorithm, over the --sets asked for; --sets 0 and a model without tables refused.
TEST(AsocCommands, TablesCalibrateEveryDrawnSet) {
  TempDir tmp;
  const FitcalRun r = RunFitcal(tmp, "paper-tables --model asoc --sets 4 --seed 1 --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Has(r.out, "Tables I and II, 4 random parameter sets (seed 1")) << r.out;
  const std::vector<double> rw = Captured(r.out, R"(\| r_w \| ([0-9.]+)% \| ([0-9.]+)% \|)");
  const std::vector<double> beta =
      Captured(r.out, R"(\| beta \| ([0-9.]+) deg \| ([0-9.]+) deg \|)");
  ASSERT_EQ(rw.size(), 2u) << r.out;
  ASSERT_EQ(beta.size(), 2u) << r.out;
  EXPECT_LT(rw[1], 0.1 * rw[0]);
  EXPECT_LT(beta[1], 0.035);
  EXPECT_GT(beta[0], 1.0);
  for (const char* algorithm : {"IPEC-1", "CAST-1", "CAST-0"}) {
    const std::vector<double> e = Captured(
        r.out, std::string(R"(\| )") + algorithm + R"( \| ([0-9.]+) mm [0-9.]+% \| ([0-9.]+) mm)");
    ASSERT_EQ(e.size(), 2u) << algorithm << r.out;
    EXPECT_LT(e[1], 0.1 * e[0]) << algorithm;
  }
  const FitcalRun none = RunFitcal(tmp, "paper-tables --model asoc --sets 0");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_TRUE(Has(none.err, "--sets")) << none.err;
  const FitcalRun omni3 = RunFitcal(tmp, "paper-tables --model omni3 --sets 1");
  EXPECT_EQ(omni3.exit_code, 2);
  EXPECT_EQ(omni3.err,
            "fitcal: --model omni3 reproduces no paper's tables (models that do: asoc)\n");
}

// ---------------------------------------------------------------------------------------------
// Clock offsets: fit --clock-offsets, report --clock-offsets, diagnose --clock-map.

constexpr double kShiftS = 0.15;  // the ground truth stamped 0.15 s late

// The simulated differential drive with every ground-truth stamp moved by kShiftS: ground truth
// stamped t + 0.15 belongs to encoder time t.
std::string ShiftedDiffDrive(const TempDir& dir) {
  const std::string data = SimulateDiffDrive(dir, "shifted");
  for (const RunFiles& run : Runs(data)) {
    Csv truth = ReadCsv(run.ground_truth);
    for (std::vector<double>& row : truth.rows) row[0] += kShiftS;
    WriteCsv(run.ground_truth, truth);
  }
  return data;
}

double EncoderPeriod(const std::string& data) {
  const Csv encoders = ReadCsv(Runs(data).front().encoders);
  return encoders.rows[1][0] - encoders.rows[0][0];
}

// fit --clock-offsets dataset finds the shift (within 4 sigma plus half an encoder period, the
// replay's timing convention: clock_offset_test) and writes it; without the flag (none) nothing
// is estimated nor written.
TEST(ClockOffsets, FitEstimatesAndWritesTheShift) {
  TempDir tmp;
  const std::string data = ShiftedDiffDrive(tmp);
  const std::string with = tmp.Path("with.yaml"), without = tmp.Path("without.yaml");
  const FitcalRun r = RunFitcal(
      tmp, "fit --logs " + data + " --train-reps 1 --clock-offsets dataset --out " + with);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node groups = YAML::LoadFile(with)["calibration"]["clock_offsets"]["groups"];
  ASSERT_EQ(groups.size(), 1u) << ReadFileBytes(with);
  const double offset = groups[0]["offset_s"].as<double>();
  const double sigma = groups[0]["sigma_s"].as<double>();
  EXPECT_GT(sigma, 0.0);
  EXPECT_NEAR(offset, kShiftS, 4.0 * sigma + 0.5 * EncoderPeriod(data));
  ASSERT_EQ(RunFitcal(tmp, "fit --logs " + data + " --train-reps 1 --out " + without).exit_code, 0);
  EXPECT_FALSE(YAML::LoadFile(without)["calibration"]["clock_offsets"]) << ReadFileBytes(without);
}

// report --clock-offsets: `recorded` (the default) re-stamps the ground truth by the offset the
// calibration records, `none` does not; on the shifted data the calibrated ATE with the offset
// is under half the one without (0.15 s at the runs' speed is centimetres).
TEST(ClockOffsets, ReportAppliesTheRecordedOffsetOrNot) {
  TempDir tmp;
  const std::string data = ShiftedDiffDrive(tmp), cal = tmp.Path("cal.yaml");
  ASSERT_EQ(
      RunFitcal(tmp, "fit --logs " + data + " --train-reps 1 --clock-offsets dataset --out " + cal)
          .exit_code,
      0);
  const std::string ate = R"(ATE RMSE \[m\] \(Eq\. 12\) +([0-9.]+) -> ([0-9.]+))";
  const FitcalRun recorded =
      RunFitcal(tmp, "report --logs " + data + " --calibration " + cal + " --out " + tmp.Path("a"));
  ASSERT_EQ(recorded.exit_code, 0) << recorded.err;
  EXPECT_TRUE(Has(recorded.out, "clock offsets: recorded by the calibration")) << recorded.out;
  const FitcalRun none = RunFitcal(tmp, "report --logs " + data + " --calibration " + cal +
                                            " --clock-offsets none --out " + tmp.Path("b"));
  ASSERT_EQ(none.exit_code, 0) << none.err;
  EXPECT_FALSE(Has(none.out, "clock offsets: recorded")) << none.out;
  const std::vector<double> a = Captured(recorded.out, ate), b = Captured(none.out, ate);
  ASSERT_EQ(a.size(), 2u) << recorded.out;
  ASSERT_EQ(b.size(), 2u) << none.out;
  EXPECT_LT(a[1], 0.5 * b[1]);
}

// diagnose --clock-map re-stamps the shifted ground truth (kept on most runs) and the odometry's
// heading walk the shift made goes away (the residual's high frequencies: a 0.15 s lag turns a
// turn's heading into noise); without the flag the header does not say re-mapped.
TEST(ClockOffsets, DiagnoseClockMapRemovesTheLag) {
  TempDir tmp;
  const std::string data = ShiftedDiffDrive(tmp);
  const FitcalRun mapped = RunFitcal(
      tmp, "diagnose --logs " + data + " --clock-map --max-effects 0 --out " + tmp.Path("m"));
  ASSERT_EQ(mapped.exit_code, 0) << mapped.err;
  const std::vector<double> kept =
      Captured(mapped.out, R"(clock map kept on ([0-9]+) of ([0-9]+))");
  ASSERT_EQ(kept.size(), 2u) << mapped.out;
  EXPECT_EQ(kept[1], 12.0);
  EXPECT_GE(kept[0], 10.0);
  EXPECT_TRUE(Has(mapped.out, "ground-truth clocks re-mapped")) << mapped.out;
  const FitcalRun plain =
      RunFitcal(tmp, "diagnose --logs " + data + " --max-effects 0 --out " + tmp.Path("p"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(Has(plain.out, "re-mapped")) << plain.out;
  const std::string walk = R"(odometry walk [0-9.]+ mm / [0-9.]+ mm / ([0-9.]+) deg)";
  const std::vector<double> w_mapped = Captured(mapped.out, walk),
                            w_plain = Captured(plain.out, walk);
  ASSERT_EQ(w_mapped.size(), 1u) << mapped.out;
  ASSERT_EQ(w_plain.size(), 1u) << plain.out;
  EXPECT_LT(w_mapped[0], w_plain[0] / 3.0);
}

// diagnose --alpha is the family-wise level of the tracing: the first round's threshold is alpha
// over the candidates it fitted (Bonferroni), counted here from the round's table; 5 % covers the
// threshold's two printed digits.
TEST(DiagnoseAlpha, TheThresholdIsAlphaOverTheCandidates) {
  TempDir tmp;
  const std::string data = SimulateDiffDrive(tmp, "data");
  for (const double alpha : {0.01, 0.3}) {
    SCOPED_TRACE("alpha " + std::to_string(alpha));
    char flag[32];
    std::snprintf(flag, sizeof flag, " --alpha %g", alpha);
    const FitcalRun r = RunFitcal(
        tmp, "diagnose --logs " + data + flag + " --out " + tmp.Path("d" + std::to_string(alpha)));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::size_t table = r.out.find("| candidate |");
    ASSERT_NE(table, std::string::npos) << r.out;
    const std::size_t end = r.out.find("\n\n", table);
    const std::string rows = r.out.substr(table, end - table);
    // The candidates fitted: the rows with a p value and its threshold (one that cannot be told
    // apart from the model is not fitted and has none).
    int candidates = 0;
    for (std::size_t at = rows.find(" >= "); at != std::string::npos;
         at = rows.find(" >= ", at + 1)) {
      ++candidates;
    }
    ASSERT_GT(candidates, 2) << rows;
    const std::vector<double> threshold = Captured(rows, R"(>= ([0-9.e-]+)\))");
    ASSERT_EQ(threshold.size(), 1u) << rows;
    EXPECT_NEAR(threshold[0], alpha / candidates, 0.05 * alpha / candidates) << rows;
  }
}

// What diagnose refuses before it fits (calibrate/diagnosis_calibration.h), each exit 2 with one
// line and nothing written: a robot YAML that already declares effects, and a split that leaves
// no held-out run to judge an effect on.
TEST(DiagnoseRefusals, DeclaredEffectsAndASplitWithoutHeldOutRunsAreRefusedBeforeAnyFit) {
  TempDir tmp;
  const std::string data = SimulateDiffDrive(tmp, "data");
  const FitcalRun one_sided =
      RunFitcal(tmp, "diagnose --logs " + data + " --train-reps 1-99 --out " + tmp.Path("a"));
  EXPECT_EQ(one_sided.exit_code, 2) << one_sided.err;
  EXPECT_TRUE(Has(one_sided.err, "diagnose needs training and held-out runs; got ")) << one_sided.err;
  EXPECT_TRUE(Has(one_sided.err, " training and 0 validation runs")) << one_sided.err;
  EXPECT_FALSE(fs::exists(tmp.Path("a")));

  std::ofstream(data + "/robot.yaml", std::ios::app)
      << "effects:\n  - {name: acceleration_slip, slip_s2_per_rad: 0.012}\n";
  const FitcalRun declared = RunFitcal(tmp, "diagnose --logs " + data + " --out " + tmp.Path("b"));
  EXPECT_EQ(declared.exit_code, 2) << declared.err;
  EXPECT_TRUE(Has(declared.err, "robot.yaml: the robot already declares effects")) << declared.err;
  EXPECT_EQ(std::count(declared.err.begin(), declared.err.end(), '\n'), 1) << declared.err;
  EXPECT_FALSE(fs::exists(tmp.Path("b")));
}

// ---------------------------------------------------------------------------------------------
// generalise --optiodom, --sessions, --effects (on '^square' against the rest, the squares'
// 4 runs counted from dataset.yaml).

int CountRows(const std::string& out, const std::string& candidate) {
  int n = 0;
  for (std::size_t at = out.find(" | " + candidate + " | "); at != std::string::npos;
       at = out.find(" | " + candidate + " | ", at + 1)) {
    ++n;
  }
  return n;
}

TEST(GeneraliseFlags, OptiodomAddsItsCandidateToEverySplit) {
  TempDir tmp;
  const std::string data = SimulateDiffDrive(tmp, "data");
  const std::string args =
      "generalise --logs " + data + " --train-trajectories '^square' --no-loso";
  const FitcalRun plain = RunFitcal(tmp, args);
  const FitcalRun with = RunFitcal(tmp, args + " --optiodom");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(with.exit_code, 0) << with.err;
  EXPECT_EQ(CountRows(plain.out, "optiodom"), 0) << plain.out;
  EXPECT_EQ(CountRows(with.out, "optiodom"), CountRows(with.out, "nominal")) << with.out;
  int squares = 0;
  for (const RunFiles& run : Runs(data)) squares += run.id.rfind("square", 0) == 0;
  // The square-trained row: trained on the squares, held out on the rest; calibrated.
  const std::vector<double> row = Captured(
      with.out, R"(\| '\^square' -> others \| optiodom \| ([0-9]+) \| ([0-9]+) \| ([0-9.]+) \|)");
  const std::vector<double> nominal = Captured(
      with.out, R"(\| '\^square' -> others \| nominal \| ([0-9]+) \| ([0-9]+) \| ([0-9.]+) \|)");
  ASSERT_EQ(row.size(), 3u) << with.out;
  ASSERT_EQ(nominal.size(), 3u) << with.out;
  EXPECT_EQ(row[0], squares);
  EXPECT_EQ(row[1], static_cast<double>(Runs(data).size()) - squares);
  EXPECT_LT(row[2], 0.5 * nominal[2]);
}

// --sessions: a leave-one-session-out session is a trajectory label (6 here) or a label and a
// repetition (12), counted from dataset.yaml.
TEST(GeneraliseFlags, SessionsChoosesWhatIsLeftOut) {
  TempDir tmp;
  const std::string data = SimulateDiffDrive(tmp, "data");
  std::set<std::string> labels;
  for (const YAML::Node& r : YAML::LoadFile(data + "/dataset.yaml")["runs"]) {
    labels.insert(r["trajectory"].as<std::string>());
  }
  const std::string args = "generalise --logs " + data + " --train-trajectories '^square'";
  const std::string sessions = R"(leave-one-session-out \(([0-9]+) sessions)";
  const FitcalRun label = RunFitcal(tmp, args + " --sessions label");
  const FitcalRun repetition = RunFitcal(tmp, args + " --sessions repetition");
  ASSERT_EQ(label.exit_code, 0) << label.err;
  ASSERT_EQ(repetition.exit_code, 0) << repetition.err;
  EXPECT_EQ(Captured(label.out, sessions), std::vector<double>{double(labels.size())}) << label.out;
  EXPECT_EQ(Captured(repetition.out, sessions), std::vector<double>{double(Runs(data).size())})
      << repetition.out;
}

// --effects: the track fit alone and with the named effect join the candidates of each split.
TEST(GeneraliseFlags, EffectsAddTheTrackFitsWithAndWithout) {
  TempDir tmp;
  const std::string data = SimulateDiffDrive(tmp, "data");
  const std::string args =
      "generalise --logs " + data + " --train-trajectories '^square' --no-loso";
  const FitcalRun plain = RunFitcal(tmp, args);
  const FitcalRun with = RunFitcal(tmp, args + " --effects pivot_yaw_gain");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(with.exit_code, 0) << with.err;
  EXPECT_EQ(CountRows(plain.out, "track fit + pivot_yaw_gain"), 0) << plain.out;
  EXPECT_GE(CountRows(with.out, "track fit + pivot_yaw_gain"), 2) << with.out;
  EXPECT_EQ(CountRows(with.out, "track fit + pivot_yaw_gain"), CountRows(with.out, "track fit"))
      << with.out;
  const FitcalRun unknown = RunFitcal(tmp, args + " --effects nosuch");
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_TRUE(Has(unknown.err, "nosuch")) << unknown.err;
}

// ---------------------------------------------------------------------------------------------
// export --force: an existing parameter file of another node is refused without it (exit 2,
// the file unchanged) and replaced with it.
TEST(ExportForce, ReplacesOnlyWhenAsked) {
  TempDir tmp;
  const std::string data = SimulateDiffDrive(tmp, "data"), cal = tmp.Path("cal.yaml");
  ASSERT_EQ(RunFitcal(tmp, "fit --logs " + data + " --out " + cal).exit_code, 0);
  const std::string out = tmp.Path("params.yaml");
  const std::string args = "export ros2-control --controller diff_drive_controller --calibration " +
                           cal + " --out " + out;
  ASSERT_EQ(RunFitcal(tmp, args).exit_code, 0);
  const std::string first = ReadFileBytes(out);
  const FitcalRun refused = RunFitcal(tmp, args + " --node-name other");
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_TRUE(Has(refused.err, "--force")) << refused.err;
  EXPECT_EQ(ReadFileBytes(out), first);
  const FitcalRun forced = RunFitcal(tmp, args + " --node-name other --force");
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_TRUE(YAML::LoadFile(out)["other"]) << ReadFileBytes(out);
}

// compare fits final poses only: the track's flags are not its flags (issue 41: it declared them
// and ignored them - `slsqp --residuals track` gave the final-pose table). Refused, one line,
// exit 2, nothing written; the final-pose weights it does use (--heading-sigma-deg) still change
// its fit: Eq. 14's 1 m : 1 rad against a heading weighed 100x more moves the flower's CF.
TEST(CompareFlags, TrackFlagsAreRefusedAndTheFinalPoseWeightsApply) {
  TempDir tmp;
  const std::string base = "compare --logs " + kFlower + " --methods ceres --repetitions 2 ";
  for (const std::string flag : {"--residuals track", "--clock-offsets run",
                                 "--track-heading increments", "--weights estimated"}) {
    const FitcalRun refused = RunFitcal(tmp, base + flag + " --out " + tmp.Path("c"));
    EXPECT_EQ(refused.exit_code, 2) << flag << "\n" << refused.out;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_TRUE(Has(refused.err, flag.substr(0, flag.find(' ')))) << refused.err;
    for (const char* ext : {".csv", ".md", "_trace.csv"}) {
      EXPECT_FALSE(fs::exists(tmp.Path(std::string("c") + ext))) << flag << ext;
    }
  }
  const auto cf_of = [&](const std::string& extra) {
    const FitcalRun run = RunFitcal(tmp, base + extra + " --no-output --quiet");
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return run.out;
  };
  EXPECT_NE(cf_of(""), cf_of("--heading-sigma-deg 0.573"));
}

// ---------------------------------------------------------------------------------------------
// fit --loss and --objective on the final-pose fit (where they apply): one training run's ground
// truth ends 0.3 m off (an outlier among 6). Squares follow it (0.35-0.75 % off the fit on the
// clean data); a Cauchy loss of 1 cm and Eq. 14's sum of norms both stay within a third of that
// distance of the clean fit, and the record names the objective.
TEST(FitRobustness, LossAndObjectiveResistAnOutlierRun) {
  TempDir tmp;
  const std::string clean = SimulateDiffDrive(tmp, "clean");
  const std::string outlier = SimulateDiffDrive(tmp, "outlier");
  const RunFiles bad = Runs(outlier).front();
  ASSERT_EQ(bad.repetition, 1);
  Csv truth = ReadCsv(bad.ground_truth);
  for (std::size_t k = truth.rows.size() * 4 / 5; k < truth.rows.size(); ++k)
    truth.rows[k][1] += 0.3;
  WriteCsv(bad.ground_truth, truth);
  const auto fit = [&tmp](const std::string& data, const std::string& flags,
                          const std::string& name) {
    const std::string out = tmp.Path(name + ".yaml");
    const FitcalRun r =
        RunFitcal(tmp, "fit --logs " + data + " --train-reps 1 --residuals final-pose " + flags +
                           " --out " + out);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return out;
  };
  const std::string reference = fit(clean, "", "clean");
  const std::string squares = fit(outlier, "", "squares");
  const std::string cauchy = fit(outlier, "--loss cauchy --loss-scale 0.01", "cauchy");
  const std::string eq14 = fit(outlier, "--objective eq14", "eq14");
  EXPECT_TRUE(
      Has(YAML::LoadFile(cauchy)["calibration"]["objective"].as<std::string>(), "cauchy loss"));
  EXPECT_TRUE(Has(YAML::LoadFile(eq14)["calibration"]["objective"].as<std::string>(), "Eq. 14"));
  const std::vector<double> p0 = ReadRobotModelFile(reference)->robot().nominal;
  const std::vector<double> ps = ReadRobotModelFile(squares)->robot().nominal;
  for (const std::string& robust : {cauchy, eq14}) {
    const std::vector<double> p = ReadRobotModelFile(robust)->robot().nominal;
    for (std::size_t k = 0; k < p0.size(); ++k) {
      EXPECT_LT(std::abs(p[k] - p0[k]), std::abs(ps[k] - p0[k]) / 3.0) << robust << " " << k;
    }
  }
}

}  // namespace
}  // namespace fitcal
