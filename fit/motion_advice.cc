#include "fit/motion_advice.h"

#include <algorithm>
#include <cmath>

namespace fitcal {
namespace {

constexpr double kSpeed_m_s = 0.3;
constexpr double kTurnRate_rad_s = 0.6;
constexpr double kSamplePeriod_s = 0.02;

// The exact end of a constant twist held for t from the origin (body frame rotating at omega).
Pose2d EndOfTwist(const Twist& v, double t) {
  const double theta = v.omega_rad_s * t;
  if (std::abs(theta) < 1e-12) return Pose2d{v.vx_m_s * t, v.vy_m_s * t, 0.0};
  const double s = std::sin(theta) / v.omega_rad_s;
  const double c = (1.0 - std::cos(theta)) / v.omega_rad_s;
  return Pose2d{s * v.vx_m_s - c * v.vy_m_s, c * v.vx_m_s + s * v.vy_m_s, theta};
}

}  // namespace

std::vector<StandardMotion> StandardMotions() {
  const double quarter_circle_s = (M_PI / 2.0) / (kSpeed_m_s / 1.0);  // radius 1 m
  return {
      {"a straight run of 2 m", {kSpeed_m_s, 0.0, 0.0}, 2.0 / kSpeed_m_s},
      {"a sideways run of 2 m", {0.0, kSpeed_m_s, 0.0}, 2.0 / kSpeed_m_s},
      {"a half turn on the spot", {0.0, 0.0, kTurnRate_rad_s}, M_PI / kTurnRate_rad_s},
      {"a quarter circle of 1 m radius to the left", {kSpeed_m_s, 0.0, kSpeed_m_s},
       quarter_circle_s},
      {"a quarter circle of 1 m radius to the right", {kSpeed_m_s, 0.0, -kSpeed_m_s},
       quarter_circle_s},
  };
}

bool RunOfMotion(const RobotModelInterface& model, const std::vector<double>& p,
                 const StandardMotion& motion, AlignedRun* run) {
  const int channels = model.robot().NumChannels();
  std::vector<double> values(static_cast<std::size_t>(channels));
  if (!model.ChannelsForTwist(p.data(), motion.twist, values.data())) return false;
  *run = AlignedRun{};
  run->id = run->trajectory = motion.words;
  run->samples = EncoderSamples(channels);
  const int n = std::max(1, static_cast<int>(std::ceil(motion.duration_s / kSamplePeriod_s)));
  for (int k = 0; k < n; ++k) run->samples.push_back(motion.duration_s / n, values.data());
  run->t_final_s = motion.duration_s;
  run->final_ground_truth = EndOfTwist(motion.twist, motion.duration_s);
  return true;
}

std::vector<MotionThatDetermines> MotionsThatDetermine(const UndeterminedDirection& d,
                                                       const RobotModelInterface& model,
                                                       const std::vector<double>& p,
                                                       const ResidualWeights& weights) {
  // Information adds over runs: 1 / f_k^2 = 1 / f^2 + k g with g one run's own.
  const double data_information =
      1.0 / std::max(d.posterior_fraction * d.posterior_fraction, 1e-300);
  const double needed = 1.0 / (kMaxPosteriorFraction * kMaxPosteriorFraction) - data_information;
  std::vector<MotionThatDetermines> out;
  for (const StandardMotion& motion : StandardMotions()) {
    AlignedRun run;
    if (!RunOfMotion(model, p, motion, &run)) continue;
    const double f1 = PosteriorFractionWith(d, {run}, model, p, weights);
    const double per_run = 1.0 / (f1 * f1) - data_information;
    if (!(per_run > 0.0)) continue;
    const double runs = std::ceil(std::max(needed, 0.0) / per_run);
    if (runs <= kMaxAdvisedRuns) out.push_back({motion.words, std::max(1, static_cast<int>(runs))});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.runs < b.runs; });
  return out;
}

std::string MotionAdviceLine(const std::vector<MotionThatDetermines>& motions) {
  if (motions.empty()) {
    return "to determine it: no short standard motion judged at its end does; record longer runs "
           "with a dense ground truth and fit their tracks (--residuals track)";
  }
  std::string line = "to determine it, add to the training runs ";
  const std::size_t listed = std::min<std::size_t>(motions.size(), 2);
  for (std::size_t i = 0; i < listed; ++i) {
    const MotionThatDetermines& m = motions[i];
    line += (i == 0 ? "" : ", or ") + m.words + " (" + std::to_string(m.runs) +
            (m.runs == 1 ? " run" : " runs") + ")";
  }
  return line + ", judged at its end";
}

}  // namespace fitcal
