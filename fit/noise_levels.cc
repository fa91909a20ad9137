#include "fit/noise_levels.h"

#include <ceres/cost_function.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "odometry/pose2.h"

namespace fitcal {

namespace {

// Weighted sums of squares of one component pair (position, heading) and the runs behind them.
struct ComponentSums {
  double position = 0.0;
  double heading = 0.0;
  int runs = 0;
};

// Adds the residuals of `cost` at `parameters` to `sums`; false when the replay fails.
bool AddResiduals(const ceres::CostFunction& cost, const double* const* parameters,
                  ComponentSums* sums) {
  std::vector<double> r(cost.num_residuals());
  if (!cost.Evaluate(parameters, r.data(), nullptr)) return false;
  for (std::size_t i = 0; i + 2 < r.size(); i += 3) {
    sums->position += r[i] * r[i] + r[i + 1] * r[i + 1];
    sums->heading += r[i + 2] * r[i + 2];
  }
  ++sums->runs;
  return true;
}

// A sigma that stays usable as a weight on noise-free data.
constexpr double kSmallestSigma = 1e-9;

double SigmaOf(double sum, double count) {
  return std::max(kSmallestSigma, std::sqrt(sum / count));
}

double Ratio(double a, double b) { return a / std::max(b, kSmallestSigma); }

}  // namespace

NoiseLevels EstimateNoiseLevels(const std::vector<AlignedRun>& training,
                                const RobotModelInterface& model, const std::vector<double>& p,
                                const std::vector<double>& clock_offsets_s,
                                const TrackFitData& track, bool final_poses, int num_estimated) {
  NoiseLevels out;
  out.with_final_poses = final_poses;
  // Unit weights and no Huber: the residuals in metres and radians, each run's checkpoints
  // weighed 1/sqrt(K) as in the fit.
  TrackResidualOptions plain = track.options;
  plain.huber_scale = std::sqrt(std::numeric_limits<double>::max());
  ComponentSums tracks, finals;
  int residuals = 0;
  for (std::size_t i = 0; i < training.size() && i < track.runs.size(); ++i) {
    const TrackCheckpoints& run = track.runs[i];
    if (!run.segments.empty()) {
      const std::unique_ptr<ceres::CostFunction> cost(
          TrackResidual::Create(run, model, ResidualWeights{}, plain));
      const double* parameters[] = {p.data(), &clock_offsets_s[run.clock_group]};
      if (!AddResiduals(*cost, parameters, &tracks)) return out;
      residuals += cost->num_residuals();
    }
    if (!final_poses) continue;
    const std::unique_ptr<ceres::CostFunction> cost(
        model.FinalPoseCost(training[i], ResidualWeights{}));
    const double* parameters[] = {p.data()};
    if (!AddResiduals(*cost, parameters, &finals)) return out;
    residuals += cost->num_residuals();
  }
  const double redundancy = 1.0 - static_cast<double>(num_estimated) / std::max(1, residuals);
  if (tracks.runs == 0 || !(redundancy > 0.0)) return out;
  out.track_position_m = SigmaOf(tracks.position, 2.0 * tracks.runs * redundancy);
  out.track_heading_rad = SigmaOf(tracks.heading, tracks.runs * redundancy);
  if (final_poses && finals.runs > 0) {
    out.final_position_m = SigmaOf(finals.position, 2.0 * finals.runs * redundancy);
    out.final_heading_rad = SigmaOf(finals.heading, finals.runs * redundancy);
  }
  out.estimated = true;
  return out;
}

FitWeights WeightsFromNoiseLevels(const NoiseLevels& levels) {
  FitWeights w;
  if (!levels.estimated) return w;
  const double reference = levels.track_position_m;
  w.track = {1.0, Ratio(levels.track_heading_rad, reference)};
  if (levels.with_final_poses) {
    w.final_pose = {Ratio(levels.final_position_m, reference),
                    Ratio(levels.final_heading_rad, reference)};
  }
  return w;
}

bool NoiseLevelsAgree(const NoiseLevels& a, const NoiseLevels& b) {
  if (!a.estimated || !b.estimated) return false;
  const FitWeights wa = WeightsFromNoiseLevels(a), wb = WeightsFromNoiseLevels(b);
  const auto close = [](double x, double y) {
    return std::abs(x - y) <= kNoiseLevelTolerance * std::max(std::abs(x), std::abs(y));
  };
  return close(wa.track.heading_sigma_rad, wb.track.heading_sigma_rad) &&
         close(wa.final_pose.position_sigma_m, wb.final_pose.position_sigma_m) &&
         close(wa.final_pose.heading_sigma_rad, wb.final_pose.heading_sigma_rad);
}

std::string NoiseLevelsText(const NoiseLevels& levels) {
  char text[300];
  std::snprintf(text, sizeof text, "track position %.3g m, heading %.3g deg per checkpoint",
                levels.track_position_m, RadToDeg(levels.track_heading_rad));
  std::string out = text;
  if (levels.with_final_poses) {
    std::snprintf(text, sizeof text, "; final pose position %.3g m, heading %.3g deg",
                  levels.final_position_m, RadToDeg(levels.final_heading_rad));
    out += text;
  }
  std::snprintf(text, sizeof text, " (%d fits, %s)", levels.iterations,
                levels.settled ? "settled" : "not settled");
  return out + text;
}

}  // namespace fitcal
