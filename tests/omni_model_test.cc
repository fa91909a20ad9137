// The general holonomic model (models/omni/): Palacin's three-wheel model as its N = 3 case, a
// mecanum robot against hand-derived kinematics, the pseudo-inverse, derivatives, YAML, refused
// geometry, the gauge, recovery from simulated runs, and the real OptiOdom four-wheel robot.

#include "models/omni/omni_model.h"

#include <ceres/cost_function.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>

#include "fit/model_fit.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "models/kinematic_model.h"
#include "models/model_registry.h"
#include "models/omni/omni_kinematics.h"
#include "models/omni3/omni3_kinematics.h"
#include "models/pose_errors.h"
#include "odometry/aligned_run.h"
#include "tests/model_support.h"
#include "tests/test_files.h"
#include "interchange/optiodom/optiodom_import.h"
#include "sim/model_simulator.h"
#include "models/omni/omni_trajectories.h"
#include "tests/three_wheel_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

RobotModelPtr Read(const std::string& yaml) { return ReadOmniModel(YAML::Load(yaml), "test.yaml"); }

RobotModelPtr Mecanum() { return Read(kOmniExampleYaml); }

// Palacin Table 1's robot written as an `omni` robot with the defaults (tangential, roller 0).
constexpr const char* kOmni3AsOmni = R"(model: omni
name: apr02
wheels:
  - {name: a, distance_m: 0.195, radius_m: 0.148, angle_deg: 60}
  - {name: b, distance_m: 0.195, radius_m: 0.148, angle_deg: 180}
  - {name: c, distance_m: 0.195, radius_m: 0.148, angle_deg: 300}
bounds:
  distance_m: [0.17, 0.22]
  radius_m: [0.138, 0.158]
  angle_offset_deg: [-2, 2]
)";

// Seeded parameters near Palacin's robot (Eq. 15 order) and wheel rates of a few rad/s.
std::vector<std::vector<double>> Omni3ParameterSets() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<std::vector<double>> out;
  for (int s = 0; s < 20; ++s) {
    std::vector<double> p(9);
    for (int i = 0; i < 3; ++i) {
      p[i] = 0.195 + 0.02 * u(rng);
      p[3 + i] = 0.148 + 0.008 * u(rng);
      p[6 + i] = DegToRad(60.0 + 120.0 * i + 2.0 * u(rng));
    }
    out.push_back(p);
  }
  return out;
}

EncoderSamples RandomSamples(int channels, int n, double rate_rad_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  EncoderSamples samples(channels);
  std::vector<double> w(channels);
  for (int k = 0; k < n; ++k) {
    for (double& v : w) v = rate_rad_s * u(rng);
    samples.push_back(0.01 + 0.002 * u(rng), w.data());
  }
  return samples;
}

TEST(OmniKinematics, ThreeTangentialOmniWheelsArePalacinsModel) {
  const OmniKinematics<3> omni;  // defaults: tangential drive, roller 0
  const EncoderSamples samples = RandomSamples(3, 2000, 5.0, 3);
  for (const std::vector<double>& p : Omni3ParameterSets()) {
    // Eq. 3's matrix and Eq. 6's inverse, entry by entry.
    EXPECT_LT((omni.KinematicMatrix(p.data()) - omni3::KinematicMatrix(p.data())).norm(), 1e-12);
    const auto f = omni.Prepare(p.data());
    const auto m_inv = Omni3Kinematics::Prepare(p.data());
    EXPECT_LT((f - m_inv).norm(), 1e-12);
    // Body steps of single intervals, and a replay of 2000 intervals (20 s).
    for (std::size_t k = 0; k < 20; ++k) {
      double a[3], b[3];
      omni.BodyStep(f, samples[k].value, samples[k].dt_s, &a[0], &a[1], &a[2]);
      Omni3Kinematics::BodyStep(m_inv, samples[k].value, samples[k].dt_s, &b[0], &b[1], &b[2]);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], 1e-12);
    }
    const Pose2d start{0.3, -0.2, 0.7};
    const Pose2d x = ReplayKinematics(omni, p.data(), samples, 0, samples.size(), start);
    const Pose2d y = ReplayKinematics<Omni3Kinematics>(p.data(), samples, 0, samples.size(), start);
    EXPECT_NEAR(x.x, y.x, 1e-12);
    EXPECT_NEAR(x.y, y.y, 1e-12);
    EXPECT_NEAR(x.theta, y.theta, 1e-12);
  }
}

// The shipped flower data set: the same residuals per run from the `omni3` and `omni` robots
// (nominal and a calibrated-looking parameter vector).
TEST(OmniKinematics, FlowerResidualsEqualOmni3s) {
  const fs::path flower = fs::path(FITCAL_SOURCE_DIR) / "data" / "flower";
  const io::Dataset data = io::LoadDataset(flower.string());
  const std::vector<AlignedRun> runs = AlignRuns(data.runs);
  const RobotModelPtr omni3 = ReadRobotModelFile((flower / "robot.yaml").string());
  const RobotModelPtr omni = Read(kOmni3AsOmni);
  ASSERT_EQ(omni->robot().held.size(), 0u) << "three wheels: all nine parameters determinable";
  std::vector<double> p = omni3->robot().nominal;
  for (const std::vector<double>& q :
       {p, std::vector<double>{0.2, 0.19, 0.198, 0.147, 0.149, 0.1485, DegToRad(60.5),
                               DegToRad(179.6), DegToRad(300.8)}}) {
    for (const AlignedRun& run : runs) {
      std::unique_ptr<ceres::CostFunction> a(omni3->FinalPoseCost(run, ResidualWeights{}));
      std::unique_ptr<ceres::CostFunction> b(omni->FinalPoseCost(run, ResidualWeights{}));
      const double* parameters[] = {q.data()};
      double ra[3], rb[3];
      ASSERT_TRUE(a->Evaluate(parameters, ra, nullptr));
      ASSERT_TRUE(b->Evaluate(parameters, rb, nullptr));
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(ra[i], rb[i], 1e-12) << run.id;
    }
  }
}

// ros2_controllers' mecanum equations for the example robot (lx = 0.2, ly = 0.15, r = 0.05,
// lx + ly = 0.35): w_fl = (vx - vy - 0.35 omega) / r, w_fr = (vx + vy + 0.35 omega) / r,
// w_rl = (vx + vy - 0.35 omega) / r, w_rr = (vx - vy + 0.35 omega) / r.
//   strafe vy = 0.1 m/s:  w = (-2, 2, 2, -2) rad/s
//   spin omega = 1 rad/s: w = (-7, 7, -7, 7) rad/s
//   forward vx = 0.1 m/s: w = (2, 2, 2, 2) rad/s
// and back: over dt = 0.5 s these rates move the robot (0, 0.05, 0), (0, 0, 0.5), (0.05, 0, 0).
TEST(OmniKinematics, MecanumMatchesHandDerivedStrafeAndSpin) {
  const RobotModelPtr model = Mecanum();
  const double* p = model->robot().nominal.data();
  const struct {
    Twist twist;
    double w[4];
  } cases[] = {{{0.0, 0.1, 0.0}, {-2, 2, 2, -2}},
               {{0.0, 0.0, 1.0}, {-7, 7, -7, 7}},
               {{0.1, 0.0, 0.0}, {2, 2, 2, 2}}};
  for (const auto& c : cases) {
    double w[4];
    ASSERT_TRUE(model->ChannelsForTwist(p, c.twist, w));
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(w[i], c.w[i], 1e-7) << i;  // angles to 1e-8 deg
    EncoderSamples one(4);
    one.push_back(0.5, c.w);
    // One interval from the origin: the pose is the body step itself.
    const Pose2d step = model->ReplayFinalPose(p, one, Pose2d{});
    EXPECT_NEAR(step.x, 0.5 * c.twist.vx_m_s, 1e-8);
    EXPECT_NEAR(step.y, 0.5 * c.twist.vy_m_s, 1e-8);
    EXPECT_NEAR(step.theta, 0.5 * c.twist.omega_rad_s, 1e-8);
  }
}

// Rates generated by J v replay exactly v (Eq. 4 integrated by hand); a slip of one wheel moves
// the step by the slip times that wheel's column of the pseudo-inverse.
TEST(OmniKinematics, AgreeingWheelsReplayExactlyAndSlipIsAveraged) {
  const RobotModelPtr model = Mecanum();
  const double* p = model->robot().nominal.data();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  EncoderSamples samples(4);
  Pose2d expected{0.1, 0.2, 0.3};
  const Pose2d start = expected;
  for (int k = 0; k < 3000; ++k) {
    const Twist v{0.4 * u(rng), 0.4 * u(rng), 1.0 * u(rng)};
    const double dt = 0.01;
    double w[4];
    ASSERT_TRUE(model->ChannelsForTwist(p, v, w));
    samples.push_back(dt, w);
    const double c = std::cos(expected.theta), s = std::sin(expected.theta);
    expected.x += (c * v.vx_m_s - s * v.vy_m_s) * dt;
    expected.y += (s * v.vx_m_s + c * v.vy_m_s) * dt;
    expected.theta += v.omega_rad_s * dt;
  }
  const Pose2d replayed = model->ReplayFinalPose(p, samples, start);
  EXPECT_NEAR(replayed.x, expected.x, 1e-10);
  EXPECT_NEAR(replayed.y, expected.y, 1e-10);
  EXPECT_NEAR(replayed.theta, expected.theta, 1e-10);

  // Slip of +4 rad/s on fl alone (w = (4, 0, 0, 0)) for 0.5 s. J^T J = diag(4, 4, 4 0.35^2) / r^2,
  // so pinv's first column is (r/4) (1, -1, -1/0.35): the body moves a quarter of fl's rim travel
  // (0.1 m) forward and right and turns by -0.1 / (4 0.35) rad - the slip is averaged.
  EncoderSamples slip(4);
  slip.push_back(0.5, {4.0, 0.0, 0.0, 0.0});
  const Pose2d step = model->ReplayFinalPose(p, slip, Pose2d{});
  EXPECT_NEAR(step.x, 0.5 * 0.05 * 4.0 / 4.0, 1e-8);
  EXPECT_NEAR(step.y, -0.5 * 0.05 * 4.0 / 4.0, 1e-8);
  EXPECT_NEAR(step.theta, -0.5 * 0.05 * 4.0 / (4.0 * 0.35), 1e-8);
}

// Five omni wheels at uneven angles, one mecanum-like: autodiff against central differences.
TEST(OmniKinematics, AutodiffMatchesCentralDifferences) {
  const RobotModelPtr model = Read(R"(model: omni
name: five
wheels:
  - {name: a, distance_m: 0.2, angle_deg: 10, radius_m: 0.05}
  - {name: b, distance_m: 0.21, angle_deg: 80, radius_m: 0.05, roller_angle_deg: 30}
  - {name: c, distance_m: 0.19, angle_deg: 150, radius_m: 0.051}
  - {name: d, distance_m: 0.2, angle_deg: 220, radius_m: 0.05, drive_angle_deg: 300}
  - {name: e, distance_m: 0.2, angle_deg: 290, radius_m: 0.049}
bounds: {distance_m: [0.15, 0.25], radius_m: [0.04, 0.06], angle_offset_deg: [-3, 3]}
)");
  AlignedRun run;
  run.samples = RandomSamples(5, 500, 8.0, 5);
  run.start = {0.1, 0.0, 0.4};
  run.final_ground_truth = {0.5, -0.3, 1.0};
  std::vector<double> p = model->robot().nominal;
  p[0] += 0.003;
  p.back() += 0.01;
  testing::ExpectFinalPoseJacobianMatchesCentralDifferences(*model, run, p);
}

TEST(OmniModel, YamlRoundTripKeepsGeometryAndDefaults) {
  const RobotModelPtr model = Mecanum();
  std::vector<double> p = model->robot().nominal;
  p[1] += 0.004;   // R_fr
  p[6] -= 0.0005;  // r_rl
  p[8] += 0.01;    // delta_fl
  const std::string text = model->RobotYaml(p, "");
  const RobotModelPtr back = Read(text);
  ASSERT_EQ(back->robot().NumParameters(), 12);
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(back->robot().nominal[k], p[k], 1e-9) << k;
  for (int k = 0; k < 12; ++k) {
    EXPECT_DOUBLE_EQ(back->robot().bounds[k].Width(), model->robot().bounds[k].Width());
  }
  // Same drive and roller geometry: the same replay.
  const EncoderSamples samples = RandomSamples(4, 300, 6.0, 9);
  const Pose2d a = model->ReplayFinalPose(p.data(), samples, Pose2d{});
  const Pose2d b = back->ReplayFinalPose(back->robot().nominal.data(), samples, Pose2d{});
  EXPECT_NEAR(a.x, b.x, 1e-8);
  EXPECT_NEAR(a.y, b.y, 1e-8);
  EXPECT_NEAR(a.theta, b.theta, 1e-8);
  // Defaults: tangential drive (angle + 90 deg) and roller 0 equal their explicit values.
  const std::string explicit_text = R"(model: omni
name: apr02
wheels:
  - {name: a, distance_m: 0.195, radius_m: 0.148, angle_deg: 60, drive_angle_deg: 150, roller_angle_deg: 0}
  - {name: b, distance_m: 0.195, radius_m: 0.148, angle_deg: 180, drive_angle_deg: 270, roller_angle_deg: 0}
  - {name: c, distance_m: 0.195, radius_m: 0.148, angle_deg: 300, drive_angle_deg: 390, roller_angle_deg: 0}
bounds: {distance_m: [0.17, 0.22], radius_m: [0.138, 0.158], angle_offset_deg: [-2, 2]}
)";
  const RobotModelPtr defaults = Read(kOmni3AsOmni), explicit_model = Read(explicit_text);
  const EncoderSamples three = RandomSamples(3, 300, 6.0, 10);
  const Pose2d c = defaults->ReplayFinalPose(defaults->robot().nominal.data(), three, Pose2d{});
  const Pose2d d =
      explicit_model->ReplayFinalPose(explicit_model->robot().nominal.data(), three, Pose2d{});
  EXPECT_NEAR(c.x, d.x, 1e-12);
  EXPECT_NEAR(c.theta, d.theta, 1e-12);
  // The registry reads it by `model: omni`.
  EXPECT_NE(FindModel("omni"), nullptr);
}

std::string FourWheels(const std::string& drive_a, const std::string& drive_b) {
  return R"(model: omni
name: bad
wheels:
  - {name: w1, distance_m: 0.2, angle_deg: 0, radius_m: 0.05, )" +
         drive_a + R"(}
  - {name: w2, distance_m: 0.2, angle_deg: 90, radius_m: 0.05, )" +
         drive_b + R"(}
  - {name: w3, distance_m: 0.2, angle_deg: 180, radius_m: 0.05, )" +
         drive_a + R"(}
  - {name: w4, distance_m: 0.2, angle_deg: 270, radius_m: 0.05, )" +
         drive_b + R"(}
bounds: {distance_m: [0.1, 0.3], radius_m: [0.04, 0.06], angle_offset_deg: [-2, 2]}
)";
}

TEST(OmniModel, GeometryWithoutFullRankIsRefusedInOneLine) {
  // Every wheel driven radially (drive angle = position angle): no wheel senses a rotation.
  // Every wheel driven along x: none senses a sideways motion.
  const std::string radial = R"(model: omni
name: bad
wheels:
  - {name: w1, distance_m: 0.2, angle_deg: 0, radius_m: 0.05, drive_angle_deg: 0}
  - {name: w2, distance_m: 0.2, angle_deg: 90, radius_m: 0.05, drive_angle_deg: 90}
  - {name: w3, distance_m: 0.2, angle_deg: 180, radius_m: 0.05, drive_angle_deg: 180}
  - {name: w4, distance_m: 0.2, angle_deg: 270, radius_m: 0.05, drive_angle_deg: 270}
bounds: {distance_m: [0.1, 0.3], radius_m: [0.04, 0.06], angle_offset_deg: [-2, 2]}
)";
  for (const std::string& yaml : {radial, FourWheels("drive_angle_deg: 0", "drive_angle_deg: 0")}) {
    try {
      Read(yaml);
      ADD_FAILURE() << "accepted a rank-deficient geometry";
    } catch (const io::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("wheels w1, w2, w3, w4"), std::string::npos) << what;
      EXPECT_NE(what.find("full rank"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  // The same wheels, tangential: accepted (four omni wheels in a + layout).
  EXPECT_NO_THROW(Read(FourWheels("roller_angle_deg: 0", "roller_angle_deg: 0")));
  EXPECT_THROW(Read(FourWheels("roller_angle_deg: 90", "roller_angle_deg: 0")), io::InputError);
}

// A wheel's own problem is refused at its line (line 4, the `wheels:` list's, named the third
// wheel's duplicate name and the fourth's zero radius).
TEST(OmniModel, AWheelsProblemIsRefusedAtItsLine) {
  const std::string head = "model: omni\nname: bad\nwheels:\n";
  const auto wheel = [](const char* name, int angle, const char* radius) {
    char line[128];
    std::snprintf(line, sizeof line,
                  "  - {name: %s, distance_m: 0.2, angle_deg: %d, radius_m: %s}\n", name, angle,
                  radius);
    return std::string(line);
  };
  const std::string bounds =
      "bounds: {distance_m: [0.1, 0.3], radius_m: [0.04, 0.06], angle_offset_deg: [-2, 2]}\n";
  for (const auto& [yaml, says] : std::vector<std::pair<std::string, std::string>>{
           {head + wheel("a", 0, "0.05") + wheel("b", 120, "0.05") + wheel("a", 240, "0.05") +
                bounds,
            "bad.yaml:6: wheel name 'a' is used twice"},
           {head + wheel("a", 0, "0.05") + wheel("b", 90, "0.05") + wheel("c", 180, "0.05") +
                wheel("d", 270, "0") + bounds,
            "bad.yaml:7: wheel d: distance_m and radius_m must be positive"}}) {
    try {
      ReadOmniModel(YAML::Load(yaml), "bad.yaml");
      ADD_FAILURE() << says << ": accepted";
    } catch (const io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
}

// Symmetric mecanum: J's columns are (1,1,1,1), (-1,1,1,-1) and 0.35 (-1,1,-1,1) / r, so the
// wheel-disagreement direction is n = (1, 1, -1, -1) and the 3 x 4 = 12 parameters hold 9
// determinable combinations. The yaw entries are x tan(gamma) - y = -/+0.35 = R_i s_i with
// s = (-1.4, 1.4, -1.4, 1.4), so row changes n_i (0, 0, c) are R changes proportional to
// (-1, 1, 1, -1): R_fl - e, R_fr + e, R_rl + e, R_rr - e replays agreeing wheels identically.
TEST(OmniModel, GaugeOfFourMecanumWheelsIsNamed) {
  const RobotModelPtr model = Mecanum();
  const Robot& robot = model->robot();
  ASSERT_EQ(robot.held.size(), 3u);
  // Held: R_rr (pins the yaw direction), delta_rr and delta_rl (their rows point along (1, -1)
  // and (1, 1): together they pin the two translation directions); R_rl would repeat R_rr's.
  EXPECT_EQ(robot.parameters[robot.held[0].index].name, "R_rr");
  EXPECT_EQ(robot.parameters[robot.held[1].index].name, "delta_rl");
  EXPECT_EQ(robot.parameters[robot.held[2].index].name, "delta_rr");
  const std::string& reason = robot.held[0].reason;
  EXPECT_NE(reason.find("R_fl +1 m/m"), std::string::npos) << reason;
  EXPECT_NE(reason.find("R_fr -1 m/m"), std::string::npos) << reason;
  EXPECT_NE(reason.find("R_rl -1 m/m"), std::string::npos) << reason;
  // ... and it is true: that move leaves a run of agreeing wheels unchanged to first order (the
  // pseudo-inverse of J + n a^T differs from J's by O(|a|^2): with e = 1e-4 m, (e / R)^2 ~ 1.6e-7
  // of the 0.9 rad turned), while moving R_rr alone changes the heading by its quarter share of
  // e / R = 4e-4 of it (9e-5 rad).
  std::vector<double> p = robot.nominal;
  EncoderSamples samples(4);
  double w[4];
  for (const Twist& v : {Twist{0.3, 0.1, 0.5}, Twist{-0.1, 0.3, -0.8}, Twist{0.0, 0.0, 1.2}}) {
    ASSERT_TRUE(model->ChannelsForTwist(p.data(), v, w));
    for (int k = 0; k < 100; ++k) samples.push_back(0.01, w);
  }
  const Pose2d reference = model->ReplayFinalPose(p.data(), samples, Pose2d{});
  std::vector<double> gauge = p, alone = p;
  const double e = 1e-4;
  gauge[0] -= e, gauge[1] += e, gauge[2] += e, gauge[3] -= e;
  alone[3] -= e;
  const Pose2d a = model->ReplayFinalPose(gauge.data(), samples, Pose2d{});
  const Pose2d b = model->ReplayFinalPose(alone.data(), samples, Pose2d{});
  EXPECT_NEAR(a.theta, reference.theta, 1e-6);
  EXPECT_NEAR(a.x, reference.x, 1e-6);
  EXPECT_NEAR(a.y, reference.y, 1e-6);
  EXPECT_GT(std::abs(b.theta - reference.theta), 3e-5);
  // Three wheels: nothing held.
  EXPECT_TRUE(Read(kOmni3AsOmni)->robot().held.empty());
}

// A simulated run on the encoders' clock: the simulator records the start pose and its ground
// truth covers the whole encoder span, so the run needs no clipping (odometry/aligned_run.h does
// the same for these runs, for any channel count).
AlignedRun AlignedOnEncoderClock(const RunLog& log) {
  AlignedRun run;
  run.id = log.id;
  run.t_start_s = log.encoders.t_s.front();
  run.t_final_s = log.encoders.t_s.back();
  run.start = *log.start_pose;
  run.final_ground_truth = InterpolateGroundTruth(log.ground_truth, run.t_final_s);
  run.samples = log.encoders.samples;
  return run;
}

// The example mecanum robot with its free parameters moved, simulated on the generalised flower
// (36 runs, plus spins) with encoder and ground-truth noise; the fit holds the gauge and must
// land within 4 sigma of the truth, sigma from its covariance (i.e. from the noise). The
// perturbation is >= 3 sigma for every parameter, so the nominal would fail the same test.
TEST(OmniModel, FitRecoversASimulatedMecanumRobot) {
  const RobotModelPtr model = Mecanum();
  const Robot& robot = model->robot();
  std::vector<double> truth = robot.nominal;
  const double moves[9] = {0.006,  -0.008,  0.005,         0.0008,        -0.0006,
                           0.0005, -0.0007, DegToRad(0.8), DegToRad(-0.6)};
  const int free_index[9] = {0, 1, 2, 4, 5, 6, 7, 8, 9};  // all but R_rr, delta_rl, delta_rr
  for (int j = 0; j < 9; ++j) truth[free_index[j]] += moves[j];
  sim::OmniTrajectoryOptions shapes;
  shapes.spin_angle_rad = 2.0 * M_PI;
  sim::SimulationOptions options;
  options.encoder_period_s = 0.02;
  options.ground_truth_period_s = 0.05;
  options.wheel_rate_sigma_rad_s = 0.02;
  options.gt_position_sigma_m = 0.001;
  options.gt_heading_sigma_rad = 0.002;
  options.record_start_pose = true;
  options.seed = 42;
  const auto simulated =
      sim::SimulateRuns(*model, truth, sim::OmniFlowerTrajectories(2, shapes), options);
  std::vector<AlignedRun> runs;
  for (const auto& s : simulated) runs.push_back(AlignedOnEncoderClock(s.log));
  const ModelFitResult fit = FitModel(runs, *model);
  ASSERT_TRUE(fit.usable) << fit.message;
  ASSERT_TRUE(fit.has_covariance) << fit.covariance_message;
  for (const HeldParameter& h : robot.held) {
    EXPECT_EQ(fit.parameters[h.index], robot.nominal[h.index]);
  }
  for (int j = 0; j < 9; ++j) {
    const int k = free_index[j];
    SCOPED_TRACE(robot.parameters[k].name);
    EXPECT_GT(fit.sigma[k], 0.0);
    EXPECT_LT(std::abs(fit.parameters[k] - truth[k]), 4.0 * fit.sigma[k]);
    EXPECT_GT(std::abs(moves[j]), 3.0 * fit.sigma[k]);
  }
}

// ---- the real four-wheel robot (skipped without ../shared/data/optiodom) ----

const fs::path kOmni4 = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / "omni4";
const fs::path kSession = kOmni4 / "circular" / "080920201911";

// The authors' odometry written out independently of the model (simulateRobot_omni4.m's J, Eq. 4
// steps as fitcal's replay): d_i = pi D enc_i, dx = (d1 - d2 + d3 - d4) / 4,
// dy = (-d1 - d2 + d3 + d4) / 4, dtheta = -(d1 + d2 + d3 + d4) / (2 (L1 + L2)).
Pose2d AuthorsFinalPose(const fs::path& file, double diameter_m, double l1_plus_l2_m) {
  std::ifstream in(file);
  std::string line;
  Pose2d pose;
  bool first = true;
  while (std::getline(in, line)) {
    const std::vector<double> v = testing::CsvNumbers(line, 8);
    if (first) {
      first = false;
      continue;
    }
    double d[4];
    for (int i = 0; i < 4; ++i) d[i] = M_PI * diameter_m * v[4 + i];
    const double dx = (d[0] - d[1] + d[2] - d[3]) / 4.0;
    const double dy = (-d[0] - d[1] + d[2] + d[3]) / 4.0;
    const double dth = -(d[0] + d[1] + d[2] + d[3]) / (2.0 * l1_plus_l2_m);
    pose.x += std::cos(pose.theta) * dx - std::sin(pose.theta) * dy;
    pose.y += std::sin(pose.theta) * dx + std::cos(pose.theta) * dy;
    pose.theta += dth;
  }
  return pose;
}

TEST(OptiOdomOmni4, ImportedSessionReproducesTheAuthorsNominalOdometry) {
  if (!fs::is_directory(kSession)) GTEST_SKIP() << "no " << kSession;
  const fs::path out = fs::temp_directory_path() / ("fitcal_omni4_" + std::to_string(::getpid()));
  fs::remove_all(out);
  optiodom::ImportOptiOdomOptions options;
  options.sessions = {kSession.string()};
  options.out = out.string();
  const optiodom::OptiOdomImport result = optiodom::ImportOptiOdom(options);
  EXPECT_EQ(result.runs.size(), 4u);
  // The channel-order check kept the documented layout (it throws otherwise) on the track's
  // windows.
  EXPECT_NE(result.channel_order.find("0.5 m windows"), std::string::npos) << result.channel_order;

  const optiodom::OptiOdomImport session = optiodom::ReadOptiOdomSessions({kSession.string()});
  const RobotModelPtr model = session.model;
  // The written robot YAML (10 significant digits) is the same robot.
  const RobotModelPtr written = ReadRobotModelFile((out / "robot.yaml").string());
  ASSERT_EQ(written->robot().NumChannels(), 4);
  for (int k = 0; k < 12; ++k) {
    EXPECT_NEAR(written->robot().nominal[k], model->robot().nominal[k], 1e-9) << k;
  }
  double mean_cf = 0.0;
  for (const RunLog& log : session.runs) {
    const std::string file = "080920201911_run-" + std::string(log.repetition < 10 ? "0" : "") +
                             std::to_string(log.repetition) + ".csv";
    const Pose2d authors = AuthorsFinalPose(kSession / file, 0.06, 0.4);
    const Pose2d ours =
        model->ReplayFinalPose(model->robot().nominal.data(), log.encoders.samples, Pose2d{});
    // Same equations, rates via 2 pi enc / dt and back: rounding only.
    EXPECT_NEAR(ours.x, authors.x, 1e-9) << file;
    EXPECT_NEAR(ours.y, authors.y, 1e-9) << file;
    EXPECT_NEAR(ours.theta, authors.theta, 1e-9) << file;
    const Pose2d& gt = log.ground_truth.world_T_robot.back();
    mean_cf += std::sqrt(std::pow(authors.x - gt.x, 2) + std::pow(authors.y - gt.y, 2) +
                         std::pow(WrapAngle(authors.theta - gt.theta), 2)) /
               4.0;
  }
  EXPECT_NEAR(result.nominal.cf, mean_cf, 1e-9);
  // The written encoder CSV holds the same rates (shortest exact decimal form).
  std::ifstream csv(out / "runs" / (session.runs[0].id + "_encoders.csv"));
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header, "t,w_fl,w_fr,w_rl,w_rr");
  std::getline(csv, row);
  std::getline(csv, row);
  const std::vector<double> first = testing::CsvNumbers(row, 5);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(first[1 + i], session.runs[0].encoders.samples[0].value[i]);
  std::printf("omni4 %s: nominal mean final-pose CF %.4f; %s\n", kSession.filename().c_str(),
              mean_cf, result.channel_order.c_str());
  fs::remove_all(out);
}

}  // namespace
}  // namespace fitcal
