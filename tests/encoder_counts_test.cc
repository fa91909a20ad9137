// Encoder counts as recorders write them (io/log_files.h): counters of a declared width
// (`encoder: {..., counter_bits: 16|32}`) unwrapped, running totals and per-interval counts; an
// angle channel read as counts of an absolute encoder (`steering_encoder: {ticks_per_rev,
// zero_tick}`, column `ticks_steering`); counter glitches named, bridged and counted. Expected
// values are computed here from the counts by hand, not by the loader; the command-line test
// fits a simulated tricycle from its counts and from its rates and compares the two.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/input_error.h"
#include "io/log_files.h"
#include "io/warnings.h"
#include "models/model_registry.h"
#include "models/tricycle/tricycle_model.h"
#include "tests/recorded_counts.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

using testing::Glitches;
using testing::Has;
using testing::RunFitcal;
using testing::TempDir;
using testing::WriteFileBytes;

constexpr const char* kTricycle =
    "model: tricycle\nname: t\ntraction_wheel: {radius_m: 0.0325}\nwheelbase_m: 0.15\n"
    "steering_offset_deg: 0.0\nbounds: {radius_m: [0.030, 0.035], wheelbase_m: [0.13, 0.17], "
    "steering_offset_deg: [-10.0, 10.0]}\n";

Robot RobotWith(const std::string& extra) {
  return ReadRobotModel(YAML::Load(std::string(kTricycle) + extra), "robot.yaml")->robot();
}

EncoderLog Load(const Robot& robot, const std::string& csv) {
  TempDir dir;
  WriteFileBytes(dir.Path("enc.csv"), csv);
  return io::ReadEncoderCsv(dir.Path("enc.csv"), robot);
}

std::string ErrorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "accepted";
}

// The loader's warnings, captured for one scope.
struct CapturedWarnings {
  std::vector<std::string> lines;
  CapturedWarnings() {
    io::SetWarningSinkForTests([this](const std::string& line) { lines.push_back(line); });
  }
  ~CapturedWarnings() { io::SetWarningSinkForTests(nullptr); }
};

constexpr double kTicksPerRev = 4096.0;
double Rate(double ticks, double dt) { return 2.0 * M_PI * ticks / (kTicksPerRev * dt); }

// A 16-bit running total passing 65535: 65530 -> 4 is 10 counts forward.
TEST(EncoderCounts, SixteenBitRunningTotalsAreUnwrapped) {
  const Robot robot =
      RobotWith("encoder: {ticks_per_rev: 4096, cumulative: true, counter_bits: 16}\n");
  const EncoderLog log = Load(robot,
                              "t,ticks_traction,steering\n0.0,65520,0.1\n0.1,65530,0.1\n"
                              "0.2,4,0.1\n0.3,14,0.1\n");
  ASSERT_EQ(log.samples.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(log.samples[k].value[0], Rate(10, 0.1), 1e-9);
  EXPECT_EQ(log.dropped_glitches, 0);
}

// 32-bit per-interval counts: a backwards interval of -5 recorded unsigned as 2^32 - 5.
TEST(EncoderCounts, ThirtyTwoBitNegativeIncrementsAreSigned) {
  const Robot robot =
      RobotWith("encoder: {ticks_per_rev: 4096, cumulative: false, counter_bits: 32}\n");
  const EncoderLog log =
      Load(robot, "t,ticks_traction,steering\n0.0,0,0.0\n0.1,7,0.0\n0.2,4294967291,0.0\n");
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_NEAR(log.samples[0].value[0], Rate(7, 0.1), 1e-9);
  EXPECT_NEAR(log.samples[1].value[0], Rate(-5, 0.1), 1e-9);
}

// Without the width the wrap is refused as before, with its line, and the message says how to
// declare it.
TEST(EncoderCounts, AnUndeclaredWidthStillRefusesTheWrap) {
  const Robot robot = RobotWith("encoder: {ticks_per_rev: 4096, cumulative: true}\n");
  std::string csv = "t,ticks_traction,steering\n";
  for (int k = 0; k < 10; ++k) {
    csv += std::to_string(0.1 * k) + "," + std::to_string((65500 + 10 * k) % 65536) + ",0.1\n";
  }
  const std::string error = ErrorOf([&] { Load(robot, csv); });
  EXPECT_TRUE(Has(error, "enc.csv:6: ")) << error;  // 65540 -> 4 is the row of t = 0.4
  EXPECT_TRUE(Has(error, "counter_bits: 16")) << error;
}

// A 16-bit counter declared as 32 bits: unwrapped modulo 2^32, each of its wraps is a jump of
// -2^16 + 10 ticks, which the glitch screen would bridge (dropping real travel, one warning per
// wrap). Refused at the wrap's line with the width to declare; a flipped bit of a running total
// (a jump of 2^b and back) stays a glitch (ATornRunningTotalIsBridgedWithItsTravelKept).
TEST(EncoderCounts, ANarrowerCounterThanDeclaredIsRefusedAtItsWrap) {
  const Robot robot =
      RobotWith("encoder: {ticks_per_rev: 4096, cumulative: true, counter_bits: 32}\n");
  std::string csv = "t,ticks_traction,steering\n";
  for (int k = 0; k < 20; ++k) {
    csv += std::to_string(0.1 * k) + "," + std::to_string((65500 + 10 * k) % 65536) + ",0.1\n";
  }
  const std::string error = ErrorOf([&] { Load(robot, csv); });
  EXPECT_TRUE(Has(error, "enc.csv:6: ")) << error;  // 65540 -> 4 is the row of t = 0.4
  EXPECT_TRUE(Has(error, "16-bit counter")) << error;
  EXPECT_TRUE(Has(error, "counter_bits: 16")) << error;
}

TEST(EncoderCounts, CounterBitsOtherThanSixteenOrThirtyTwoAreRefused) {
  const std::string error = ErrorOf(
      [] { RobotWith("encoder: {ticks_per_rev: 4096, cumulative: true, counter_bits: 12}\n"); });
  EXPECT_TRUE(Has(error, "robot.yaml:7")) << error;
  EXPECT_TRUE(Has(error, "16 or 32")) << error;
}

// angle = 2 pi (count - zero_tick) / ticks_per_rev in (-pi, pi]; an interval's value is the
// mean of its two readings, across the +-pi seam the short way.
TEST(EncoderCounts, SteeringCountsOfAnAbsoluteEncoderBecomeAngles) {
  const Robot robot = RobotWith("steering_encoder: {ticks_per_rev: 8192, zero_tick: 100}\n");
  EXPECT_EQ(robot.channels[1].ticks_column, "ticks_steering");
  // Readings: 0, +pi/4 (zero + 1024), +pi/2 (zero + 2048), then 179 deg and -179 deg (the
  // encoder's count passing its own wrap: 100 + 4073.2 ~ 179.0 deg, then 8192 + 200 - that).
  const double c179 = 100 + 8192.0 * 179.0 / 360.0;
  const EncoderLog log =
      Load(robot,
           "t,w_traction,ticks_steering\n0.0,1,100\n0.1,1,1124\n"
           "0.2,1,2148\n0.3,1," +
               std::to_string(c179) + "\n0.4,1," + std::to_string(8192 + 200 - c179) + "\n");
  ASSERT_EQ(log.samples.size(), 4u);
  EXPECT_NEAR(log.samples[0].value[1], M_PI / 8, 1e-12);
  EXPECT_NEAR(log.samples[1].value[1], 3 * M_PI / 8, 1e-12);
  EXPECT_NEAR(std::abs(log.samples[3].value[1]), M_PI, 1e-9);  // mean of 179 and -179 deg
  // The block survives the calibrated YAML.
  const RobotModelPtr model = ReadRobotModel(
      YAML::Load(std::string(kTricycle) +
                 "encoder: {ticks_per_rev: 4096, cumulative: true, counter_bits: 32}\n"
                 "steering_encoder: {ticks_per_rev: 8192, zero_tick: 100}\n"),
      "robot.yaml");
  const Robot back =
      ReadRobotModel(YAML::Load(model->RobotYaml(model->robot().nominal, "")), "again.yaml")
          ->robot();
  ASSERT_EQ(back.angle_encoders.size(), 1u);
  EXPECT_EQ(back.angle_encoders[0].ticks_per_rev, 8192.0);
  EXPECT_EQ(back.angle_encoders[0].zero_tick, 100.0);
  ASSERT_TRUE(back.encoder.has_value());
  EXPECT_EQ(back.encoder->counter_bits, 32);
}

TEST(EncoderCounts, AngleOfCountWrapsToMinusPiExclusive) {
  const AngleEncoder e{"steering", 8192.0, 0.0};
  EXPECT_DOUBLE_EQ(io::AngleOfCount(e, 4096), M_PI);
  EXPECT_DOUBLE_EQ(io::AngleOfCount(e, -4096), M_PI);
  EXPECT_NEAR(io::AngleOfCount(e, 8192 + 10), 2 * M_PI * 10 / 8192, 1e-12);
  EXPECT_NEAR(io::AngleOfCount(e, -10), -2 * M_PI * 10 / 8192, 1e-12);
}

// A ticks_steering column without its block is refused in words that say what to declare.
TEST(EncoderCounts, SteeringCountsWithoutTheirBlockAreRefused) {
  const Robot robot = RobotWith("");
  const std::string error =
      ErrorOf([&] { Load(robot, "t,w_traction,ticks_steering\n0.0,1,100\n0.1,1,1124\n"); });
  EXPECT_TRUE(Has(error, "enc.csv:1: ")) << error;
  EXPECT_TRUE(Has(error, "steering_encoder: {ticks_per_rev: N, zero_tick: Z}")) << error;
}

// 40 rows of a wheel counting `forward` ticks per 10 ms interval, as running totals from `start`
// (modulo 2^32) or per interval; `edit` changes the counts before they are written.
std::string TractionCsv(bool cumulative, double forward,
                        const std::function<void(std::vector<double>*)>& edit) {
  std::vector<double> counts(40);
  for (std::size_t k = 0; k < counts.size(); ++k) {
    counts[k] = cumulative ? std::fmod(4294967000.0 + forward * k, 4294967296.0) : forward;
  }
  edit(&counts);
  std::ostringstream csv;
  csv.precision(12);
  csv << "t,ticks_traction,steering\n";
  for (std::size_t k = 0; k < counts.size(); ++k) csv << 0.01 * k << "," << counts[k] << ",0\n";
  return csv.str();
}

// The same counts without the width: -5 recorded as 2^16 - 5 in a 40-row log going backwards
// now and then. Refused at its line in one message that names the cause and the width to
// declare, where each such interval was warned as a glitch (97 lines) before the share refused.
TEST(EncoderCounts, UnsignedNegativeIncrementsOfAnUndeclaredWidthAreNamedOnce) {
  const Robot robot = RobotWith("encoder: {ticks_per_rev: 4096, cumulative: false}\n");
  CapturedWarnings warnings;
  const std::string error = ErrorOf([&] {
    Load(robot, TractionCsv(false, 10, [](std::vector<double>* c) { (*c)[20] = 65531; }));
  });
  EXPECT_TRUE(Has(error, "enc.csv:22: channel 'traction' counts 65531 ticks")) << error;
  EXPECT_TRUE(Has(error, "negative count stored as an unsigned 16-bit number")) << error;
  EXPECT_TRUE(Has(error, "counter_bits: 16")) << error;
  EXPECT_TRUE(warnings.lines.empty());
}

// A running total torn for one row (row 20 on line 22 reads 0x5A5A5A5A): its two intervals move
// 10^9 ticks each way, a rim speed far beyond 20 m/s; the reading is dropped, the two intervals
// bridged with their sum (20 ticks over 0.02 s: exact), the line named and counted.
TEST(EncoderCounts, ATornRunningTotalIsBridgedWithItsTravelKept) {
  const Robot robot =
      RobotWith("encoder: {ticks_per_rev: 4096, cumulative: true, counter_bits: 32}\n");
  CapturedWarnings warnings;
  const EncoderLog log =
      Load(robot, TractionCsv(true, 10, [](std::vector<double>* c) { (*c)[20] = 0x5A5A5A5A; }));
  EXPECT_EQ(log.dropped_glitches, 1);
  ASSERT_EQ(warnings.lines.size(), 1u);
  EXPECT_TRUE(Has(warnings.lines[0], "enc.csv:22: counter glitch")) << warnings.lines[0];
  EXPECT_TRUE(Has(warnings.lines[0], "20 m/s")) << warnings.lines[0];
  for (std::size_t k = 0; k < log.samples.size(); ++k) {
    EXPECT_NEAR(log.samples[k].value[0], Rate(10, 0.01), 1e-6) << k;
  }
}

// The glitch: a zero increment (row 20 repeats row 19), then a large backwards jump
// (row 21 reads 400 ticks short) of a counter that then goes on. Interval 20 -> 21 runs 380 ticks
// backwards inside forward motion: named (line 23), and row 21's reading dropped: the two
// intervals it bounds get their mean, (-380 + 410) / 2 = 15 ticks each, so rows 19 -> 22 still
// travel 30 ticks (the stale row's 10 reappear after it).
TEST(EncoderCounts, AStaleThenBackwardsReadingIsNamedAndBridged) {
  const Robot robot =
      RobotWith("encoder: {ticks_per_rev: 4096, cumulative: true, counter_bits: 32}\n");
  CapturedWarnings warnings;
  const EncoderLog log = Load(robot, TractionCsv(true, 10, [](std::vector<double>* c) {
                                (*c)[20] = (*c)[19];
                                (*c)[21] -= 400;
                              }));
  EXPECT_EQ(log.dropped_glitches, 1);
  ASSERT_EQ(warnings.lines.size(), 1u);
  EXPECT_TRUE(Has(warnings.lines[0], "enc.csv:23: counter glitch")) << warnings.lines[0];
  EXPECT_TRUE(Has(warnings.lines[0], "backwards")) << warnings.lines[0];
  EXPECT_NEAR(log.samples[19].value[0], 0.0, 1e-9);  // the stale interval, not a glitch
  EXPECT_NEAR(log.samples[20].value[0], Rate(15, 0.01), 1e-6);
  EXPECT_NEAR(log.samples[21].value[0], Rate(15, 0.01), 1e-6);
}

// Per-interval counts: one interval reads -50 while its neighbours count +10; it takes the rate
// around it (10 ticks), and a real reversal (a wheel slowing through zero) is not a glitch.
TEST(EncoderCounts, ABackwardsIntervalCountIsReplacedAndAReversalIsNot) {
  const Robot robot =
      RobotWith("encoder: {ticks_per_rev: 4096, cumulative: false, counter_bits: 16}\n");
  {
    CapturedWarnings warnings;
    const EncoderLog log =
        Load(robot, TractionCsv(false, 10, [](std::vector<double>* c) { (*c)[15] = 65536 - 50; }));
    EXPECT_EQ(log.dropped_glitches, 1);
    ASSERT_EQ(warnings.lines.size(), 1u);
    EXPECT_TRUE(Has(warnings.lines[0], "enc.csv:17: counter glitch")) << warnings.lines[0];
    EXPECT_NEAR(log.samples[14].value[0], Rate(10, 0.01), 1e-9);
  }
  CapturedWarnings warnings;
  const EncoderLog log = Load(robot, TractionCsv(false, 0, [](std::vector<double>* c) {
                                for (std::size_t k = 0; k < c->size(); ++k) {
                                  const double v = 20.0 - static_cast<double>(k);
                                  (*c)[k] = v < 0 ? 65536 + v : v;
                                }
                              }));
  EXPECT_EQ(log.dropped_glitches, 0);
  EXPECT_TRUE(warnings.lines.empty());
}

// A counter that glitches in more than 1 % of its intervals is a wrong encoder block: refused.
TEST(EncoderCounts, ManyGlitchesAreAWrongEncoderBlock) {
  const Robot robot =
      RobotWith("encoder: {ticks_per_rev: 4096, cumulative: false, counter_bits: 32}\n");
  const std::string error = ErrorOf([&] {
    Load(robot, TractionCsv(false, 10, [](std::vector<double>* c) { (*c)[10] = (*c)[25] = 1e8; }));
  });
  EXPECT_TRUE(Has(error, "enc.csv:12: 2 of 39 intervals are counter glitches")) << error;
}

// A tricycle's steering log at 100 Hz (rates, radians): the steering ramps by 1 mrad a row,
// `edit` changes it.
std::string SteeringCsv(const std::function<void(std::vector<double>*)>& edit) {
  std::vector<double> steering;
  for (int k = 0; k < 40; ++k) steering.push_back(0.2 + 0.001 * k);
  edit(&steering);
  std::ostringstream csv;
  csv.precision(12);
  csv << "t,w_traction,steering\n";
  for (std::size_t k = 0; k < steering.size(); ++k)
    csv << 0.01 * k << ",5.0," << steering[k] << "\n";
  return csv.str();
}

// One steering reading of 4 rad among a slow ramp (row 20, line 22): the two intervals it bounds
// are each half-way to it. Named, counted, and both intervals take the angle between their outer
// neighbours, which on a ramp is the true reading 0.22 rad exactly (the mean of rows 18, 19, 21,
// 22).
TEST(AngleGlitches, OneWrongSteeringReadingIsNamedAndBridged) {
  CapturedWarnings warnings;
  const EncoderLog log =
      Load(RobotWith(""), SteeringCsv([](std::vector<double>* a) { (*a)[20] = 4.0; }));
  EXPECT_EQ(log.dropped_glitches, 1);
  ASSERT_EQ(warnings.lines.size(), 1u);
  EXPECT_TRUE(Has(warnings.lines[0], "enc.csv:22: angle glitch: channel 'steering'"))
      << warnings.lines[0];
  EXPECT_NEAR(log.samples[19].value[1], 0.22, 1e-12);
  EXPECT_NEAR(log.samples[20].value[1], 0.22, 1e-12);
  EXPECT_NEAR(log.samples[21].value[1], 0.2215, 1e-12);  // untouched
}

// What a steering or castor does: a step that stays (1 rad in one reading), an out-and-back of
// 0.15 rad (under the 0.2 rad that 20 rad/s makes of 10 ms), and a castor swinging across +-pi
// (3.13, -3.13: 0.02 rad apart the short way) are readings, not glitches.
TEST(AngleGlitches, AStepASmallBlipAndTheSeamAreNotGlitches) {
  const std::vector<std::function<void(std::vector<double>*)>> edits = {
      [](std::vector<double>* a) {
        for (std::size_t k = 20; k < a->size(); ++k) (*a)[k] = 1.2;
      },
      [](std::vector<double>* a) { (*a)[20] += 0.15; },
      [](std::vector<double>* a) {
        for (std::size_t k = 0; k < a->size(); ++k) (*a)[k] = k % 2 == 0 ? 3.13 : -3.13;
      }};
  for (std::size_t i = 0; i < edits.size(); ++i) {
    CapturedWarnings warnings;
    const EncoderLog log = Load(RobotWith(""), SteeringCsv(edits[i]));
    EXPECT_EQ(log.dropped_glitches, 0) << i;
    EXPECT_TRUE(warnings.lines.empty()) << i << ": " << warnings.lines.front();
  }
}

// ---- through the command line --------------------------------------------------------------

std::map<std::string, double> FittedValues(const std::string& calibrated, YAML::Node* sigma) {
  const Robot robot = ReadRobotModelFile(calibrated)->robot();
  *sigma = YAML::LoadFile(calibrated)["calibration"]["sigma"];
  std::map<std::string, double> out;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    out[robot.parameters[k].KeyName()] = robot.nominal[k] * robot.parameters[k].DisplayScale();
  }
  return out;
}

// A simulated tricycle (simulate's default noise: ground truth 2 mm and 0.2 deg, encoder rates
// 0.02 rad/s, steering 0.1 deg) fitted from its rates, then from the same recording as counts: a
// 32-bit running total that wraps, steering counts of an absolute encoder, three glitches. The
// two recordings differ only by the steering's quantisation (0.044 deg a count, 0.013 deg rms,
// under the 0.1 deg noise) and the three bridged intervals, so the calibrations must agree well
// within one sigma of the fit (the noise's effect on it): 0.3 sigma.
TEST(EncoderCountsCli, AWrappedGlitchedCounterCalibratesAsTheCleanRecording) {
  TempDir dir;
  std::string truth = kTricycleExampleYaml;
  truth.replace(truth.find("wheelbase_m: 0.15"), 17, "wheelbase_m: 0.155");
  WriteFileBytes(dir.Path("nominal.yaml"), kTricycleExampleYaml);
  WriteFileBytes(dir.Path("truth.yaml"), truth);
  const std::string clean = dir.Path("clean"), counts = dir.Path("counts");
  auto r =
      RunFitcal(dir, "simulate --model tricycle --robot " + dir.Path("nominal.yaml") + " --truth " +
                         dir.Path("truth.yaml") + " --out " + clean + " --seed 7 --repetitions 3");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::filesystem::copy(clean, counts, std::filesystem::copy_options::recursive);
  const YAML::Node index = YAML::LoadFile(clean + "/dataset.yaml");
  const std::string robot_file = index["robot"].as<std::string>();
  WriteFileBytes(counts + "/" + robot_file,
                 testing::ReadFileBytes(clean + "/" + robot_file) +
                     testing::kCountsEncoderYaml + "steering_encoder: {ticks_per_rev: 8192, zero_tick: 5000}\n");
  std::vector<std::string> expected_glitches;
  for (std::size_t i = 0; i < index["runs"].size(); ++i) {
    const std::string file = index["runs"][i]["encoders"].as<std::string>();
    Glitches glitches;
    WriteFileBytes(counts + "/" + file, testing::AsCounts(testing::ReadFileBytes(clean + "/" + file), {"steering"},
                                                 i == 1 ? &glitches : nullptr));
    for (int line : glitches.lines) {
      expected_glitches.push_back(counts + "/" + file + ":" + std::to_string(line) +
                                  ": counter glitch");
    }
  }
  ASSERT_EQ(expected_glitches.size(), 3u);

  const std::string fit_args = " --train-reps 1-2 --residuals final-pose --out ";
  r = RunFitcal(dir, "fit --logs " + clean + fit_args + dir.Path("clean.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_FALSE(Has(r.out, "encoder glitches")) << r.out;
  r = RunFitcal(dir, "fit --logs " + counts + fit_args + dir.Path("counts.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
  for (const std::string& g : expected_glitches) EXPECT_TRUE(Has(r.err, g)) << g << "\n" << r.err;
  EXPECT_TRUE(Has(r.out, "encoder glitches: 3 intervals in 1 run dropped from the fit")) << r.out;

  YAML::Node clean_sigma, counts_sigma;
  const auto from_rates = FittedValues(dir.Path("clean.yaml"), &clean_sigma);
  const auto from_counts = FittedValues(dir.Path("counts.yaml"), &counts_sigma);
  for (const auto& [key, value] : from_rates) {
    const double sigma = clean_sigma[key].as<double>();
    ASSERT_GT(sigma, 0.0) << key;
    std::printf("%-20s rates %.6f counts %.6f (%.2f sigma)\n", key.c_str(), value,
                from_counts.at(key), (from_counts.at(key) - value) / sigma);
    EXPECT_LT(std::abs(from_counts.at(key) - value), 0.3 * sigma) << key;
  }
  // The calibrated YAML keeps the encoder blocks (it loads the same recordings again).
  const Robot written = ReadRobotModelFile(dir.Path("counts.yaml"))->robot();
  ASSERT_TRUE(written.encoder.has_value());
  EXPECT_EQ(written.encoder->counter_bits, 32);
  ASSERT_EQ(written.angle_encoders.size(), 1u);
}

// The tricycle's steering gain is dimensionless (issue 39): `fit` prints it with unit 1, never
// [m], and the calibrated YAML keys its sigma by its name alone, as the robot YAML does.
TEST(SteeringGainCli, IsPrintedAndWrittenAsADimensionlessRatio) {
  TempDir dir;
  const std::string gain = std::string(kTricycleExampleYaml) + "steering_gain: 1.0\n";
  std::string truth = gain;
  truth.replace(truth.find("steering_gain: 1.0"), 18, "steering_gain: 0.9");
  WriteFileBytes(dir.Path("nominal.yaml"), gain);
  WriteFileBytes(dir.Path("truth.yaml"), truth);
  auto r = RunFitcal(dir, "simulate --model tricycle --robot " + dir.Path("nominal.yaml") +
                              " --truth " + dir.Path("truth.yaml") + " --out " + dir.Path("data") +
                              " --seed 3 --repetitions 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunFitcal(dir, "fit --logs " + dir.Path("data") + " --train-reps 1 --residuals final-pose" +
                         " --out " + dir.Path("cal.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_TRUE(Has(r.out, "  steering_gain [1] ")) << r.out;
  EXPECT_FALSE(Has(r.out, "steering_gain [m]")) << r.out;
  const YAML::Node sigma = YAML::LoadFile(dir.Path("cal.yaml"))["calibration"]["sigma"];
  EXPECT_TRUE(sigma["steering_gain"].IsDefined()) << sigma;
  EXPECT_FALSE(sigma["steering_gain_m"].IsDefined()) << sigma;
}

}  // namespace
}  // namespace fitcal
