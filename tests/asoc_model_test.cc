// The ASOC vehicle on the model seam (models/asoc/asoc_robot_model.h): its body step on simulated
// UMBmark circuits, every hold run used by the closed form (Doebbler Eq. 1-9), the odometry
// variants of the robot YAML, ASOC's own encoder files converted on load, the generic CSV, and the
// generic fit. Runs from the one simulator with the castor dynamics (tests/asoc_simulation.h).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "models/asoc/asoc_files.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "models/asoc/asoc_geometric.h"
#include "models/asoc/asoc_robot_model.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "tests/test_files.h"
#include "tests/asoc_simulation.h"
#include "tests/three_wheel_files.h"

namespace fitcal {
namespace {

io::AsocRobot RobotOf(const asoc::Vehicle& v, const std::string& odometry = "CAST-0",
                      bool redundancy_check = false) {
  io::AsocRobot robot;
  robot.name = "sim";
  robot.pivot_distance_m = v.PivotDistance(0, 1);
  robot.nominal = v;
  robot.odometry = odometry;
  robot.redundancy_check = redundancy_check;
  return robot;
}

RobotModelPtr ModelOf(const asoc::Vehicle& v, const std::string& odometry = "CAST-0",
                      bool redundancy_check = false) {
  return ReadRobotModel(YAML::Load(io::AsocRobotYaml(RobotOf(v, odometry, redundancy_check))),
                        "test robot");
}

std::vector<AlignedRun> Aligned(const std::vector<RunLog>& runs) { return AlignRuns(runs); }

double PositionError(const Pose2d& a, const Pose2d& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// UMBmark circuits of a drawn vehicle (6 m each, encoders quantised as the prototype's), replayed
// with the true parameters: the seam's body step solves Eq. 13-14 about the interval's middle
// (exact for a rigid step) from the pivot angles as the mean of an interval's two readings. Only
// the 20 Hz update and quantisation error remains after 6 m: bounds 5 mm and 4e-3 rad (before the
// one simulator: 0.03 / 3.3 mm for CW / CCW, from the native files' cubic midpoint).
TEST(AsocModelTest, BodyStepReplaysUmbmarkToTheUpdateError) {
  const asoc::Vehicle nominal = asoc::PrototypeVehicle();
  std::mt19937_64 rng(7);
  const asoc::Vehicle truth = asoc::DrawVehicle(nominal, asoc::ParameterSpread{}, rng);
  const RobotModelPtr model = ModelOf(truth);
  const std::vector<double> p = model->robot().nominal;
  for (const AlignedRun& run :
       Aligned(asoc::SimulateAsoc(truth, asoc::UmbmarkTrajectories(1, 1), 7))) {
    SCOPED_TRACE(run.trajectory);
    const Pose2d seam = model->ReplayFinalPose(p.data(), run.samples, run.start);
    const Pose2d& gt = run.final_ground_truth;
    std::printf("%s: %.2f mm, %.2e rad\n", run.trajectory.c_str(), 1e3 * PositionError(seam, gt),
                seam.theta - gt.theta);
    EXPECT_LT(PositionError(seam, gt), 5e-3);
    EXPECT_NEAR(seam.theta, gt.theta, 4e-3);
  }
}

// Three repetitions of the manoeuvre: 18 hold runs, each castor estimated from every CW x CCW pair
// of the two castors that can hold it (2 x 3 x 3 = 18 estimates), and the message counts them all
// (before, a second repetition silently replaced the first: "from 6 hold runs").
TEST(AsocModelTest, EveryHoldRunIsUsed) {
  const asoc::Vehicle nominal = asoc::PrototypeVehicle();
  std::mt19937_64 rng(5);
  const asoc::Vehicle truth = asoc::DrawVehicle(nominal, asoc::ParameterSpread{}, rng);
  std::vector<sim::TrajectorySpec> specs;
  for (int rep = 1; rep <= 3; ++rep) {
    for (sim::TrajectorySpec spec : asoc::HoldTrajectories(nominal)) {
      spec.repetition = rep;
      specs.push_back(std::move(spec));
    }
  }
  const std::vector<RunLog> runs = asoc::SimulateAsoc(truth, specs, 5);
  const asoc::GeometricResult result = asoc::CalibrateGeometric(runs, nominal);
  ASSERT_TRUE(result.usable) << result.message;
  EXPECT_NE(result.message.find("from 18 of 18 hold runs"), std::string::npos) << result.message;
  for (int i = 0; i < asoc::kNumCastors; ++i) EXPECT_EQ(result.num_estimates[i], 18);
  const auto closed = ModelOf(nominal)->ClosedForms(Aligned(runs));
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_NE(closed[0].note.find("from 18 of 18 hold runs"), std::string::npos) << closed[0].note;
}

// The odometry variants are the robot YAML's `odometry:` (Doebbler Table II names). A wheel of
// castor 2 that over-counts by 30 % for 3 s throws CAST-0 off; the redundancy check drops that
// castor while it slips, and CAST-2 / IPEC-2 (castor 2 left out) never see it.
TEST(AsocModelTest, OdometryVariantsFromTheRobotYaml) {
  const asoc::Vehicle truth = asoc::PrototypeVehicle();
  RunLog log = asoc::SimulateAsoc(truth, asoc::UmbmarkTrajectories(1, 1), 3).front();
  for (std::size_t k = 0; k < log.encoders.samples.size(); ++k) {
    const double t = log.encoders.t_s[k + 1];
    if (t > 2.0 && t <= 5.0) log.encoders.samples[k].value[asoc::kChannelsPerCastor] *= 1.3;
  }
  const AlignedRun run = AlignRun(log);
  const auto error = [&](const std::string& algorithm, bool check) {
    const RobotModelPtr model = ModelOf(truth, algorithm, check);
    const Pose2d f = model->ReplayFinalPose(model->robot().nominal.data(), run.samples, run.start);
    return PositionError(f, run.final_ground_truth);
  };
  const double cast0 = error("CAST-0", false);
  EXPECT_GT(cast0, 0.02);
  EXPECT_LT(error("CAST-0", true), 0.2 * cast0);
  EXPECT_LT(error("CAST-2", false), 0.2 * cast0);
  EXPECT_LT(error("IPEC-2", false), 0.2 * cast0);

  for (const auto& [algorithm, check] : {std::pair<std::string, bool>{"CAST-4", false},
                                         {"IPEC-0", false},
                                         {"IPEC-1", true},
                                         {"cast-0", false}}) {
    SCOPED_TRACE(algorithm);
    EXPECT_THROW(ModelOf(truth, algorithm, check), io::InputError);
  }
  // Written back as read.
  const RobotModelPtr ipec = ModelOf(truth, "IPEC-3");
  const std::string yaml = ipec->RobotYaml(ipec->robot().nominal, "");
  EXPECT_NE(yaml.find("algorithm: IPEC-3"), std::string::npos) << yaml;
}

// ASOC's encoder file (cumulative wheel angles, pivot readings wrapping at +-pi) becomes the
// model's channels: rates are increments over dt, pivot angles the interval's middle along the
// shorter arc (at the log's ends the mean of the two readings).
TEST(AsocModelTest, NativeEncoderLogBecomesTheModelsChannels) {
  asoc::EncoderLog log;
  log.t_s = {0.0, 0.05, 0.15};
  log.samples.resize(3);
  log.samples[1].wheel_rad[0][0] = 0.1;
  log.samples[2].wheel_rad[0][0] = 0.4;
  log.samples[1].wheel_rad[2][1] = -0.2;
  log.samples[0].pivot_rad[1] = M_PI - 0.01;
  log.samples[1].pivot_rad[1] = -M_PI + 0.03;  // wrapped: the castor turned by +0.04 rad
  log.samples[2].pivot_rad[1] = -M_PI + 0.03;
  const EncoderLog channels = io::AsocEncoderLogAsChannels(log);
  ASSERT_EQ(channels.samples.size(), 2u);
  ASSERT_EQ(channels.samples.num_channels(), asoc::kNumChannels);
  EXPECT_NEAR(channels.samples[0].value[asoc::kWheelAChannel], 0.1 / 0.05, 1e-12);
  EXPECT_NEAR(channels.samples[1].value[asoc::kWheelAChannel], 0.3 / 0.1, 1e-12);
  EXPECT_NEAR(channels.samples[0].value[2 * asoc::kChannelsPerCastor + asoc::kWheelBChannel],
              -0.2 / 0.05, 1e-12);
  const int pivot_2 = asoc::kChannelsPerCastor + asoc::kPivotChannel;
  EXPECT_NEAR(WrapAngle(channels.samples[0].value[pivot_2] - (M_PI + 0.01)), 0.0, 1e-12);
  EXPECT_NEAR(WrapAngle(channels.samples[1].value[pivot_2] - (-M_PI + 0.03)), 0.0, 1e-12);

  // Inside the log the pivot angle is the cubic midpoint of four readings, exact for a castor
  // whose angle is quadratic in time (the mean of two readings would say 2.5 here).
  asoc::EncoderLog swing;
  for (int k = 0; k < 4; ++k) {
    swing.t_s.push_back(k);
    swing.samples.emplace_back();
    swing.samples.back().pivot_rad[0] = 0.1 * k * k;
  }
  EXPECT_NEAR(io::AsocEncoderLogAsChannels(swing).samples[1].value[asoc::kPivotChannel], 0.225,
              1e-15);
}

// A user's own logs in the generic CSV (columns w_<castor>_a, w_<castor>_b, pivot_<castor>, named
// from the robot YAML) are read by the generic reader with the asoc model's channels: the CSV the
// simulator writes reads back as the run it simulated.
TEST(AsocModelTest, GenericCsvWithTheCastorsColumnNames) {
  const asoc::Vehicle truth = asoc::PrototypeVehicle();
  const auto p = truth.ToArray();
  const sim::ModelSimulatedRun run =
      sim::SimulateRuns(asoc::ExampleAsocModel(), {p.begin(), p.end()},
                        asoc::UmbmarkTrajectories(1, 1), asoc::PrototypeSimulation(4, 0.0))
          .back();
  const RobotModelPtr model = ModelOf(truth);
  const std::string csv = sim::SimulatedEncoderCsv(run);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "t,w_1_a,w_1_b,pivot_1,w_2_a,w_2_b,pivot_2,w_3_a,w_3_b,pivot_3");
  const testing::TempDir dir;
  const EncoderLog generic = io::ReadEncoderCsv(dir.Write("enc.csv", csv), model->robot());
  ASSERT_EQ(generic.samples.size(), run.log.encoders.samples.size());
  for (std::size_t k = 0; k < generic.samples.size(); k += 50) {
    for (int c = 0; c < asoc::kNumChannels; ++c) {
      EXPECT_NEAR(generic.samples[k].value[c], run.log.encoders.samples[k].value[c], 1e-12);
    }
  }
}

// The seam's generic final-pose fit (fit/model_fit.h) on random excursions (ground truth exact,
// encoders quantised) brings the UMBmark validation error of a random vehicle (pivot biases up to
// 5 deg, absorbed by the wheel parameters: see Gauge in asoc_robot_model.cc) down from the
// uncalibrated decimetres to the level of the true parameters (limited by quantisation and the
// 20 Hz discretisation, ~mm): below 5 % of the nominal's and within 1 cm of the truth's.
TEST(AsocModelTest, GenericFitRecoversOdometry) {
  const asoc::Vehicle nominal = asoc::PrototypeVehicle();
  asoc::ParameterSpread spread;
  spread.bias_range_rad = 5.0 * M_PI / 180.0;
  std::mt19937_64 rng(31);
  const asoc::Vehicle truth = asoc::DrawVehicle(nominal, spread, rng);
  std::vector<AlignedRun> training, validation;
  std::vector<sim::TrajectorySpec> excursions;
  for (int k = 0; k < 12; ++k) excursions.push_back(asoc::ExcursionTrajectory(k + 1, 4));
  training = Aligned(asoc::SimulateAsoc(truth, excursions, 31));
  validation = Aligned(asoc::SimulateAsoc(truth, asoc::UmbmarkTrajectories(1, 1), 32));
  const RobotModelPtr model = ModelOf(nominal);
  ModelFitOptions options;
  options.ceres.compute_covariance = false;
  const ModelFitResult fit = FitModel(training, *model, options);
  ASSERT_TRUE(fit.usable) << fit.termination << ": " << fit.message;
  const auto cf = [&](const std::vector<double>& p) {
    return EvaluateFinalPoseErrors(*model, p, validation).cf;
  };
  const double before = cf(model->robot().nominal);
  const double after = cf(fit.parameters);
  const double truth_cf = cf(ModelOf(truth)->robot().nominal);
  EXPECT_GT(before, 0.05);
  EXPECT_LT(after, 0.05 * before);
  EXPECT_LT(after, truth_cf + 0.01);
}

// The reported one-sigma of the generic fit (covariance scaled by the residual variance)
// describes the actual error to within a factor. The truth is drawn with r_c and beta at the
// nominal (the seam holds them, so the 12 free wheel parameters can equal the truth's); over 6
// seeds x 12 free parameters, z = (estimate - truth) / sigma has rms 1.36 and worst |z| 3.73
// (measured; above 1 because quantisation errors are not white). The bounds below (rms in
// [0.75, 2.2], worst < 6) fail when sigma is off by 2x either way (rms then ~0.68 or ~2.7).
TEST(AsocModelTest, GenericFitSigmaDescribesTheEstimationError) {
  const asoc::Vehicle nominal = asoc::PrototypeVehicle();
  const RobotModelPtr model = ModelOf(nominal);
  asoc::ParameterSpread spread;
  spread.offset_fraction = 0.0;
  spread.bias_range_rad = 0.0;
  double worst_z = 0.0, sum_z2 = 0.0;
  int with_covariance = 0, count = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    std::mt19937_64 rng(100 + seed);
    const asoc::Vehicle truth = asoc::DrawVehicle(nominal, spread, rng);
    std::vector<sim::TrajectorySpec> excursions;
    for (int k = 0; k < 16; ++k) excursions.push_back(asoc::ExcursionTrajectory(16 * seed + k, 4));
    const std::vector<AlignedRun> training = Aligned(asoc::SimulateAsoc(truth, excursions, seed));
    const ModelFitResult fit = FitModel(training, *model);
    ASSERT_TRUE(fit.usable) << fit.message;
    EXPECT_TRUE(fit.held_directions.empty());
    if (!fit.has_covariance) continue;
    ++with_covariance;
    const auto tru = truth.ToArray();
    for (int k = 0; k < asoc::kNumParameters; ++k) {
      if (fit.held[k]) {
        EXPECT_DOUBLE_EQ(fit.parameters[k], tru[k]) << k;
        continue;
      }
      ASSERT_GT(fit.sigma[k], 0.0) << k;
      const double z = (fit.parameters[k] - tru[k]) / fit.sigma[k];
      worst_z = std::max(worst_z, std::abs(z));
      sum_z2 += z * z;
      ++count;
    }
  }
  const double rms_z = std::sqrt(sum_z2 / std::max(count, 1));
  std::printf("z = (estimate - truth) / sigma: rms %.2f, worst %.2f over %d fits, %d values\n",
              rms_z, worst_z, with_covariance, count);
  EXPECT_GE(with_covariance, 5);
  EXPECT_EQ(count, with_covariance * 12);
  EXPECT_GT(rms_z, 0.75);
  EXPECT_LT(rms_z, 2.2);
  EXPECT_LT(worst_z, 6.0);
}

}  // namespace
}  // namespace fitcal
