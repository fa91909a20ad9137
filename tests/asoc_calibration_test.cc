// ASOC calibration: the closed form of Doebbler Eq. 1-9 and ASOC's files (the final-pose fit is
// the seam's generic one: asoc_model_test).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "io/atomic_file.h"
#include "io/input_error.h"
#include "models/asoc/asoc_files.h"
#include "models/asoc/asoc_geometric.h"
#include "models/asoc/asoc_extras.h"
#include "odometry/text_format.h"
#include "tests/asoc_simulation.h"
#include "tests/asoc_robot_file.h"
#include "tests/test_paths.h"

namespace fitcal::asoc {
namespace {

// Eq. 1-9 solved on exact (unquantised) measurements made from known parameters with Eq. 4-7
// return those parameters to rounding.
TEST(AsocGeometricTest, HoldPairInvertsEq4To7) {
  const double D = 0.52, r_c = 0.081, r_w1 = 0.0405, r_w2 = 0.0398, d1 = 0.061, d2 = 0.0594;
  const double beta = 0.1, theta_perp = -2.0;
  const double G = std::asin(r_c / D), cg = D * std::cos(G);
  HoldMeasurement m;
  m.rotation_cw_rad = 4.0;
  m.rotation_ccw_rad = 3.5;
  m.wheel_cw_rad = {m.rotation_cw_rad * (cg + d1) / r_w1, m.rotation_cw_rad * (cg - d2) / r_w2};
  m.wheel_ccw_rad = {m.rotation_ccw_rad * (cg - d1) / r_w1, m.rotation_ccw_rad * (cg + d2) / r_w2};
  // Castor angles: theta_cw = theta_perp + Gamma, theta_ccw = theta_perp + 180 deg - Gamma; the
  // encoder reads theta + beta (Eq. 1-2).
  m.gamma_cw_rad = WrapAngle(theta_perp + G + beta);
  m.gamma_ccw_rad = WrapAngle(theta_perp + M_PI - G + beta);
  const CastorParameters c = SolveHoldPair(m, D, theta_perp);
  EXPECT_NEAR(c.offset_m, r_c, 1e-15);
  EXPECT_NEAR(c.wheel_radius_m[0], r_w1, 1e-15);
  EXPECT_NEAR(c.wheel_radius_m[1], r_w2, 1e-15);
  EXPECT_NEAR(c.wheel_offset_m[0], d1, 1e-15);
  EXPECT_NEAR(c.wheel_offset_m[1], d2, 1e-15);
  EXPECT_NEAR(c.encoder_bias_rad, beta, 1e-14);
}

// End to end: random vehicles drawn as Table I, the simulated manoeuvre with the prototype's
// quantisation (wheels 0.3 deg, pivots 0.07 deg), the closed form. Tolerances from the
// quantisation q = 0.07 deg = 1.22e-3 rad of the pivot encoders (which dominates):
//   beta:  each steady reading is off by at most q/2, so |beta error| <= q/2 = 0.035 deg;
//   r_c:   Gamma is off by at most q/2, so |dr_c / r_c| <= cot(Gamma) q/2 = 6.4 * 6.1e-4 = 0.39 %
//          (Gamma = asin(0.08 / 0.52) = 8.9 deg) -> 0.5 %;
//   r_w:   Delta theta over 270 deg of rotation is off by <= q, 2.6e-4 relative, plus
//          tan(Gamma) q/2 = 1e-4 from D cos Gamma -> 0.05 %;
//   d:     the same Delta theta error enters d with lever D / d = 8.7 -> 2.3e-3 -> 0.3 %.
// The drawn errors are up to 4 % (r_w) and 16 deg (beta): a wrong sign or a swapped wheel in
// Eq. 1-9 would miss by that much.
TEST(AsocGeometricTest, RecoversSimulatedParametersToQuantisation) {
  const Vehicle nominal = PrototypeVehicle();
  std::mt19937_64 rng(21);
  for (int set = 0; set < 4; ++set) {
    const Vehicle truth = DrawVehicle(nominal, ParameterSpread{}, rng);
    const auto runs = SimulateAsoc(truth, HoldTrajectories(nominal), set);
    const GeometricResult result = CalibrateGeometric(runs, nominal);
    ASSERT_TRUE(result.usable) << result.message;
    for (int i = 0; i < kNumCastors; ++i) {
      const CastorParameters& t = truth.castors[i];
      const CastorParameters& e = result.estimate.castors[i];
      EXPECT_EQ(result.num_estimates[i], 2);
      EXPECT_NEAR(e.offset_m / t.offset_m, 1.0, 5e-3) << "castor " << i;
      EXPECT_NEAR(e.encoder_bias_rad, t.encoder_bias_rad, 0.035 * M_PI / 180.0) << "castor " << i;
      for (int k = 0; k < 2; ++k) {
        EXPECT_NEAR(e.wheel_radius_m[k] / t.wheel_radius_m[k], 1.0, 5e-4) << "castor " << i;
        EXPECT_NEAR(e.wheel_offset_m[k] / t.wheel_offset_m[k], 1.0, 3e-3) << "castor " << i;
      }
    }
  }
}

TEST(AsocGeometricTest, MissingHoldRunsMakeTheResultUnusable) {
  const Vehicle nominal = PrototypeVehicle();
  auto runs = SimulateAsoc(nominal, HoldTrajectories(nominal));
  runs.resize(2);  // only castor 1 held: castors 2 and 3 get one estimate, castor 1 none
  const GeometricResult result = CalibrateGeometric(runs, nominal);
  EXPECT_FALSE(result.usable);
  EXPECT_EQ(result.num_estimates[0], 0);
  EXPECT_EQ(result.num_estimates[1], 1);
}

std::string TempPath(const std::string& name) {
  return std::string(FITCAL_BINARY_DIR) + "/asoc_io_test_" + name;
}

TEST(AsocFilesTest, RobotYamlRoundTrip) {
  std::mt19937_64 rng(8);
  io::AsocRobot robot;
  robot.name = "proto";
  robot.nominal = DrawVehicle(PrototypeVehicle(), ParameterSpread{}, rng);
  robot.pivot_distance_m = robot.nominal.PivotDistance(0, 1);
  robot.castor_names = {"front", "left", "right"};
  const std::string path = TempPath("robot.yaml");
  io::WriteFileAtomically(path, io::AsocRobotYaml(robot, "{method: test}"));
  const io::AsocRobot back = io::ReadAsocRobot(path);
  EXPECT_EQ(back.castor_names[1], "left");
  const auto a = robot.nominal.ToArray(), b = back.nominal.ToArray();
  // Ten significant digits are written: 1e-9 relative.
  for (int k = 0; k < kNumParameters; ++k) EXPECT_NEAR(a[k], b[k], 1e-9 * (std::abs(a[k]) + 1e-3));
}

// pivot_resolution_deg (the closed form's sigmas propagate it): written and read back; a value
// that is no step (0, negative, half a turn) refused with the file and its line.
TEST(AsocFilesTest, PivotResolutionRoundTripAndBadValues) {
  io::AsocRobot robot;
  robot.name = "proto";
  robot.nominal = PrototypeVehicle();
  robot.pivot_distance_m = robot.nominal.PivotDistance(0, 1);
  robot.pivot_resolution_rad = 0.07 * M_PI / 180.0;
  const std::string path = TempPath("resolution.yaml");
  const std::string text = io::AsocRobotYaml(robot);
  io::WriteFileAtomically(path, text);
  EXPECT_NEAR(io::ReadAsocRobot(path).pivot_resolution_rad, robot.pivot_resolution_rad, 1e-12);
  const std::size_t at = text.find("pivot_resolution_deg: 0.07\n");
  ASSERT_NE(at, std::string::npos) << text;
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  for (const char* bad : {"0", "-0.07", "180"}) {
    std::string edited = text;
    edited.replace(at, std::string("pivot_resolution_deg: 0.07").size(),
                   std::string("pivot_resolution_deg: ") + bad);
    io::WriteFileAtomically(path, edited);
    try {
      io::ReadAsocRobot(path);
      ADD_FAILURE() << bad << " accepted";
    } catch (const io::InputError& e) {
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_NE(std::string(e.what()).find("pivot_resolution_deg"), std::string::npos) << e.what();
    }
  }
}

// The ASOC encoder file of `log` (the reader's format; fitcal writes none): the round trip's
// first half.
std::string AsocEncoderCsv(const EncoderLog& log) {
  std::string out =
      "t,wheel_1a,wheel_1b,wheel_2a,wheel_2b,wheel_3a,wheel_3b,pivot_1,pivot_2,pivot_3\n";
  for (std::size_t k = 0; k < log.t_s.size(); ++k) {
    const EncoderSample& s = log.samples[k];
    out += StrFormat("%.6f,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", log.t_s[k],
                     s.wheel_rad[0][0], s.wheel_rad[0][1], s.wheel_rad[1][0], s.wheel_rad[1][1],
                     s.wheel_rad[2][0], s.wheel_rad[2][1], s.pivot_rad[0], s.pivot_rad[1],
                     s.pivot_rad[2]);
  }
  return out;
}

TEST(AsocFilesTest, EncoderCsvRoundTripAndBadInput) {
  EncoderLog log;
  for (int k = 0; k < 200; ++k) {  // wheels and pivots turning at incommensurate rates
    EncoderSample s;
    for (int i = 0; i < kNumCastors; ++i) {
      s.wheel_rad[i][0] = 0.37 * k * (i + 1);
      s.wheel_rad[i][1] = -0.29 * k / (i + 1);
      s.pivot_rad[i] = std::sin(0.013 * k * (i + 2));
    }
    log.t_s.push_back(0.05 * k);
    log.samples.push_back(s);
  }
  const std::string path = TempPath("enc.csv");
  io::WriteFileAtomically(path, AsocEncoderCsv(log));
  const EncoderLog back = io::ReadAsocEncoderCsv(path);
  ASSERT_EQ(back.samples.size(), log.samples.size());
  EXPECT_NEAR(back.samples.back().wheel_rad[2][1], log.samples.back().wheel_rad[2][1], 1e-9);
  EXPECT_NEAR(back.samples[100].pivot_rad[1], log.samples[100].pivot_rad[1], 1e-11);

  const auto expect_error = [&](const std::string& text, io::InputErrorKind kind, int line) {
    io::WriteFileAtomically(path, text);
    try {
      io::ReadAsocEncoderCsv(path);
      ADD_FAILURE() << "no error for: " << text;
    } catch (const io::InputError& e) {
      EXPECT_EQ(e.kind(), kind) << e.what();
      EXPECT_EQ(e.line(), line) << e.what();
    }
  };
  const std::string header =
      "t,wheel_1a,wheel_1b,wheel_2a,wheel_2b,wheel_3a,wheel_3b,pivot_1,pivot_2,pivot_3\n";
  expect_error("t,w_a,w_b,w_c\n0,0,0,0\n", io::InputErrorKind::kBadHeader, 1);
  expect_error(header + "0,0,0,0,0,0,0,0,0,0\n0.05,1,1,1,1,1,1,0,0\n",
               io::InputErrorKind::kWrongColumnCount, 3);
  expect_error(header + "0,0,0,0,0,0,0,0,0,0\n0,1,1,1,1,1,1,0,0,0\n",
               io::InputErrorKind::kNonIncreasingTime, 3);
  expect_error(header + "0,0,0,0,0,0,0,0,0,0\n0.05,1,x,1,1,1,1,0,0,0\n",
               io::InputErrorKind::kNonNumeric, 3);
  expect_error(header + "0,0,0,0,0,0,0,0,0,0\n", io::InputErrorKind::kTooFewSamples, 2);
}

}  // namespace
}  // namespace fitcal::asoc

namespace fitcal::asoc {
namespace {

// The closed form's sigmas (GeometricResult::sigma: the spread of each castor's two estimates,
// pooled over the castors, widened by Student's t for 3 degrees of freedom) against the truth of
// the one simulator (sim/model_simulator.h with the castor dynamics of asoc_extras.h, integrated
// with RK4, and quantised encoders; it shares the castor kinematics of asoc_model.h with the library, not
// Eq. 1-9 nor the replay), over 30 random vehicles per noise level: quantisation only, and 2 % and
// 5 % random error on each wheel increment (the sigmas add the pivot step, 0.07 deg, propagated
// through Eq. 1-9, as robot.yaml of `simulate --model asoc` states it). Each of the 18
// parameters' error over its sigma, z:
//   - |z| <= 3 for at least 95 % of the 540 (a t with 3 dof widened to 1 sigma gives 96 %);
//   - |z| <= 1 for 50-90 % (68 % expected), so the sigmas are neither too narrow nor too wide;
//   - per parameter kind (r_c, r_w, d, beta: 90 or 180 z's) RMS z in 0.4-2.5: a sigma 10x too
//     wide gives RMS z near 0.1, one 10x too narrow near 10.
// The measured figures are in docs/asoc.md.
struct Coverage {
  int n = 0, within1 = 0, within3 = 0;
  double kind_ss[4] = {0, 0, 0, 0};
  int kind_n[4] = {0, 0, 0, 0};
};

Coverage ClosedFormCoverage(double wheel_slip_sigma, std::uint64_t seed, int sets) {
  const Vehicle nominal = PrototypeVehicle();
  std::mt19937_64 rng(seed);
  Coverage c;
  const int kind_of[kParametersPerCastor] = {0, 1, 1, 2, 2, 3};  // ToArray's order
  for (int set = 0; set < sets; ++set) {
    const Vehicle truth = DrawVehicle(nominal, ParameterSpread{}, rng);
    const GeometricResult r =
        CalibrateGeometric(SimulateAsoc(truth, HoldTrajectories(nominal), seed + set,
                                        wheel_slip_sigma),
                           nominal, kPrototypePivotQuantumRad);
    EXPECT_TRUE(r.usable) << r.message;
    EXPECT_EQ(r.sigma_dof, 3);
    for (int i = 0; i < kNumCastors; ++i) {
      double t[kParametersPerCastor], e[kParametersPerCastor], s[kParametersPerCastor];
      truth.castors[i].ToArray(t);
      r.estimate.castors[i].ToArray(e);
      r.sigma[i].ToArray(s);
      for (int k = 0; k < kParametersPerCastor; ++k) {
        EXPECT_GT(s[k], 0.0) << "a measured parameter with sigma 0, castor " << i << " k " << k;
        const double error = k == kBiasIndex ? WrapAngle(e[k] - t[k]) : e[k] - t[k];
        const double z = error / s[k];
        ++c.n;
        c.within1 += std::abs(z) <= 1.0;
        c.within3 += std::abs(z) <= 3.0;
        c.kind_ss[kind_of[k]] += z * z;
        ++c.kind_n[kind_of[k]];
      }
    }
  }
  return c;
}

TEST(AsocGeometricTest, SigmasCoverTheErrorOnSimulatedVehicles) {
  const char* kinds[4] = {"r_c", "r_w", "d", "beta"};
  for (const double slip : {0.0, 0.02, 0.05}) {
    SCOPED_TRACE("wheel slip sigma " + std::to_string(slip));
    const Coverage c = ClosedFormCoverage(slip, 43, 30);
    std::printf("slip %.2f: |z| <= 1 %.1f %%, |z| <= 3 %.1f %% of %d;", slip,
                100.0 * c.within1 / c.n, 100.0 * c.within3 / c.n, c.n);
    EXPECT_GE(c.within3, 0.95 * c.n);
    EXPECT_GE(c.within1, 0.50 * c.n);
    EXPECT_LE(c.within1, 0.90 * c.n);
    for (int k = 0; k < 4; ++k) {
      const double rms = std::sqrt(c.kind_ss[k] / c.kind_n[k]);
      std::printf(" %s RMS z %.2f", kinds[k], rms);
      EXPECT_GT(rms, 0.4) << kinds[k];
      EXPECT_LT(rms, 2.5) << kinds[k];
    }
    std::printf("\n");
  }
}

// `simulate --model asoc`'s data set (the asoc model's scenario, asoc_extras.h): 6 holds, 10
// UMBmark circuits as repetitions 6-10 and the excursions as 1..N, every id distinct; the closed
// form on its holds lands nearer the drawn truth than the prototype is (noise-free encoders but
// the pivot step), so the truth the scenario draws is the one that drove the runs.
TEST(AsocScenarios, TheSimulatedDataSetIsDrivenByTheTruthItWrites) {
  const AsocModel& model = ExampleAsocModel();
  const SimulationScenario& scenario = ExtrasOf("asoc").scenario;
  const std::vector<double> p = scenario.default_truth(model.robot(), 3);
  const auto specs = scenario.trajectories(model, p, 2);
  ASSERT_EQ(specs.size(), 6u + 10u + 2u);
  Vehicle truth = model.asoc().nominal;
  truth.SetFromArray(p.data());
  std::vector<sim::TrajectorySpec> holds;
  for (const sim::TrajectorySpec& spec : specs) {
    if (spec.label.rfind("hold_", 0) == 0) holds.push_back(spec);
    if (spec.label.rfind("umbmark_", 0) == 0) {
      EXPECT_GE(spec.repetition, 6);
      EXPECT_LE(spec.repetition, 10);
    }
  }
  ASSERT_EQ(holds.size(), 6u);
  const GeometricResult cal = CalibrateGeometric(SimulateAsoc(truth, holds), model.asoc().nominal);
  ASSERT_TRUE(cal.usable) << cal.message;
  for (int i = 0; i < kNumCastors; ++i) {
    const double t = truth.castors[i].wheel_radius_m[0];
    EXPECT_LT(std::abs(cal.estimate.castors[i].wheel_radius_m[0] - t),
              std::abs(model.asoc().nominal.castors[i].wheel_radius_m[0] - t))
        << "castor " << i;
  }
}

}  // namespace
}  // namespace fitcal::asoc
