// Tests of the effect library (odometry/effects.h), the effect fit's building blocks
// (fit/effect_fit.h), the tail probabilities (fit/statistics.h) and the robot YAML's
// `effects:` list.
#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "diagnosis/diagnose.h"
#include "fit/effect_fit.h"
#include "io/input_error.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_kinematics.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/omni3_reference_replay.h"
#include "tests/flower_scenario.h"
#include "fit/statistics.h"
#include "tests/test_paths.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace {

using effects::EffectId;

// A curved run with start/stop transients and both wheel directions: 4 s at 100 Hz.
EncoderSamples TestSamples() {
  EncoderSamples s(3);
  s.resize(400);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double t = 0.01 * static_cast<double>(k);
    const double ramp = std::min(1.0, t / 0.3) * std::min(1.0, (4.0 - t) / 0.3);
    s[k].dt_s = 0.01;
    s[k].value[0] = 2.0 * ramp;
    s[k].value[1] = -1.2 * ramp;
    s[k].value[2] = 0.4 * ramp + 0.3 * std::sin(t);
  }
  return s;
}

template <typename T>
Pose2<T> Replay(const T* p, EffectId id, const T* q, const EncoderSamples& samples,
                const std::vector<effects::SampleContext>& contexts) {
  std::vector<effects::ActiveEffect<T>> active = {{id, q}};
  // The omni3 model's body step (Palacin Eq. 4, dt M^-1 w) through the generic effect replay.
  const auto m_inv = Omni3Kinematics::Prepare(p);
  const auto step = [&m_inv](const T* w, double dt, T* dx, T* dy, T* dtheta) {
    Omni3Kinematics::BodyStep(m_inv, w, dt, dx, dy, dtheta);
  };
  return effects::ReplayStepsWithEffects(step, active, samples, contexts,
                                         Pose2<T>{T(0.3), T(-0.2), T(0.5)},
                                         [](std::size_t, const Pose2<T>&, const Pose2<T>&) {});
}

TEST(EffectTable, OrderMatchesIdsAndNamesRoundTrip) {
  for (int k = 0; k < effects::kNumEffects; ++k) {
    const effects::EffectInfo& info = effects::EffectTable()[k];
    EXPECT_EQ(static_cast<int>(info.id), k);
    EXPECT_EQ(effects::EffectIdFromName(info.name), info.id);
    for (int j = 0; j < info.num_parameters; ++j) {
      EXPECT_LE(info.lower[j], 0.0) << info.name;  // 0 is the neutral value, inside the box
      EXPECT_GE(info.upper[j], 0.0) << info.name;
      EXPECT_TRUE(info.typical[j] > info.lower[j] && info.typical[j] < info.upper[j]) << info.name;
    }
  }
  EXPECT_THROW(effects::EffectIdFromName("gremlins"), std::invalid_argument);
}

// Every effect at its neutral value (0) reproduces the plain replay (Palacin Eq. 4).
TEST(EffectReplay, NeutralEffectsEqualPlainReplay) {
  const EncoderSamples samples = TestSamples();
  const auto contexts = effects::MakeSampleContexts(samples);
  const auto p = sim::PalacinTable5Parameters().ToArray();
  const Pose2d start{0.3, -0.2, 0.5};
  const Pose2d plain = omni3::ReplayFinalPose(p.data(), samples, start);
  const double zero[2] = {0.0, 0.0};
  for (int k = 0; k < effects::kNumEffects; ++k) {
    const Pose2d with = Replay(p.data(), static_cast<EffectId>(k), zero, samples, contexts);
    EXPECT_NEAR(with.x, plain.x, 1e-12) << effects::EffectTable()[k].name;
    EXPECT_NEAR(with.y, plain.y, 1e-12);
    EXPECT_NEAR(with.theta, plain.theta, 1e-12);
  }
}

// Autodiff through every effect agrees with central differences (the Ceres fit relies on it).
TEST(EffectReplay, JetDerivativesMatchCentralDifferences) {
  using Jet = ceres::Jet<double, 2>;
  const EncoderSamples samples = TestSamples();
  const auto contexts = effects::MakeSampleContexts(samples);
  const auto p = sim::PalacinTable5Parameters().ToArray();
  std::array<Jet, 9> pj;
  for (int i = 0; i < 9; ++i) pj[i] = Jet(p[i]);
  for (const auto& info : effects::EffectTable()) {
    if (info.id == EffectId::kTimeOffset) continue;  // acts in the residual, not in the replay
    for (int j = 0; j < info.num_parameters; ++j) {
      Jet q[2] = {Jet(info.typical[0]), Jet(info.typical[1])};
      q[j].v[0] = 1.0;
      const Pose2<Jet> jet = Replay(pj.data(), info.id, q, samples, contexts);
      const double h = 1e-6 * std::max(1.0, std::abs(info.typical[j]));
      double qp[2] = {info.typical[0], info.typical[1]};
      double qm[2] = {info.typical[0], info.typical[1]};
      qp[j] += h;
      qm[j] -= h;
      const Pose2d a = Replay(p.data(), info.id, qp, samples, contexts);
      const Pose2d b = Replay(p.data(), info.id, qm, samples, contexts);
      // Central differences are exact to O(h^2) and rounding ~1e-16 / h = 1e-10 (relative).
      const double tol = 1e-6 * (1.0 + std::abs(jet.x.v[0]) + std::abs(jet.y.v[0]));
      EXPECT_NEAR(jet.x.v[0], (a.x - b.x) / (2 * h), tol) << info.name;
      EXPECT_NEAR(jet.y.v[0], (a.y - b.y) / (2 * h), tol) << info.name;
      EXPECT_NEAR(jet.theta.v[0], (a.theta - b.theta) / (2 * h), tol) << info.name;
    }
  }
}

// The honest negative, exactly: an encoder clock scale s is a common radius scale (1 + s).
TEST(EffectReplay, ClockScaleEqualsCommonRadiusScale) {
  const EncoderSamples samples = TestSamples();
  const auto contexts = effects::MakeSampleContexts(samples);
  auto p = sim::PalacinTable5Parameters().ToArray();
  const double s[1] = {0.013};
  const Pose2d with = Replay(p.data(), EffectId::kEncoderClockScale, s, samples, contexts);
  for (int i = 0; i < 3; ++i) p[omni3::kRadiusIndex + i] *= 1.0 + s[0];
  const Pose2d scaled = omni3::ReplayFinalPose(p.data(), samples, Pose2d{0.3, -0.2, 0.5});
  EXPECT_NEAR(with.x, scaled.x, 1e-12);
  EXPECT_NEAR(with.y, scaled.y, 1e-12);
  EXPECT_NEAR(with.theta, scaled.theta, 1e-12);
}

// Backlash eats exactly beta of each wheel's encoder angle when the wheel turns one way.
TEST(EffectTransforms, BacklashLosesBetaOfEachWheel) {
  const EncoderSamples samples = TestSamples();
  const auto contexts = effects::MakeSampleContexts(samples);
  const double beta[1] = {0.07};
  effects::EffectMemory<double> memory;
  double measured = 0.0, transmitted = 0.0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    double w[3] = {samples[k].value[0], samples[k].value[1], samples[k].value[2]};
    effects::Backlash::Rates(beta, contexts[k], w, &memory);
    measured += samples[k].value[0] * samples[k].dt_s;
    transmitted += w[0] * samples[k].dt_s;
  }
  EXPECT_NEAR(measured - transmitted, beta[0], 1e-12);
}

// Gear play is crossed again on every reversal: a wheel that turns 1 rad forward, 0.5 rad back
// and 0.3 rad forward again transmits 1 - beta, -(0.5 - 2 beta), 0.3 - 2 beta (the play
// operator, worked by hand); a back-and-forth smaller than the play (2 beta) transmits nothing.
TEST(EffectTransforms, BacklashCrossesThePlayOnEveryReversal) {
  const double beta[1] = {0.05};
  const auto transmitted = [&](const std::vector<double>& moves) {
    EncoderSamples samples(1);
    for (double move : moves) {
      const double rate[1] = {move / 0.01};
      for (int k = 0; k < 100; ++k) samples.push_back(0.0001, rate);
    }
    const auto contexts = effects::MakeSampleContexts(samples);
    effects::EffectMemory<double> memory;
    std::vector<double> per_move;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      double w[1] = {samples[k].value[0]};
      effects::Backlash::Rates(beta, contexts[k], w, &memory);
      if (k % 100 == 0) per_move.push_back(0.0);
      per_move.back() += w[0] * samples[k].dt_s;
    }
    return per_move;
  };
  const std::vector<double> three = transmitted({1.0, -0.5, 0.3});
  EXPECT_NEAR(three[0], 1.0 - beta[0], 1e-12);
  EXPECT_NEAR(three[1], -(0.5 - 2.0 * beta[0]), 1e-12);
  EXPECT_NEAR(three[2], 0.3 - 2.0 * beta[0], 1e-12);
  const std::vector<double> wiggle = transmitted({1.0, -0.08, 0.08});
  EXPECT_NEAR(wiggle[1], 0.0, 1e-12);
  EXPECT_NEAR(wiggle[2], 0.0, 1e-12);
}

// A wheel pair's turn fraction (SampleContext) and the pivot yaw gain that scales the yaw by it.
TEST(EffectTransforms, PivotYawGainScalesTheYawByTheWheelPairsTurnFraction) {
  EncoderSamples samples(2);
  const double straight[2] = {3.0, 3.0}, arc[2] = {1.2, 0.8}, pivot[2] = {-2.0, 2.0};
  const double rest[2] = {0.0, 0.0};
  for (const double* v : {straight, arc, pivot, rest}) samples.push_back(0.02, v);
  const auto contexts = effects::MakeSampleContexts(samples, 0x3u);
  EXPECT_DOUBLE_EQ(contexts[0].turn_fraction, 0.0);
  EXPECT_DOUBLE_EQ(contexts[1].turn_fraction, 0.4 / 2.0);  // b / (2 R) of the arc
  EXPECT_DOUBLE_EQ(contexts[2].turn_fraction, 1.0);
  EXPECT_DOUBLE_EQ(contexts[3].turn_fraction, 0.0);
  // Only a pair of wheel channels has one: a tricycle's wheel + steering angle has none.
  EXPECT_DOUBLE_EQ(effects::MakeSampleContexts(samples, 0x1u)[1].turn_fraction, 0.0);

  const double g[1] = {0.01};
  double v[3] = {0.2, 0.0, 0.5};
  effects::PivotYawGain::Body(g, contexts[1], v);
  EXPECT_DOUBLE_EQ(v[0], 0.2);
  EXPECT_DOUBLE_EQ(v[2], 0.5 * (1.0 + 0.01 * 0.2));
}

TEST(EffectTransforms, SpeedSlipAndDirectionRadiusAsDocumented) {
  effects::SampleContext c;
  double w[3] = {2.0, -1.0, 0.0};
  const double k[1] = {0.01};
  effects::WheelSpeedSlip::Rates(k, c, w);
  EXPECT_DOUBLE_EQ(w[0], 2.0 * (1.0 - 0.02));
  EXPECT_DOUBLE_EQ(w[1], -1.0 * (1.0 - 0.01));
  double v[3] = {2.0, -1.0, 0.5};
  const double a[1] = {0.02};
  effects::DirectionRadius::Rates(a, c, v);
  EXPECT_DOUBLE_EQ(v[0], 2.0 * 1.02);   // forward: larger radius
  EXPECT_DOUBLE_EQ(v[1], -1.0 * 0.98);  // backward: smaller
}

// The smoothed acceleration of a linear ramp is its slope (away from the ends).
TEST(SampleContexts, AccelerationOfARamp) {
  EncoderSamples s(3);
  s.resize(100);
  for (std::size_t k = 0; k < s.size(); ++k) {
    s[k].dt_s = 0.01;
    s[k].value[0] = 5.0 * 0.01 * (static_cast<double>(k) + 0.5);  // 5 rad/s^2
  }
  const auto c = effects::MakeSampleContexts(s);
  EXPECT_NEAR(c[50].accel_rad_s2(0), 5.0, 1e-9);
  EXPECT_NEAR(c[50].angle_rad[0], 0.5 * 5.0 * 0.5 * 0.5, 1e-12);
}

// Up to kMaxEffectChannels channels (an ASOC base of four castors); one more is refused.
TEST(SampleContexts, TwelveChannelsAndNoMore) {
  for (int channels : {9, effects::kMaxEffectChannels}) {
    EncoderSamples s(channels);
    s.resize(10);
    for (std::size_t k = 0; k < s.size(); ++k) {
      s[k].dt_s = 0.01;
      for (int i = 0; i < channels; ++i) s[k].value[i] = 1.0 + i;
    }
    const auto c = effects::MakeSampleContexts(s);
    // Channel i turns at 1 + i rad/s: its angle at the start of interval 5 is 0.05 (1 + i) rad.
    EXPECT_NEAR(c[5].angle_rad[channels - 1], 0.05 * channels, 1e-12);
  }
  EncoderSamples too_many(effects::kMaxEffectChannels + 1);
  too_many.resize(2);
  EXPECT_THROW(effects::MakeSampleContexts(too_many), std::invalid_argument);
}

// Golden values: R's pt(2.228, 10, lower = FALSE) = 0.02500 and pf(3.708, 3, 10, lower = FALSE)
// = 0.05000 (the tabulated 97.5% t and 95% F quantiles).
TEST(Statistics, TailsMatchTables) {
  EXPECT_NEAR(stats::StudentTUpperTail(2.228, 10), 0.025, 1e-4);
  EXPECT_NEAR(stats::StudentTUpperTail(-2.228, 10), 0.975, 1e-4);
  EXPECT_NEAR(stats::StudentTUpperTail(0.0, 5), 0.5, 1e-12);
  EXPECT_NEAR(stats::FUpperTail(3.708, 3, 10), 0.05, 1e-4);
  EXPECT_NEAR(stats::FUpperTail(1.0, 200, 200), 0.5, 0.01);
  EXPECT_NEAR(stats::RegularizedIncompleteBeta(2, 3, 0.4), 0.5248, 1e-4);  // 1 - pbeta(0.4,2,3)
}

// By hand: base (2, 4, 8) against candidate (1, 2, 2) gives log ratios a, a, 2a (a = ln 2), mean
// 4a/3, variance a^2/3 on 2 df, standard error a/3: t = 4 exactly, and on 2 df
// P(T > t) = (1 - t / sqrt(t^2 + 2)) / 2 = 0.0285955.
TEST(Statistics, PairedLogRatioTestByHand) {
  const stats::PairedTest test = stats::PairedLogRatioTest({2.0, 4.0, 8.0}, {1.0, 2.0, 2.0});
  EXPECT_NEAR(test.t, 4.0, 1e-12);
  EXPECT_NEAR(test.p, 0.5 * (1.0 - 4.0 / std::sqrt(18.0)), 1e-9);
  // Worse candidates are not better: the upper tail of a negative t.
  EXPECT_GT(stats::PairedLogRatioTest({1.0, 2.0, 2.0}, {2.0, 4.0, 8.0}).p, 0.9);
  EXPECT_EQ(stats::PairedLogRatioTest({1.0}, {0.5}).p, 1.0);  // one run tests nothing
}

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("fitcal_effects_test_" + name)).string();
}

// The calibrated YAML carries the effects and gives them back.
TEST(RobotYamlEffects, RoundTripAndBadInput) {
  Omni3Robot robot = ReadOmni3Robot(FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml");
  effects::EffectValue slip;
  slip.id = EffectId::kWheelSpeedSlip;
  slip.value[0] = 0.0123;
  slip.sigma[0] = 0.0004;
  effects::EffectValue slope;
  slope.id = EffectId::kFloorSlope;
  slope.value = {0.004, -0.002};
  robot.effects = {slip, slope};
  const std::string path = TempPath("robot.yaml");
  {
    std::ofstream f(path);
    const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(robot);
    f << model->RobotYaml(model->robot().nominal, "");
  }
  const Omni3Robot back = ReadOmni3Robot(path);
  ASSERT_EQ(back.effects.size(), 2u);
  EXPECT_EQ(back.effects[0].id, EffectId::kWheelSpeedSlip);
  EXPECT_DOUBLE_EQ(back.effects[0].value[0], 0.0123);
  EXPECT_DOUBLE_EQ(back.effects[0].sigma[0], 0.0004);
  EXPECT_EQ(back.effects[1].id, EffectId::kFloorSlope);
  EXPECT_DOUBLE_EQ(back.effects[1].value[1], -0.002);

  const auto expect_bad = [&](const std::string& effects_text, const std::string& what) {
    const RobotModelPtr model = ReadRobotModelFile(FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml");
    std::string yaml = model->RobotYaml(model->robot().nominal, "");
    yaml += "effects:\n" + effects_text;
    {
      std::ofstream f(path);
      f << yaml;
    }
    try {
      ReadOmni3Robot(path);
      ADD_FAILURE() << "accepted " << effects_text;
    } catch (const io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_bad("  - {name: gremlins, x: 1}\n", "unknown effect");
  expect_bad("  - {name: backlash, backlash_rad: 2.0}\n", "outside");
  expect_bad("  - {name: backlash, backlash_rad: 0.1, colour: red}\n", "colour");
  expect_bad("  - {name: floor_slope, creep_x_m_s: 0.01}\n", "creep_y_m_s");
  expect_bad("  - {name: acceleration_slip, traction_s2_per_rad: 0.01}\n", "slip_s2_per_rad");

  // A calibration written before acceleration_slip gained its traction term still loads: the
  // term reads as 0, the effect as it was then.
  {
    const RobotModelPtr model = ReadRobotModelFile(FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml");
    std::ofstream f(path);
    f << model->RobotYaml(model->robot().nominal, "")
      << "effects:\n  - {name: acceleration_slip, slip_s2_per_rad: 0.012}\n";
  }
  const Omni3Robot old = ReadOmni3Robot(path);
  ASSERT_EQ(old.effects.size(), 1u);
  EXPECT_DOUBLE_EQ(old.effects[0].value[0], 0.012);
  EXPECT_EQ(old.effects[0].value[1], 0.0);
  std::filesystem::remove(path);
}

// The verdict diagnose prints for a fitted candidate (CandidateVerdict) reports the held-out test
// as it came out: a p below its threshold is "significant" whatever rule then decides, and the
// deciding rule is named. The case of the acceleration slip that was printed "not significant
// (p 2.8e-09 vs 0.0011)", and every other way a significant candidate can be turned down.
TEST(DiagnoseVerdict, SaysTheTestItReportsAndTheRuleThatDecided) {
  constexpr double kThreshold = 0.0011, kRule = 0.5;
  CandidateResult c;
  c.p_value = 2.8e-9;
  c.significant = true;
  c.improves = true;
  c.bic_falls = true;
  c.mean_improvement = 4e-5;
  c.delta_bic = -12.0;
  c.explained_fraction = 0.31;
  c.explains = false;
  const auto verdict = [&] { return CandidateVerdict(c, kThreshold, kRule, "wheel_speed_slip"); };
  EXPECT_EQ(verdict(),
            "significant (p 2.8e-09 < 0.0011) but explains only 31 % of the lack of fit "
            "(rule: >= 50 %)");
  // Just below the rule reads below it (rounded down), not as the rule itself.
  c.explained_fraction = 0.4996;
  EXPECT_NE(verdict().find("explains only 49 %"), std::string::npos) << verdict();
  c.explained_fraction = 0.8;
  c.explains = true;
  EXPECT_EQ(verdict(),
            "significant (p 2.8e-09 < 0.0011) but wheel_speed_slip lowers the held-out error "
            "more (rule: the largest mean d is accepted)");
  c.accepted = true;
  EXPECT_EQ(verdict(),
            "ACCEPTED: significant (p 2.8e-09 < 0.0011), explains 80 % of the lack of fit "
            "(rule: >= 50 %)");
  c.accepted = false;
  c.bic_falls = false;
  c.delta_bic = 4.0;
  EXPECT_EQ(verdict(),
            "significant (p 2.8e-09 < 0.0011) but BIC on the training runs rises by 4.0 "
            "(rule: dBIC < 0)");
  c.improves = false;
  c.mean_improvement = -2e-7;
  EXPECT_EQ(verdict(),
            "significant (p 2.8e-09 < 0.0011) but the mean held-out error does not fall "
            "(mean d -2e-07; rule: mean d > 0)");
  c.significant = false;
  c.p_value = 0.22;
  EXPECT_EQ(verdict(), "not significant (p 0.22 >= 0.0011)");
}

}  // namespace
}  // namespace fitcal
