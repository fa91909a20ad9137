// Tests of the pieces added to close the loop on measured data: the
// trajectory-label split (fit/trajectory_split.h) and the translation-dependent yaw gain
// (odometry/effects.h TranslationYawGain). Recovery of the effect by diagnose on simulated data and
// the clean-data false-positive rate are covered for every registry effect by diagnose_test.cc.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fit/trajectory_split.h"
#include "io/command_failure.h"
#include "models/omni3/omni3_kinematics.h"
#include "odometry/effects.h"
#include "tests/omni3_reference_replay.h"
#include "tests/flower_scenario.h"

namespace fitcal {
namespace {

TEST(TrajectorySelector, ListOfLabelsMatchesExactly) {
  const std::vector<std::string> labels = {"circular_1643", "circular_1701", "square_1934"};
  const TrajectorySelector s("circular_1643,square_1934", labels);
  EXPECT_TRUE(s.is_list());
  EXPECT_TRUE(s.Matches("circular_1643"));
  EXPECT_TRUE(s.Matches("square_1934"));
  EXPECT_FALSE(s.Matches("circular_1701"));
}

TEST(TrajectorySelector, RegularExpressionIsSearched) {
  const std::vector<std::string> labels = {"circular_1643", "square_1934"};
  const TrajectorySelector s("^circ", labels);
  EXPECT_FALSE(s.is_list());
  EXPECT_TRUE(s.Matches("circular_1643"));
  EXPECT_FALSE(s.Matches("square_1934"));
  EXPECT_FALSE(s.Matches("x_circular"));  // anchored
}

// A pattern that makes a backtracking matcher take time exponential in the label (std::regex:
// 28 s on 30 characters, doubling with each more) is matched in one pass: this test ends.
TEST(TrajectorySelector, NoPatternBacktracks) {
  const std::string label = std::string(200, 'a') + "X";
  const TrajectorySelector s("(a+)+$", {label});
  EXPECT_FALSE(s.Matches(label));
  EXPECT_TRUE(s.Matches("aaa"));
}

TEST(TrajectorySelector, BadSelectorThrows) {
  EXPECT_THROW(TrajectorySelector("", {"a"}), std::invalid_argument);
  // Not a regular expression: a usage error (exit 2), as a malformed --train-reps is.
  EXPECT_THROW(TrajectorySelector("(unclosed", {"a"}), UsageError);
}

// omega' = omega (1 + g_x v_x + g_y v_y); translation untouched. Values chosen so that a swapped
// g_x/g_y or a wrong sign changes the result by far more than rounding (exact arithmetic here).
TEST(TranslationYawGain, ScalesYawRateByTranslation) {
  const double g[2] = {0.1, -0.3};
  double v[3] = {0.2, 0.5, 0.4};
  effects::TranslationYawGain::Body(g, effects::SampleContext{}, v);
  EXPECT_DOUBLE_EQ(v[0], 0.2);
  EXPECT_DOUBLE_EQ(v[1], 0.5);
  EXPECT_DOUBLE_EQ(v[2], 0.4 * (1.0 + 0.1 * 0.2 - 0.3 * 0.5));
  // Pure rotation and pure translation are unaffected: only the coupling matters, which the nine
  // parameters (yaw rate linear in the wheel rates) cannot produce.
  double spin[3] = {0.0, 0.0, 1.3};
  effects::TranslationYawGain::Body(g, effects::SampleContext{}, spin);
  EXPECT_DOUBLE_EQ(spin[2], 1.3);
  double straight[3] = {0.3, -0.2, 0.0};
  effects::TranslationYawGain::Body(g, effects::SampleContext{}, straight);
  EXPECT_DOUBLE_EQ(straight[2], 0.0);
  EXPECT_EQ(effects::EffectIdFromName("translation_yaw_gain"),
            effects::EffectId::kTranslationYawGain);
}

}  // namespace
}  // namespace fitcal

namespace fitcal {
namespace {

// The honest negative for the ground-truth extrinsic: a tracked point offset by e is exactly the
// nine-parameter model with R_i - e_x cos(delta_i) - e_y sin(delta_i) (the replay is linear in the
// body velocity, so the identity holds to rounding on any wheel data).
TEST(GroundTruthOffset, EqualsShiftedDistancesExactly) {
  EncoderSamples samples(3);
  samples.resize(300);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const double t = 0.01 * static_cast<double>(k);
    samples[k].dt_s = 0.01;
    samples[k].value[0] = 2.0 + std::sin(t);
    samples[k].value[1] = -1.2 + 0.5 * t;
    samples[k].value[2] = 0.7 - std::cos(2 * t);
  }
  const auto contexts = effects::MakeSampleContexts(samples);
  auto p = sim::PalacinTable5Parameters().ToArray();
  const double e[2] = {0.021, -0.013};
  const Pose2d start{0.3, -0.2, 0.5};
  std::vector<effects::ActiveEffect<double>> active = {{effects::EffectId::kGroundTruthOffset, e}};
  // The omni3 model's body step (Palacin Eq. 4) through the generic effect replay.
  const omni3::Matrix3<double> m_inv = Omni3Kinematics::Prepare(p.data());
  const auto step = [&m_inv](const double* w, double dt, double* dx, double* dy, double* dtheta) {
    Omni3Kinematics::BodyStep(m_inv, w, dt, dx, dy, dtheta);
  };
  const Pose2d with = effects::ReplayStepsWithEffects(
      step, active, samples, contexts, start, [](std::size_t, const Pose2d&, const Pose2d&) {});
  for (int i = 0; i < 3; ++i) {
    const double d = p[omni3::kAngleIndex + i];
    p[omni3::kDistanceIndex + i] -= e[0] * std::cos(d) + e[1] * std::sin(d);
  }
  const Pose2d shifted = omni3::ReplayFinalPose(p.data(), samples, start);
  // Moved ~0.02 m by the offset; equal to rounding after the shift.
  EXPECT_NEAR(with.x, shifted.x, 1e-12);
  EXPECT_NEAR(with.y, shifted.y, 1e-12);
  EXPECT_NEAR(with.theta, shifted.theta, 1e-12);
  EXPECT_FALSE(effects::Info(effects::EffectId::kGroundTruthOffset).identifiable);
}

}  // namespace
}  // namespace fitcal
