// ASOC model and multi-castor odometry (Doebbler Sec. II-D, III-B).
#include "models/asoc/asoc_odometry.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "models/asoc/asoc_extras.h"
#include "models/asoc/asoc_model.h"
#include "models/asoc/asoc_tables.h"
#include "tests/asoc_simulation.h"

namespace fitcal::asoc {
namespace {

// True when the used pivots' centroid is the body origin (b = c = 0 in Eq. 18), to 1e-9 m.
bool PivotsCentred(const std::array<PivotPosition, kNumCastors>& pivots, CastorMask mask) {
  double mx = 0.0, my = 0.0;
  for (int i = 0; i < kNumCastors; ++i) {
    if ((mask >> i) & 1u) {
      mx += pivots[i].x_m();
      my += pivots[i].y_m();
    }
  }
  return std::hypot(mx, my) < 1e-9;
}

// CAST centred solution, Eq. 22: translation = the mean pivot displacement, and
//   dpsi = sum R_i (dy_i cos(psi+phi_i) - dx_i sin(psi+phi_i)) / sum R_i^2,
// which is Eq. 22's (1/n) sum (1/R)(...) when all R_i equal R. Only valid for centred pivots.
template <typename T>
BodyStep<T> SolveCastCentred(const std::array<PivotPosition, kNumCastors>& pivots, CastorMask mask,
                             const T& psi, const T* dx, const T* dy) {
  using std::cos;
  using std::sin;
  const T cp = cos(psi), sp = sin(psi);
  double n = 0.0, d = 0.0;
  BodyStep<T> out{T(0.0), T(0.0), T(0.0)};
  for (int i = 0; i < kNumCastors; ++i) {
    if (!((mask >> i) & 1u)) continue;
    const double px = pivots[i].x_m(), py = pivots[i].y_m();
    n += 1.0;
    d += px * px + py * py;
    out.dx_m += dx[i];
    out.dy_m += dy[i];
    out.dpsi_rad += (px * cp - py * sp) * dy[i] - (py * cp + px * sp) * dx[i];
  }
  out.dx_m /= n;
  out.dy_m /= n;
  out.dpsi_rad /= d;
  return out;
}

CastorParameters TestCastor() {
  CastorParameters c;
  c.offset_m = 0.08;
  c.wheel_radius_m = {0.040, 0.042};
  c.wheel_offset_m = {0.060, 0.058};
  c.encoder_bias_rad = 0.0;
  return c;
}

// The pivot velocity from two wheel rates, worked by hand from the derivation in asoc_model.h:
// roll_1 = 0.04 * 3 = 0.12, roll_2 = 0.042 * 5 = 0.21 (m/s), axle d1 + d2 = 0.118 m:
//   omega_c = (0.21 - 0.12) / 0.118             = 0.762711864406780 rad/s
//   u       = (0.058 * 0.12 + 0.06 * 0.21) / 0.118 = 0.165762711864407 m/s
//   w       = 0.08 * omega_c                     = 0.061016949152542 m/s
TEST(AsocModelTest, PivotVelocityMatchesHandDerivation) {
  double p[kParametersPerCastor];
  TestCastor().ToArray(p);
  const CastorMotion<double> m = PivotMotionFromWheels(p, 3.0, 5.0);
  EXPECT_NEAR(m.turn, 0.762711864406780, 1e-14);
  EXPECT_NEAR(m.along, 0.165762711864407, 1e-14);
  EXPECT_NEAR(m.lateral, 0.061016949152542, 1e-14);
}

// The same relation checked as vector algebra: with the computed (u, w, omega_c) the contact
// point of each wheel has no lateral velocity and rolls at r_w * rate; and the inverse maps back.
TEST(AsocModelTest, ContactPointsRollWithoutLateralSlip) {
  const CastorParameters c = TestCastor();
  double p[kParametersPerCastor];
  c.ToArray(p);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double w1 = u(rng), w2 = u(rng);
    const CastorMotion<double> m = PivotMotionFromWheels(p, w1, w2);
    for (int k = 0; k < 2; ++k) {
      const double s = k == 0 ? 1.0 : -1.0;
      // q - p = -r_c c1 + s d c2; v_q = v_p + omega perp(q - p), in castor coordinates.
      const double vq_along = m.along - m.turn * s * c.wheel_offset_m[k];
      const double vq_lateral = m.lateral - m.turn * c.offset_m;
      EXPECT_NEAR(vq_lateral, 0.0, 1e-13);
      EXPECT_NEAR(vq_along, c.wheel_radius_m[k] * (k == 0 ? w1 : w2), 1e-13);
    }
    const auto back = WheelRatesFromPivotMotion(c, m.along, m.lateral);
    EXPECT_NEAR(back[0], w1, 1e-12);
    EXPECT_NEAR(back[1], w2, 1e-12);
  }
}

// A pure rotation about a stationary pivot at distance D: the wheel rates of Eq. 4-7 (per unit
// body rotation, castor trailing at Gamma = asin(r_c / D)) must make the pivot move exactly as a
// rigid body turning about the held pivot, and turn the castor with the body.
TEST(AsocModelTest, RotationAboutStationaryCastorReproducesEq4To7) {
  const CastorParameters c = TestCastor();
  double p[kParametersPerCastor];
  c.ToArray(p);
  const double D = 0.52;
  const double gamma_path = std::asin(c.offset_m / D);  // Eq. 3
  for (const double psi_dot : {-0.7, 0.4}) {
    const double rate = std::abs(psi_dot);
    const bool cw = psi_dot < 0.0;
    // Eq. 4-7 with dtheta -> |psi_dot| and c -> wheel rate.
    const double w1 = rate * (D * std::cos(gamma_path) + (cw ? 1 : -1) * c.wheel_offset_m[0]) /
                      c.wheel_radius_m[0];
    const double w2 = rate * (D * std::cos(gamma_path) - (cw ? 1 : -1) * c.wheel_offset_m[1]) /
                      c.wheel_radius_m[1];
    const CastorMotion<double> m = PivotMotionFromWheels(p, w1, w2);
    EXPECT_NEAR(m.turn, psi_dot, 1e-14);                           // castor turns with the body
    EXPECT_NEAR(std::hypot(m.along, m.lateral), D * rate, 1e-14);  // on the circle of radius D
    EXPECT_NEAR(std::atan2(m.lateral, m.along), cw ? -gamma_path : gamma_path, 1e-14);
  }
}

// The total angle each wheel turned over a run: the sum of its interval rates times the intervals.
double WheelTotal(const RunLog& run, int castor, int wheel) {
  const EncoderSamples& samples = run.encoders.samples;
  double total = 0.0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    total += samples[k].value[castor * kChannelsPerCastor + kWheelAChannel + wheel] *
             samples[k].dt_s;
  }
  return total;
}

// The simulated calibration manoeuvre (no quantisation) obeys Eq. 4-7 on the integrated angles.
TEST(AsocModelTest, SimulatedHoldRunObeysEq4To7) {
  Vehicle truth = PrototypeVehicle();
  truth.castors[1] = TestCastor();
  const double D = truth.PivotDistance(0, 1);
  const double cg = D * std::cos(std::asin(truth.castors[1].offset_m / D));
  const double dtheta = 2.0;  // the segment's rotation: the ramps keep its integral
  std::vector<sim::TrajectorySpec> specs;
  for (int direction : {-1, 1}) {
    const double w = direction * 0.4;
    const PivotPosition& p = truth.pivots[0];
    specs.push_back({"hold_1", 1, {{{w * p.y_m(), -w * p.x_m(), w}, dtheta / 0.4}}});
  }
  const auto runs = SimulateAsoc(truth, specs, PrototypeSimulation(1, 0.0, 0.0, 0.0));
  for (int k = 0; k < 2; ++k) {
    const int direction = k == 0 ? -1 : 1;
    const RunLog& run = runs[k];
    EXPECT_NEAR(std::abs(WrapAngle(run.ground_truth.world_T_robot.back().theta -
                                   run.ground_truth.world_T_robot.front().theta)),
                dtheta, 1e-9);
    const double c1 = WheelTotal(run, 1, 0), c2 = WheelTotal(run, 1, 1);
    const double d1 = truth.castors[1].wheel_offset_m[0], d2 = truth.castors[1].wheel_offset_m[1];
    // RK4 at 400 Hz on a steady rotation: the integration error is far below 1e-9.
    EXPECT_NEAR(c1 * truth.castors[1].wheel_radius_m[0], dtheta * (cg - direction * d1), 1e-9);
    EXPECT_NEAR(c2 * truth.castors[1].wheel_radius_m[1], dtheta * (cg + direction * d2), 1e-9);
    // The held castor's wheels stay still.
    EXPECT_NEAR(WheelTotal(run, 0, 0), 0.0, 1e-12);
  }
}

// Castor dynamics checked against the closed form of a trailing castor towed in a straight line
// (the tractrix), from physics, not from the code under test: a pivot moving at speed v along
// the body's x (no body rotation) with the castor at angle theta to it has lateral velocity
// -v sin theta, so r_c theta_dot = -v sin theta, i.e. tan(theta / 2) = tan(theta0 / 2) e^(-s/r_c),
// s = v t. The wheels roll the pivot's along-track motion v cos theta less (wheel 1) or plus
// (wheel 2) d_k times the castor's turn: r_w1 c_1 = C - d_1 (theta - theta0),
// r_w2 c_2 = C + d_2 (theta - theta0), with C = int cos theta ds
// = s - r_c ln((1 + A^2) / (1 + A^2 e^(-2 s / r_c))), A = tan(theta0 / 2).
TEST(AsocModelTest, CastorDynamicsFollowTheTractrix) {
  Vehicle truth = PrototypeVehicle();
  truth.castors[0] = TestCastor();
  truth.castors[0].encoder_bias_rad = 0.2;
  const double theta0 = 2.5, v = 0.3, dt = 0.004;
  const auto dynamics = MakeCastorDynamics(truth, {theta0, 0.0, 0.0}, 0.0);
  double values[kNumChannels], wheel[2] = {0.0, 0.0};
  const CastorParameters& c = truth.castors[0];
  const double a = std::tan(theta0 / 2.0);
  for (int k = 1; k <= 500; ++k) {
    dynamics->Step(Twist{v, 0.0, 0.0}, dt, values);
    for (int j = 0; j < 2; ++j) wheel[j] += values[kWheelAChannel + j] * dt;
    dynamics->Read(values);
    const double s = v * dt * k;
    const double theta = 2.0 * std::atan(a * std::exp(-s / c.offset_m));
    ASSERT_NEAR(values[kPivotChannel] - c.encoder_bias_rad, theta, 1e-8) << "t " << k * dt;
    const double along =
        s - c.offset_m * std::log((1.0 + a * a) / (1.0 + a * a * std::exp(-2.0 * s / c.offset_m)));
    ASSERT_NEAR(wheel[0] * c.wheel_radius_m[0], along - c.wheel_offset_m[0] * (theta - theta0),
                1e-8);
    ASSERT_NEAR(wheel[1] * c.wheel_radius_m[1], along + c.wheel_offset_m[1] * (theta - theta0),
                1e-8);
  }
  EXPECT_LT(std::abs(values[kPivotChannel] - c.encoder_bias_rad), 0.01);  // it has trailed
}

int MaskCount(CastorMask mask) {
  int n = 0;
  for (int i = 0; i < kNumCastors; ++i) n += (mask >> i) & 1u;
  return n;
}

// Least squares of Eq. 15-17 solved by QR, as the reference for the closed forms.
BodyStep<double> SolveByQr(const std::array<PivotPosition, kNumCastors>& pivots, CastorMask mask,
                           double psi, const double* dx, const double* dy) {
  const int n = MaskCount(mask);
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2 * n, 3);
  Eigen::VectorXd y(2 * n);
  int row = 0;
  for (int i = 0; i < kNumCastors; ++i) {
    if (!((mask >> i) & 1u)) continue;
    const double a = psi + pivots[i].angle_rad, r = pivots[i].radius_m;
    h.row(row) << 1.0, 0.0, -r * std::sin(a);
    h.row(n + row) << 0.0, 1.0, r * std::cos(a);
    y(row) = dx[i];
    y(n + row) = dy[i];
    ++row;
  }
  const Eigen::Vector3d x = h.colPivHouseholderQr().solve(y);
  return {x(0), x(1), x(2)};
}

TEST(AsocOdometryTest, ClosedFormEq18MatchesLeastSquaresForAnyPivots) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    std::array<PivotPosition, kNumCastors> pivots;
    for (auto& q : pivots) q = {0.2 + 0.3 * std::abs(u(rng)), M_PI * u(rng)};
    double dx[3], dy[3];
    for (int i = 0; i < 3; ++i) {
      dx[i] = 0.01 * u(rng);
      dy[i] = 0.01 * u(rng);
    }
    const double psi = M_PI * u(rng);
    for (CastorMask mask : {kAllCastors, MaskExcluding(1), MaskExcluding(2), MaskExcluding(3)}) {
      const BodyStep<double> a = SolveCastGeneral(pivots, mask, psi, dx, dy);
      const BodyStep<double> b = SolveByQr(pivots, mask, psi, dx, dy);
      // Both are the same 3x3 solve; 1e-12 m is ~1e4 ulp of the 1e-2 m inputs.
      EXPECT_NEAR(a.dx_m, b.dx_m, 1e-12);
      EXPECT_NEAR(a.dy_m, b.dy_m, 1e-12);
      EXPECT_NEAR(a.dpsi_rad, b.dpsi_rad, 1e-11);
    }
  }
}

TEST(AsocOdometryTest, CentredEq22MatchesGeneralSolution) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Centred layouts: the prototype (equal R, Eq. 22 verbatim) and an unequal-R triangle whose
  // centroid is the origin.
  std::array<PivotPosition, kNumCastors> equal = PrototypeVehicle().pivots;
  const Eigen::Vector2d a(0.35, 0.05), b(-0.10, 0.30);
  const Eigen::Vector2d c = -a - b;
  std::array<PivotPosition, kNumCastors> unequal;
  int k = 0;
  for (const Eigen::Vector2d& v : {a, b, c}) unequal[k++] = {v.norm(), std::atan2(v.y(), v.x())};
  for (const auto& pivots : {equal, unequal}) {
    ASSERT_TRUE(PivotsCentred(pivots, kAllCastors));
    for (int trial = 0; trial < 100; ++trial) {
      double dx[3], dy[3];
      for (int i = 0; i < 3; ++i) {
        dx[i] = 0.01 * u(rng);
        dy[i] = 0.01 * u(rng);
      }
      const double psi = M_PI * u(rng);
      const BodyStep<double> g = SolveCastGeneral(pivots, kAllCastors, psi, dx, dy);
      const BodyStep<double> s = SolveCastCentred(pivots, kAllCastors, psi, dx, dy);
      EXPECT_NEAR(g.dx_m, s.dx_m, 1e-15);
      EXPECT_NEAR(g.dy_m, s.dy_m, 1e-15);
      EXPECT_NEAR(g.dpsi_rad, s.dpsi_rad, 1e-14);
    }
  }
  EXPECT_FALSE(PivotsCentred(equal, MaskExcluding(1)));
}

// The seam's replay with one of Doebbler's algorithms ("CAST-0", "IPEC-1", ...).
RobotModelPtr Algorithm(const std::string& name, bool redundancy_check = false) {
  AsocOdometryOptions o;
  EXPECT_TRUE(AsocOdometryOptions::Parse(name, &o)) << name;
  o.redundancy_check = redundancy_check;
  return ExampleAsocModel().WithOdometry(o);
}

std::vector<double> Parameters(const Vehicle& v) {
  const auto p = v.ToArray();
  return {p.begin(), p.end()};
}

// With the true parameters and no quantisation the odometry closes the UMBmark square up to the
// discretisation of the updates only (castor rates vary within an update). That error is second
// order in the update period: 0.7-5 mm over 6 m at 20 Hz, so at 200 Hz it must be near
// 5e-3 m / 100 = 5e-5 m; the bound is twice that. Every CAST-i and IPEC-i.
TEST(AsocOdometryTest, TrueParametersCloseTheSquare) {
  const Vehicle truth = PrototypeVehicle();
  sim::SimulationOptions options = PrototypeSimulation(5, 0.0, 0.0, 0.0);
  options.encoder_period_s = options.ground_truth_period_s = 0.005;
  options.substep_s = 0.0025;
  const auto runs = SimulateAsoc(truth, UmbmarkTrajectories(1, 1), options);
  for (int excluded = 0; excluded <= 3; ++excluded) {
    const std::string i = std::to_string(excluded);
    EXPECT_LT(UmbmarkEmax(*Algorithm("CAST-" + i), Parameters(truth), runs), 1e-4) << i;
    if (excluded > 0) {
      EXPECT_LT(UmbmarkEmax(*Algorithm("IPEC-" + i), Parameters(truth), runs), 1e-4) << i;
    }
  }
}

// Doebbler Table II: two-castor least squares and IPEC give nearly the same answer (394.6 vs
// 394.1 mm, 0.13 %). On random uncalibrated vehicles with quantised encoders the mean E_max of
// IPEC-1 and CAST-1 must agree within 2 %; a swapped wheel or a wrong sign in either would break
// the agreement.
TEST(AsocOdometryTest, TwoCastorCastAgreesWithIpec) {
  const Vehicle nominal = PrototypeVehicle();
  ParameterSpread spread;
  spread.bias_range_rad = 0.0;  // Table II: beta = 0
  std::mt19937_64 rng(11);
  double ipec = 0.0, cast1 = 0.0;
  const int kSets = 6;
  for (int s = 0; s < kSets; ++s) {
    const Vehicle truth = DrawVehicle(nominal, spread, rng);
    const auto runs = SimulateAsoc(truth, UmbmarkTrajectories(1, 1), s);
    cast1 += UmbmarkEmax(*Algorithm("CAST-1"), Parameters(nominal), runs) / kSets;
    ipec += UmbmarkEmax(*Algorithm("IPEC-1"), Parameters(nominal), runs) / kSets;
  }
  EXPECT_GT(cast1, 0.05);  // the uncalibrated error is large (Table II: ~0.4 m)
  EXPECT_NEAR(ipec / cast1, 1.0, 0.02);
}

// The redundancy check: a wheel of castor 2 whose encoder over-counts by 30 % for 3 s (a spinning
// wheel) ruins CAST-0; dropping the inconsistent castor while it slips restores the accuracy.
TEST(AsocOdometryTest, RedundancyCheckDropsSlippingCastor) {
  const Vehicle truth = PrototypeVehicle();
  const auto clean = SimulateAsoc(truth, UmbmarkTrajectories(1, 1), 6);
  std::vector<RunLog> slipping = clean;
  for (RunLog& run : slipping) {
    EncoderSamples& samples = run.encoders.samples;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const double t = run.encoders.t_s[k + 1];
      if (t > 2.0 && t <= 5.0) samples[k].value[1 * kChannelsPerCastor + kWheelAChannel] *= 1.3;
    }
  }
  const double e_plain = UmbmarkEmax(*Algorithm("CAST-0"), Parameters(truth), slipping);
  const double e_checked = UmbmarkEmax(*Algorithm("CAST-0", true), Parameters(truth), slipping);
  // 30 % of ~0.5 m of rolling, split over three castors: centimetres of error without the check.
  EXPECT_GT(e_plain, 0.02);
  EXPECT_LT(e_checked, 0.2 * e_plain);
  // Without slip the check must not drop anything with the true parameters: the same replay.
  for (const RunLog& run : clean) {
    const Pose2d a = Algorithm("CAST-0")->ReplayFinalPose(Parameters(truth).data(),
                                                          run.encoders.samples, Pose2d{});
    const Pose2d b = Algorithm("CAST-0", true)
                         ->ReplayFinalPose(Parameters(truth).data(), run.encoders.samples, Pose2d{});
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.y, b.y);
  }
}

}  // namespace
}  // namespace fitcal::asoc
