// Input classes (issue 31, item 3), each through the command a user runs, on a small simulated
// data set of a model other than omni3 (omni3 has its own tests in refusal_test): one line naming
// the file (and the line or key) and what is wrong, the exit status the README gives, nothing
// written. And the fit that has nothing to judge it (item 1): refused, not written with exit 0.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "io/input_error.h"
#include "io/yaml_reader.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::Has;
using testing::Lines;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;
using testing::WriteFileBytes;

// Every run file of the data set in `data` whose name holds `suffix`: each row's numbers passed
// through `edit` and written back (%.9g), the header kept.
void EditRows(const fs::path& data, const std::string& suffix,
              const std::function<void(std::vector<double>&)>& edit) {
  for (const auto& e : fs::directory_iterator(data / "runs")) {
    if (!Has(e.path().filename().string(), suffix)) continue;
    std::istringstream in(ReadFileBytes(e.path()));
    std::string line, out;
    std::getline(in, line);
    out = line + "\n";
    while (std::getline(in, line)) {
      std::vector<double> row =
          testing::CsvNumbers(line, 1 + std::count(line.begin(), line.end(), ','));
      edit(row);
      for (std::size_t k = 0; k < row.size(); ++k) {
        char number[32];
        std::snprintf(number, sizeof number, k + 1 < row.size() ? "%.9g," : "%.9g\n", row[k]);
        out += number;
      }
    }
    WriteFileBytes(e.path(), out);
  }
}

class InputClassesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = dir_.path() / "data";
    const auto r = RunFitcal(dir_, "simulate --model diff_drive --repetitions 3 --seed 4 --out '" +
                                       data_.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    out_ = dir_.path() / "cal.yaml";
  }

  // `fit` on the data set: must fail with `exit_code` and one line holding every `parts`, and
  // write nothing.
  void ExpectFitRefused(int exit_code, const std::vector<std::string>& parts,
                        const std::string& extra = "") {
    const auto r = RunFitcal(
        dir_, "fit --logs '" + data_.string() + "' --out '" + out_.string() + "' " + extra);
    EXPECT_EQ(r.exit_code, exit_code) << r.err << r.out;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    for (const std::string& part : parts) EXPECT_TRUE(Has(r.err, part)) << part << " in " << r.err;
    EXPECT_FALSE(fs::exists(out_));
  }

  std::string RobotYaml() const { return ReadFileBytes(data_ / "robot.yaml"); }
  void SetRobotYaml(const std::string& text) const { WriteFileBytes(data_ / "robot.yaml", text); }
  static std::string Replace(std::string text, const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
  }

  // Every encoder log, its value columns multiplied by `factor` (a unit slip).
  void ScaleRates(double factor) const {
    EditRows(data_, "_encoders.csv", [&](std::vector<double>& t_a_b) {
      t_a_b[1] *= factor;
      t_a_b[2] *= factor;
    });
  }

  TempDir dir_;
  fs::path data_, out_;
};

TEST_F(InputClassesTest, TheDataSetItselfFitsAndCarriesSigmas) {
  const auto r =
      RunFitcal(dir_, "fit --logs '" + data_.string() + "' --out '" + out_.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string cal = ReadFileBytes(out_);
  EXPECT_TRUE(Has(cal, "sigma:")) << cal;
  EXPECT_FALSE(Has(cal, "sigma: ~")) << cal;
  EXPECT_FALSE(Has(cal, "sigma: null")) << cal;
}

// One run: three final-pose residuals for three parameters, fitted exactly whatever the robot.
TEST_F(InputClassesTest, AFitWithNoResidualDegreesOfFreedomIsRefused) {
  std::istringstream in(ReadFileBytes(data_ / "dataset.yaml"));
  std::string robot, runs, first;
  std::getline(in, robot);
  std::getline(in, runs);
  std::getline(in, first);
  WriteFileBytes(data_ / "dataset.yaml", robot + "\n" + runs + "\n" + first + "\n");
  ExpectFitRefused(1,
                   {"1 training run gives 3 final-pose residuals for 3 free parameters",
                    "Record at least 2 training runs"},
                   "--residuals final-pose");
  // Fitted on its track (the default where the ground truth is dense), the same run has
  // residuals to spare: it is judged on its own held-out time blocks, and the fit of the whole
  // run is written with its sigmas.
  const auto r = RunFitcal(dir_, "fit --logs '" + data_.string() + "' --out '" + out_.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_TRUE(Has(r.out, "judged on held-out time blocks")) << r.out;
  EXPECT_TRUE(Has(ReadFileBytes(out_), "held-out time blocks")) << ReadFileBytes(out_);
  EXPECT_FALSE(Has(ReadFileBytes(out_), "null")) << ReadFileBytes(out_);
}

TEST_F(InputClassesTest, RatesInDegreesPerSecondAreNamed) {
  ScaleRates(180.0 / M_PI);
  ExpectFitRefused(1, {"not in rad/s", "deg/s"});
}

TEST_F(InputClassesTest, RatesInRpmAreNamed) {
  ScaleRates(30.0 / M_PI);
  ExpectFitRefused(1, {"not in rad/s", "rpm"});
}

TEST_F(InputClassesTest, GroundTruthInMillimetresIsNamed) {
  EditRows(data_, "_ground_truth.csv", [](std::vector<double>& t_x_y_theta) {
    t_x_y_theta[1] *= 1000;
    t_x_y_theta[2] *= 1000;
  });
  ExpectFitRefused(1, {"millimetres", "ground-truth positions"});
}

TEST_F(InputClassesTest, LengthsInMillimetresAreNamedWithTheirLine) {
  SetRobotYaml(
      Replace(Replace(Replace(RobotYaml(), "wheel_separation_m: 0.2", "wheel_separation_m: 200"),
                      "radius_m: [0.038, 0.046]", "radius_m: [38, 46]"),
              "wheel_separation_m: [0.18, 0.22]", "wheel_separation_m: [180, 220]"));
  ExpectFitRefused(1, {"robot.yaml:6:", "wheel_separation_m = 200", "millimetres"});
}

TEST_F(InputClassesTest, AMisspeltKeyIsNamedOnItsOwnLine) {
  SetRobotYaml(Replace(RobotYaml(), "wheel_separation_m: 0.2", "wheel_separaton_m: 0.2"));
  ExpectFitRefused(1, {"robot.yaml:6:", "wheel_separaton_m", "misspelt 'wheel_separation_m'"});
}

TEST_F(InputClassesTest, EmptyOrControlCharacterNamesAreRefused) {
  const std::string original = RobotYaml();
  SetRobotYaml(Replace(original, "name: example_diff_drive", "name: \"\""));
  ExpectFitRefused(1, {"robot.yaml:2:", "name is empty"});
  SetRobotYaml(Replace(original, "name: example_diff_drive", "name: \"a\\tb\""));
  ExpectFitRefused(1, {"robot.yaml:2:", "control character"});
}

TEST_F(InputClassesTest, NegativeRepetitionNumbersAreRefused) {
  const std::string yaml = ReadFileBytes(data_ / "dataset.yaml");
  WriteFileBytes(data_ / "dataset.yaml", Replace(yaml, "repetition: 1,", "repetition: -1,"));
  ExpectFitRefused(1, {"dataset.yaml:3:", "repetition -1 is negative"});
}

TEST_F(InputClassesTest, AStartHeadingInDegreesIsRefused) {
  const std::string yaml = ReadFileBytes(data_ / "dataset.yaml");
  WriteFileBytes(
      data_ / "dataset.yaml",
      Replace(yaml, "repetition: 1, encoders", "repetition: 1, start_pose: [0, 0, 90], encoders"));
  ExpectFitRefused(1, {"dataset.yaml:3:", "start_pose theta 90", "degrees?"});
}

// Cumulative 16-bit tick counts that pass 65535 inside a run.
TEST_F(InputClassesTest, ATickCounterThatWrapsIsRefusedAtItsLine) {
  SetRobotYaml(RobotYaml() + "encoder: {ticks_per_rev: 4096, cumulative: true}\n");
  for (const auto& e : fs::directory_iterator(data_ / "runs")) {
    if (!Has(e.path().filename().string(), "_encoders.csv")) continue;
    std::istringstream in(ReadFileBytes(e.path()));
    std::string line, out = "t,ticks_right,ticks_left\n";
    std::getline(in, line);
    double count[2] = {65000.0, 65000.0}, previous_t = 0.0;
    bool first = true;
    while (std::getline(in, line)) {
      double t = 0, w[2] = {0, 0};
      if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &w[0], &w[1]) != 3) continue;
      for (int k = 0; k < 2 && !first; ++k) count[k] += w[k] * (t - previous_t) * 4096 / (2 * M_PI);
      first = false;
      previous_t = t;
      char row[128];
      std::snprintf(row, sizeof row, "%.6f,%.0f,%.0f\n", t, std::fmod(std::round(count[0]), 65536),
                    std::fmod(std::round(count[1]), 65536));
      out += row;
    }
    WriteFileBytes(e.path(), out);
  }
  ExpectFitRefused(1, {"_encoders.csv:", "2^16", "wraps inside the run"});
}

TEST(InputClassesCli, ASteeringAngleInDegreesIsRefused) {
  const TempDir dir;
  const fs::path data = dir.path() / "tri";
  ASSERT_EQ(
      RunFitcal(dir, "simulate --model tricycle --repetitions 2 --out " + data.string()).exit_code,
      0);
  EditRows(data, "_encoders.csv",
           [](std::vector<double>& t_w_steering) { t_w_steering[2] *= 180.0 / M_PI; });
  const auto r = RunFitcal(dir, "fit --logs " + data.string() + " --no-output");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "_encoders.csv:") && Has(r.err, "steering")) << r.err;
}

TEST(InputClassesCli, RobotAnglesInRadiansNameTheFileAndKey) {
  const TempDir dir;
  const std::string robot = dir.Write("omni.yaml", R"(model: omni
name: radians
wheels:
  - {name: a, distance_m: 0.2, angle_deg: 1.0472, radius_m: 0.05, drive_angle_deg: 90, roller_angle_deg: 0}
  - {name: b, distance_m: 0.2, angle_deg: 3.1416, radius_m: 0.05, drive_angle_deg: 90, roller_angle_deg: 0}
  - {name: c, distance_m: 0.2, angle_deg: 5.2360, radius_m: 0.05, drive_angle_deg: 90, roller_angle_deg: 0}
bounds: {distance_m: [0.18, 0.22], radius_m: [0.045, 0.055], angle_offset_deg: [-2, 2]}
)");
  const auto r =
      RunFitcal(dir, "simulate --model omni --robot " + robot + " --out " + dir.Path("data"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "omni.yaml:4:") && Has(r.err, "angle_deg") && Has(r.err, "radians"))
      << r.err;
}

// An error line cuts what it echoes, not fitcal's own sentence: an angle glitch's message with
// its hint (~400 characters) was cut mid-word at 300. A field a megabyte long is still cut.
TEST(InputClassesCli, AnErrorLineKeepsItsOwnSentenceAndCutsWhatItEchoes) {
  const std::string sentence(450, 's');
  const std::string own = io::InputError(io::InputErrorKind::kBadValue, "f.csv", 3, sentence).what();
  EXPECT_EQ(own, "f.csv:3: " + sentence);
  const std::string echoed =
      io::InputError(io::InputErrorKind::kBadValue, "f.csv", 3, std::string(1 << 20, 'x')).what();
  EXPECT_LT(echoed.size(), 700u);
  EXPECT_NE(echoed.find("bytes]..."), std::string::npos);
}

TEST(InputClassesCli, UsageErrorsAreOneLineExitTwoBeforeAnyWork) {
  const TempDir dir;
  for (const std::string& args :
       {std::string("fit --logs . --threads abc"), std::string("fit --logs . --threads -2"),
        std::string("diagnose --logs . --threads 1.5"), std::string("fit --logs . --out ''"),
        std::string("report --logs . --calibration x --out ''"),
        std::string("diagnose --logs . --train-reps 1-2 --train-trajectories x"),
        std::string("fit --logs . --train-reps 1-2 --train-trajectories x"),
        std::string("generalise --logs . --train-reps 5-1"),
        std::string("fit --logs . --closed-form-only --train-reps 5-1"),
        std::string("fit --logs . --closed-form-only --method crs2lm"),
        // nan and inf pass CLI11's PositiveNumber: every floating-point flag refuses them
        std::string("fit --logs . --position-sigma-m nan"),
        std::string("fit --logs . --loss-scale inf"),
        std::string("diagnose --logs . --alpha nan"),
        std::string("simulate --out x --gt-position-sigma-m inf")}) {
    const auto r = RunFitcal(dir, args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_EQ(Lines(r.err), 1) << args << ": " << r.err;
    EXPECT_FALSE(Has(r.err, "could not be converted")) << r.err;
  }
}

// Each refusal names the flag that is wrong and why: one message for two flags left the user to
// guess, and a repetition list of a number too large to expand said it was no whole number.
TEST(InputClassesCli, EachFlagIsNamedWithWhatIsWrong) {
  const TempDir dir;
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"fit --logs . --max-evaluations 0", "--max-evaluations must be positive"},
           {"fit --logs . --loss huber --loss-scale -1", "--loss-scale must be positive"},
           {"fit --logs . --train-reps 1-2000000000",
            "2000000000 is beyond the last repetition"},
           // 1e-300 weighed a metre as 1e300: the solve failed, its tables printed nan, and
           // UMBmark was written, exit 0.
           {"fit --logs . --position-sigma-m 1e-300", "must be at least 1e-09 m"},
           {"compare --logs . --heading-sigma-deg 1e-300", "must be at least 1e-07 deg"},
           // fit's flags on the top level, before another subcommand, were read by nothing:
           // generalise ran on its default split, exit 0.
           {"--train-reps 1-3 generalise --logs .",
            "--train-reps is given before 'generalise': there it is fit's flag"},
           {"--residuals track export ros2-control --calibration /dev/null --controller y",
            "write it after 'export ros2-control'"}}) {
    const auto r = RunFitcal(dir, args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_TRUE(Has(r.err, says)) << args << ": " << r.err;
  }
}

// probe45: flags the command would drop. compare ran every fit without --seed (Ceres methods
// only), --loss (NLopt methods only), --polish or --max-iterations where no method asked for uses
// them, exit 0, where fit refuses the same flags; fit, compare and asoc-geometric (now
// fit --closed-form-only, which refuses a fit's flags beside it) with --no-output dropped an
// --out given beside it. Each: exit 2, one line naming the flag, before any data is read.
TEST(InputClassesCli, FlagsNoMethodAskedWouldUseAreRefused) {
  const TempDir dir;
  struct Case {
    std::string args, says;
  };
  const std::string compare = "compare --logs . --strategies all --repetitions 1 --quiet ";
  for (const Case& c : std::vector<Case>{
           {compare + "--methods ceres --seed 5", "--methods ceres does not use them"},
           {compare + "--methods ceres ceres-dogleg --polish", "apply to the NLopt methods"},
           {compare + "--methods crs2lm --loss huber", "--methods crs2lm does not use them"},
           {compare + "--methods crs2lm --max-iterations 5", "bounds the Ceres methods"},
           {compare + "--methods ceres --loss-scale 0.1", "--loss-scale without --loss"},
           {compare + "--methods ceres --no-output --out " + dir.Path("table"),
            "--out excludes --no-output"},
           {"fit --logs . --no-output --out " + dir.Path("cal.yaml"),
            "--out excludes --no-output"},
           {"fit --logs . --closed-form-only --effects pivot_yaw_gain",
            "--closed-form-only runs no fit, so it cannot take --effects"}}) {
    const auto r = RunFitcal(dir, c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << ": " << r.out << r.err;
    EXPECT_EQ(Lines(r.err), 1) << c.args << ": " << r.err;
    EXPECT_TRUE(Has(r.err, c.says)) << c.args << ": " << r.err;
  }
  for (const char* written : {"table.csv", "table.md", "cal.yaml"}) {
    EXPECT_FALSE(std::filesystem::exists(dir.Path(written))) << written;
  }
}

}  // namespace
}  // namespace fitcal
