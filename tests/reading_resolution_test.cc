// The resolution of an angle channel's readings (odometry/reading_resolution.h): seen in the
// readings, kept by the loader, and added to the fit's sigmas (calibrate/
// reading_resolution_uncertainty.h) - checked against values known without fitcal: the grid the
// test itself put the readings on, and a tricycle's kinematics, in which a constant error of the
// steering reading is exactly a change of the steering offset.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "io/log_files.h"
#include "models/model_registry.h"
#include "models/tricycle/tricycle_model.h"
#include "odometry/reading_resolution.h"
#include "tests/test_files.h"

namespace fitcal {
namespace reading_resolution_test {
namespace {

using testing::RunFitcal;
using testing::TempDir;

// Readings of an angle swept back and forth over +-0.3 rad, on the grid phase + k step.
std::vector<double> SweptReadings(double step, double phase, int n) {
  std::vector<double> readings;
  for (int i = 0; i < n; ++i) {
    const double angle = 0.3 * std::sin(0.01 * i);
    readings.push_back(phase + step * std::round((angle - phase) / step));
  }
  return readings;
}

ReadingResolution ResolutionOf(const std::vector<double>& readings) {
  ReadingGrid grid;
  for (double r : readings) grid.Add(r);
  return grid.Resolution();
}

double StepOf(const std::vector<double>& readings) { return ResolutionOf(readings).step_rad; }

TEST(ReadingGrid, FindsTheEncodersCountWhateverItsZero) {
  const double step = 2.0 * M_PI / 4096.0;
  EXPECT_NEAR(StepOf(SweptReadings(step, 0.0, 20000)), step, 1e-12);
  EXPECT_NEAR(StepOf(SweptReadings(step, 0.37 * step, 20000)), step, 1e-12);
}

// The real tricycle's log (docs/everyday_driving.md): readings printed to 8 decimals and 14 of
// 69,480 off the grid (recorder glitches).
TEST(ReadingGrid, ToleratesPrintedDigitsAndAFewGlitches) {
  const double step = M_PI / 400.0;
  std::vector<double> readings = SweptReadings(step, 0.0, 20000);
  for (double& r : readings) r = std::round(r * 1e8) / 1e8;
  for (int i = 0; i < 100; i += 10) readings[i] = 0.24;  // 0.05 % glitches
  EXPECT_NEAR(StepOf(readings), step, 1e-8);
}

TEST(ReadingGrid, SeesNoGridInContinuousOrSetPointReadings) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-3);
  std::vector<double> noisy = SweptReadings(1e-9, 0.0, 20000);
  for (double& r : noisy) r += noise(rng);
  EXPECT_EQ(StepOf(noisy), 0.0);
  // Three set-points 10 deg apart, held: no 10 deg encoder.
  std::vector<double> set_points;
  for (int i = 0; i < 3000; ++i) set_points.push_back((i % 3 - 1) * 10.0 * M_PI / 180.0);
  EXPECT_EQ(StepOf(set_points), 0.0);
  // Too many glitches (2 %): not a grid either.
  std::vector<double> glitchy = SweptReadings(0.01, 0.0, 5000);
  for (int i = 0; i < 5000; i += 50) glitchy[static_cast<std::size_t>(i)] += 0.003;
  EXPECT_EQ(StepOf(glitchy), 0.0);
  EXPECT_EQ(StepOf({}), 0.0);
}

// Noise before the count (dither) makes a held angle flicker between counts (a, b, a); the rate
// measures the noise over the step. Drawn here: held angles anywhere in their count, Gaussian
// noise of 0.05, 0.15 and 0.3 counts, 20,000 readings each - the estimate within 15 % (its
// sampling spread is ~5 %), and the bias left by the noise exp(-2 pi^2 s^2) of the undithered.
TEST(ReadingGrid, TheFlickerOfHeldAnglesMeasuresTheNoiseOverTheStep) {
  const double step = 0.01;
  for (double s : {0.05, 0.15, 0.3}) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> where(-0.05, 0.05);  // ten counts, all visited
    std::normal_distribution<double> noise(0.0, s * step);
    std::vector<double> readings;
    for (int held = 0; held < 40; ++held) {
      const double angle = where(rng);
      for (int i = 0; i < 500; ++i) {
        readings.push_back(step * std::round((angle + noise(rng)) / step));
      }
    }
    const ReadingResolution r = ResolutionOf(readings);
    EXPECT_NEAR(r.step_rad, step, 1e-12) << s;
    EXPECT_NEAR(r.NoiseOverStep(), s, 0.15 * s);
    EXPECT_NEAR(r.BiasSigma(), step / std::sqrt(12.0) * std::exp(-2.0 * M_PI * M_PI * s * s),
                0.2 * step / std::sqrt(12.0));
  }
}

// The loader keeps the step of a tricycle's steering: read on the grid of the readings in rad,
// and the count of an absolute encoder when the log holds counts; the wheel-rate channel none.
TEST(ReadingGrid, TheLoaderKeepsEachAngleChannelsStep) {
  TempDir dir;
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kTricycleExampleYaml), "robot.yaml");
  const double step = 2.0 * M_PI / 1024.0;
  std::ostringstream csv;
  csv.precision(17);
  csv << "t,w_traction,steering\n";
  const std::vector<double> readings = SweptReadings(step, 0.0, 2000);
  for (std::size_t i = 0; i < readings.size(); ++i) {
    csv << 0.01 * static_cast<double>(i) << ",10," << readings[i] << "\n";
  }
  const EncoderLog log = io::ReadEncoderCsv(dir.Write("e.csv", csv.str()), model->robot());
  ASSERT_EQ(log.reading_resolution.size(), 2u);
  EXPECT_EQ(log.reading_resolution[0].step_rad, 0.0);
  EXPECT_NEAR(log.reading_resolution[1].step_rad, step, 1e-12);
  EXPECT_EQ(log.reading_resolution[1].NoiseOverStep(), 0.0);  // a noiseless sweep

  const RobotModelPtr counted_model = ReadRobotModel(
      YAML::Load(std::string(kTricycleExampleYaml) +
                 "steering_encoder: {ticks_per_rev: 4096, zero_tick: 2048}\n"),
      "robot.yaml");
  const Robot& counted = counted_model->robot();
  std::ostringstream counts;
  counts << "t,w_traction,ticks_steering\n";
  for (int i = 0; i < 50; ++i) counts << 0.01 * i << ",10," << 2048 + (i % 3) << "\n";
  const EncoderLog counted_log = io::ReadEncoderCsv(dir.Write("c.csv", counts.str()), counted);
  EXPECT_NEAR(counted_log.reading_resolution[1].step_rad, 2.0 * M_PI / 4096.0, 1e-15);
  // 2048, 2049, 2050, 2048, ...: no reading returns to the one two back after a change.
  EXPECT_EQ(counted_log.reading_resolution[1].NoiseOverStep(), 0.0);
}

// Rewrites every encoder CSV's `steering` column of a data set onto the grid k * step.
void QuantiseSteering(const std::string& dataset, double step) {
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dataset)) {
    const std::string path = entry.path().string();
    if (path.find("encoders") == std::string::npos || entry.path().extension() != ".csv") continue;
    std::ifstream in(path);
    std::string header, line;
    std::getline(in, header);
    std::stringstream cols(header);
    std::string name;
    int steering_col = -1;
    for (int i = 0; std::getline(cols, name, ','); ++i) {
      if (name == "steering") steering_col = i;
    }
    ASSERT_GE(steering_col, 0) << path;
    std::ostringstream out;
    out.precision(17);
    out << header << "\n";
    while (std::getline(in, line)) {
      std::stringstream fields(line);
      std::string field;
      for (int i = 0; std::getline(fields, field, ','); ++i) {
        if (i > 0) out << ",";
        if (i == steering_col) {
          out << step * std::round(std::stod(field) / step);
        } else {
          out << field;
        }
      }
      out << "\n";
    }
    in.close();
    std::ofstream(path, std::ios::trunc) << out.str();
  }
}

// "steering_offset 0.0335 -> 0.134 deg" in the resolution line: the two sigmas.
bool OffsetSigmas(const std::string& out, double* before, double* after) {
  const std::size_t at = out.find("resolution: channel 'steering'");
  if (at == std::string::npos) return false;
  const std::size_t name = out.find("steering_offset ", at);
  return name != std::string::npos &&
         std::sscanf(out.c_str() + name, "steering_offset %lf -> %lf deg", before, after) == 2;
}

// A tricycle whose steering reads in counts of 2 pi / 1024 (0.35 deg), without noise: the fit's
// sigma of the offset gains exactly the count's uniform sigma, count / sqrt(12) - the kinematics
// turn the wheel by reading + offset, so a constant error of the reading is absorbed by the offset
// alone; the refit must say so to 1 % (its convergence). The truth lies within 3 sigmas. Without
// the counts (continuous readings) nothing is added.
TEST(ReadingResolutionUncertainty, ACoarseSteeringEncoderWidensTheOffsetsSigmaByItsCount) {
  TempDir dir;
  const std::string data = dir.Path("data"), cal = dir.Path("cal.yaml");
  ASSERT_EQ(RunFitcal(dir, "simulate --model tricycle --repetitions 3 --seed 4 --angle-sigma-deg 0 "
                          "--out " + data)
                .exit_code,
            0);
  testing::FitcalRun plain = RunFitcal(dir, "fit --logs " + data + " --train-reps 1-2 --no-output");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.out.find("resolution:"), std::string::npos) << plain.out;

  const double step = 2.0 * M_PI / 1024.0;
  QuantiseSteering(data, step);
  const testing::FitcalRun r =
      RunFitcal(dir, "fit --logs " + data + " --train-reps 1-2 --out " + cal);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  double before_deg = 0.0, after_deg = 0.0;
  ASSERT_TRUE(OffsetSigmas(r.out, &before_deg, &after_deg)) << r.out;
  const double count_sigma_deg = step / std::sqrt(12.0) * 180.0 / M_PI;
  EXPECT_NEAR(after_deg * after_deg - before_deg * before_deg, count_sigma_deg * count_sigma_deg,
              0.02 * count_sigma_deg * count_sigma_deg);  // 1 % on each printed 3-digit sigma

  const YAML::Node block = YAML::LoadFile(cal)["calibration"];
  const double written_deg = block["sigma"]["steering_offset_deg"].as<double>();
  EXPECT_NEAR(written_deg, after_deg, 0.005 * after_deg);  // printed to 3 digits
  const double truth = ReadRobotModelFile(data + "/true_robot.yaml")->robot().nominal[2];
  const double fitted = ReadRobotModelFile(cal)->robot().nominal[2];
  EXPECT_LT(std::abs(fitted - truth) * 180.0 / M_PI, 3.0 * written_deg);

  // diagnose's calibration holds the count too (it wrote the fit's own 0.012 deg, 9x below fit's
  // 0.13 on the OptiOdom tricycle): the same line, and the variance grown by count^2 / 12 to 1 %.
  const testing::FitcalRun d =
      RunFitcal(dir, "diagnose --logs " + data + " --train-reps 1-2 --out " + dir.Path("d"));
  ASSERT_EQ(d.exit_code, 0) << d.err << d.out;
  ASSERT_TRUE(OffsetSigmas(d.out, &before_deg, &after_deg)) << d.out;
  EXPECT_NEAR(after_deg * after_deg - before_deg * before_deg, count_sigma_deg * count_sigma_deg,
              0.02 * count_sigma_deg * count_sigma_deg);
  const double diagnosed_deg = YAML::LoadFile(dir.Path("d/calibrated.yaml"))["calibration"]
                                   ["sigma"]["steering_offset_deg"].as<double>();
  EXPECT_NEAR(diagnosed_deg, after_deg, 0.005 * after_deg);
}

// The simulator's default steering noise, 0.1 deg before the same count (0.28 of a step), dithers
// the readings, and the bias it leaves is exp(-2 pi^2 0.28^2) = 0.21 of the undithered one. The
// flicker is measured on the runs whose grid shows (the squares; a circle's few held readings show
// none), which hold mostly the straight-ahead angle near its count's centre and flicker less than
// held angles spread over their counts: it reads 0.15 of a step, and the offset's variance gains
// 0.41 of count^2 / 12 - wide, but less than the undithered 1 (the test's bound 0.6).
TEST(ReadingResolutionUncertainty, NoiseBeforeTheCountLeavesLessOfItsBias) {
  TempDir dir;
  const std::string data = dir.Path("data");
  ASSERT_EQ(RunFitcal(dir, "simulate --model tricycle --repetitions 3 --seed 4 --out " + data)
                .exit_code,
            0);
  const double step = 2.0 * M_PI / 1024.0;
  QuantiseSteering(data, step);
  const testing::FitcalRun r =
      RunFitcal(dir, "fit --logs " + data + " --train-reps 1-2 --no-output");
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("its noise, 0.1"), std::string::npos) << r.out;  // 0.1x of a step
  double before_deg = 0.0, after_deg = 0.0;
  ASSERT_TRUE(OffsetSigmas(r.out, &before_deg, &after_deg)) << r.out;
  const double count_variance = std::pow(step / std::sqrt(12.0) * 180.0 / M_PI, 2);
  EXPECT_GT(after_deg * after_deg - before_deg * before_deg, 0.0);
  EXPECT_LT(after_deg * after_deg - before_deg * before_deg, 0.6 * count_variance);
}

}  // namespace
}  // namespace reading_resolution_test
}  // namespace fitcal
