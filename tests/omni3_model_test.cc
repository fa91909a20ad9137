// Golden numbers of Palacin et al. 2022 for the omni3 model (models/omni3/omni3_parameters.h), and
// the identities the model must satisfy (closed-form vs numeric inverse, matrix <-> parameter
// round trips, autodiff vs finite-difference derivatives).

#include "models/omni3/omni3_parameters.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <random>

#include "odometry/pose2.h"
#include "models/omni/flower_trajectories.h"
#include "tests/flower_scenario.h"
#include "tests/omni3_robot.h"

namespace fitcal::omni3 {
namespace {

using ParameterArray = std::array<double, kNumParameters>;

ParameterArray Nominal() { return sim::PalacinNominalParameters().ToArray(); }
ParameterArray Table5() { return sim::PalacinTable5Parameters().ToArray(); }

// Palacin Eq. 17: M^-1 of the STE-GA5 calibration, printed to 16 digits.
Eigen::Matrix3d Eq17() {
  Eigen::Matrix3d m;
  m << -0.0892930568372762, -0.0005606566978203, 0.0867466159313470,  //
      0.0520955668635434, -0.1010213675626970, 0.0533117820461363,    //
      0.2364093797047320, 0.2341358647406650, 0.2353792947863630;
  return m;
}

const std::array<double, 3> kNominalAngles = {DegToRad(60.0), DegToRad(180.0), DegToRad(300.0)};

TEST(Omni3Model, NominalInverseMatchesEq7) {
  // Palacin Eq. 7, printed to 16 digits: agreement to 1e-12 leaves room only for the printing.
  Eigen::Matrix3d eq7;
  eq7 << -0.0854478398400646, 0.0000000000000000, 0.0854478398400646,  //
      0.0493333333333333, -0.0986666666666667, 0.0493333333333333,     //
      0.2529914529914529, 0.2529914529914529, 0.2529914529914529;
  const ParameterArray p = Nominal();
  EXPECT_LE((InverseKinematicMatrix(p.data()) - eq7).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Omni3Model, ClosedFormInverseEq6EqualsNumericInverseOfEq3) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> distance(0.15, 0.25), radius(0.03, 0.2), jitter(-0.3, 0.3);
  for (int trial = 0; trial < 200; ++trial) {
    ParameterArray p{};
    for (int i = 0; i < 3; ++i) {
      p[kDistanceIndex + i] = distance(rng);
      p[kRadiusIndex + i] = radius(rng);
      p[kAngleIndex + i] = kNominalAngles[i] + jitter(rng);
    }
    const Eigen::Matrix3d numeric = KinematicMatrix(p.data()).inverse();
    EXPECT_LE((InverseKinematicMatrix(p.data()) - numeric).cwiseAbs().maxCoeff(),
              1e-12 * numeric.cwiseAbs().maxCoeff());
  }
}

// Table A1: (alpha_deg, omega sign, rpm a, rpm b, rpm c) for R1..R12, G1..G12, B1..B12.
struct TableA1Row {
  const char* label;
  double rpm[3];
};
const TableA1Row kTableA1[] = {
    {"R1", {-19.557, 0.000, 19.557}},   {"R2", {-11.291, -11.291, 22.583}},
    {"R3", {0.000, -19.557, 19.557}},   {"R4", {11.291, -22.583, 11.291}},
    {"R5", {19.557, -19.557, 0.000}},   {"R6", {22.583, -11.291, -11.291}},
    {"R7", {19.557, 0.000, -19.557}},   {"R8", {11.291, 11.291, -22.583}},
    {"R9", {0.000, 19.557, -19.557}},   {"R10", {-11.291, 22.583, -11.291}},
    {"R11", {-19.557, 19.557, 0.000}},  {"R12", {-22.583, 11.291, 11.291}},
    {"G1", {-15.154, 4.404, 23.961}},   {"G2", {-6.888, -6.888, 26.986}},
    {"G3", {4.404, -15.154, 23.961}},   {"G4", {15.695, -18.179, 15.695}},
    {"G5", {23.961, -15.154, 4.404}},   {"G6", {26.986, -6.888, -6.888}},
    {"G7", {23.961, 4.404, -15.154}},   {"G8", {15.695, 15.695, -18.179}},
    {"G9", {4.404, 23.961, -15.154}},   {"G10", {-6.888, 26.986, -6.888}},
    {"G11", {-15.154, 23.961, 4.404}},  {"G12", {-18.179, 15.695, 15.695}},
    {"B1", {-23.961, -4.404, 15.154}},  {"B2", {-15.695, -15.695, 18.179}},
    {"B3", {-4.404, -23.961, 15.154}},  {"B4", {6.888, -26.986, 6.888}},
    {"B5", {15.154, -23.961, -4.404}},  {"B6", {18.179, -15.695, -15.695}},
    {"B7", {15.154, -4.404, -23.961}},  {"B8", {6.888, 6.888, -26.986}},
    {"B9", {-4.404, 15.154, -23.961}},  {"B10", {-15.695, 18.179, -15.695}},
    {"B11", {-23.961, 15.154, -4.404}}, {"B12", {-26.986, 6.888, 6.888}},
};

TEST(Omni3Model, WheelRatesOfAllTableA1Rows) {
  const auto commands = sim::FlowerTrajectories();
  ASSERT_EQ(commands.size(), std::size(kTableA1));
  const ParameterArray p = Nominal();
  const double rad_s_to_rpm = 60.0 / (2.0 * M_PI);
  for (std::size_t row = 0; row < commands.size(); ++row) {
    const auto& c = commands[row];
    ASSERT_EQ(c.label, kTableA1[row].label);
    const Eigen::Vector3d w =
        WheelRatesForCommand(p.data(), c.speed_m_s, c.alpha_rad, c.omega_rad_s) * rad_s_to_rpm;
    for (int i = 0; i < 3; ++i) {
      // Printed to 0.001 rpm: a correct model is within the rounding, 0.0005 rpm (+ 1e-9).
      EXPECT_NEAR(w[i], kTableA1[row].rpm[i], 0.0005 + 1e-9) << c.label << " wheel " << i;
    }
  }
}

TEST(Omni3Model, Table5ParametersRoundTripThroughTheMatrix) {
  const ParameterArray p = Table5();
  const Parameters back =
      ParametersFromInverseKinematicMatrix(InverseKinematicMatrix(p.data()), kNominalAngles);
  const ParameterArray q = back.ToArray();
  for (int k = 0; k < kNumParameters; ++k) EXPECT_NEAR(q[k], p[k], 1e-12) << k;
  // And via M (Eq. 3) directly.
  const ParameterArray r =
      ParametersFromKinematicMatrix(KinematicMatrix(p.data()), kNominalAngles).ToArray();
  for (int k = 0; k < kNumParameters; ++k) EXPECT_NEAR(r[k], p[k], 1e-12) << k;
}

TEST(Omni3Model, Eq17MatrixRoundTripsAndIsNotTable5) {
  // Eq. 17 and Table 5 disagree in the paper (seeds/README.md): treat them as two test vectors.
  const Parameters from_eq17 = ParametersFromInverseKinematicMatrix(Eq17(), kNominalAngles);
  const ParameterArray p = from_eq17.ToArray();
  EXPECT_LE((InverseKinematicMatrix(p.data()) - Eq17()).cwiseAbs().maxCoeff(), 1e-13);
  // The parameters that Eq. 17 implies, as checked numerically in seeds/README.md (printed to
  // 4 decimals in m, 2 in deg).
  const double r[3] = {0.1530, 0.1533, 0.1529};
  const double d_deg[3] = {60.59, 180.47, 299.93};
  const double R[3] = {0.2098, 0.2235, 0.2174};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(from_eq17.radius_m[i], r[i], 0.00005 + 1e-9) << i;
    EXPECT_NEAR(RadToDeg(from_eq17.angle_rad[i]), d_deg[i], 0.005 + 1e-9) << i;
    EXPECT_NEAR(from_eq17.distance_m[i], R[i], 0.00005 + 1e-9) << i;
  }
  // Table 5 gives a different matrix: entries differ by up to 0.003.
  const ParameterArray t5 = Table5();
  const double max_diff = (InverseKinematicMatrix(t5.data()) - Eq17()).cwiseAbs().maxCoeff();
  EXPECT_GT(max_diff, 0.002);
  EXPECT_LT(max_diff, 0.004);
}

TEST(Omni3Model, Eq17RoundsToTable4SteGa5) {
  // Table 4, STE GA5 row, printed to 4 decimals: Eq. 17 must round to it.
  Eigen::Matrix3d table4;
  table4 << -0.0893, -0.0006, 0.0867,  //
      0.0521, -0.1010, 0.0533,         //
      0.2364, 0.2341, 0.2354;
  EXPECT_LE((Eq17() - table4).cwiseAbs().maxCoeff(), 0.00005 + 1e-12);
}

// d(M^-1)/d(parameter) by autodiff through Eq. 6.
Eigen::Matrix3d InverseDerivative(const ParameterArray& p, int k) {
  using Jet = ceres::Jet<double, 1>;
  std::array<Jet, kNumParameters> pj;
  for (int i = 0; i < kNumParameters; ++i) pj[i] = Jet(p[i]);
  pj[k].v[0] = 1.0;
  const Matrix3<Jet> m = InverseKinematicMatrix(pj.data());
  Eigen::Matrix3d d;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) d(r, c) = m(r, c).v[0];
  return d;
}

TEST(Omni3Model, AutodiffDerivativesMatchCentralDifferences) {
  const ParameterArray p = Table5();
  for (int k = 0; k < kNumParameters; ++k) {
    const double h = 1e-6;
    ParameterArray plus = p, minus = p;
    plus[k] += h;
    minus[k] -= h;
    const Eigen::Matrix3d numeric =
        (InverseKinematicMatrix(plus.data()) - InverseKinematicMatrix(minus.data())) / (2 * h);
    // Central differences: truncation O(h^2) ~ 1e-12 times third derivatives (< 100 here),
    // rounding ~ 1e-16 / 1e-6 = 1e-10.
    EXPECT_LE((InverseDerivative(p, k) - numeric).cwiseAbs().maxCoeff(), 1e-8) << k;
  }
}

TEST(Omni3Model, SensitivitiesMatchTables1To3) {
  // Palacin Tables 1-3: dM^-1/dR_i and dM^-1/dr_i (per metre), dM^-1/ddelta_i per radian, at the
  // nominal parameters, printed to 4 decimals.
  const ParameterArray p = Nominal();
  struct Golden {
    int parameter;
    double m[9];
  };
  const Golden golden[] = {
      {kDistanceIndex + 0,
       {0.1461, 0.1461, 0.1461, -0.0843, -0.0843, -0.0843, -0.4325, -0.4325, -0.4325}},
      {kRadiusIndex + 0, {-0.5774, 0, 0, 0.3333, 0, 0, 1.7094, 0, 0}},
      {kAngleIndex + 0, {0, 0.0493, -0.0493, 0, -0.0285, 0.0285, 0, -0.1461, 0.1461}},
      {kDistanceIndex + 1, {0, 0, 0, 0.1687, 0.1687, 0.1687, -0.4325, -0.4325, -0.4325}},
      {kRadiusIndex + 1, {0, 0, 0, 0, -0.6667, 0, 0, 1.7094, 0}},
      {kAngleIndex + 1, {0, 0, 0, -0.0570, 0, 0.0570, 0.1461, 0, -0.1461}},
      {kDistanceIndex + 2,
       {-0.1461, -0.1461, -0.1461, -0.0843, -0.0843, -0.0843, -0.4325, -0.4325, -0.4325}},
      {kRadiusIndex + 2, {0, 0, 0.5774, 0, 0, 0.3333, 0, 0, 1.7094}},
      {kAngleIndex + 2, {-0.0493, 0.0493, 0, -0.0285, 0.0285, 0, -0.1461, 0.1461, 0}},
  };
  for (const Golden& g : golden) {
    const Eigen::Matrix3d d = InverseDerivative(p, g.parameter);
    for (int e = 0; e < 9; ++e) {
      EXPECT_NEAR(d(e / 3, e % 3), g.m[e], 0.00005 + 1e-9)
          << "parameter " << g.parameter << " entry " << e;
    }
  }
}

TEST(Omni3Model, WrapAngleMapsIntoHalfOpenInterval) {
  for (double a : {-10.0, -M_PI, -1.0, 0.0, 1.0, M_PI - 1e-12, M_PI, 7.0, 100.0}) {
    const double w = WrapAngle(a);
    EXPECT_GE(w, -M_PI);
    EXPECT_LT(w, M_PI);
    EXPECT_NEAR(std::remainder(w - a, 2 * M_PI), 0.0, 1e-12) << a;
  }
}

}  // namespace
}  // namespace fitcal::omni3
