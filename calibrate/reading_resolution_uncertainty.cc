#include "calibrate/reading_resolution_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "fit/correlation.h"
#include "odometry/text_format.h"

namespace fitcal {

std::vector<ReadingResolution> ReadingResolutionsOf(const Robot& robot,
                                                    const std::vector<RunLog>& runs) {
  std::vector<ReadingResolution> out(static_cast<std::size_t>(robot.NumChannels()));
  for (std::size_t c = 0; c < out.size(); ++c) {
    for (const RunLog& run : runs) {
      const std::vector<ReadingResolution>& of_run = run.encoders.reading_resolution;
      if (c >= of_run.size() || !(of_run[c].step_rad > 0.0)) continue;
      out[c].step_rad = std::max(out[c].step_rad, of_run[c].step_rad);
      out[c].readings += of_run[c].readings;
      out[c].reversals += of_run[c].reversals;
    }
  }
  return out;
}

namespace {

// The parameters' move when every training run's channel `c` reads `shift_rad` more: the method's
// fit warm-started from `parameters` (a judgement fit: only its parameters are read); empty when
// that fit is not usable.
std::optional<Eigen::VectorXd> MoveOfAShiftedChannel(const FitMethod& method,
                                                     FitMethodSettings settings,
                                                     const RobotModelInterface& model,
                                                     const std::vector<AlignedRun>& runs, int c,
                                                     double shift_rad,
                                                     const std::vector<double>& parameters) {
  const AlignedRun* original = runs.data();
  std::vector<AlignedRun> training = runs;
  // The track residuals read the runs' samples through their checkpoints: pointed at the copies.
  std::optional<TrackFitData> shifted_tracks;
  if (settings.track != nullptr) {
    shifted_tracks = *settings.track;
    for (TrackCheckpoints& checkpoints : shifted_tracks->runs) {
      const std::ptrdiff_t i = checkpoints.run - original;
      if (i < 0 || i >= static_cast<std::ptrdiff_t>(runs.size())) {
        throw std::logic_error("the track residuals are not of the training runs");
      }
      checkpoints.run = &training[static_cast<std::size_t>(i)];
    }
    settings.track = &*shifted_tracks;
  }
  for (AlignedRun& run : training) {
    for (auto&& sample : run.samples) sample.value[c] += shift_rad;
  }
  settings.start = parameters;
  settings.judgement_fit = true;
  const ModelFitResult refit = method.run_model(training, model, settings).fit;
  if (!refit.usable) return std::nullopt;
  Eigen::VectorXd move(static_cast<Eigen::Index>(parameters.size()));
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    move[static_cast<Eigen::Index>(k)] = refit.parameters[k] - parameters[k];
  }
  return move;
}

// "channel 'steering' reads in steps of 0.45 deg: a held angle's reading is off by a constant
// (uniform over a step, sigma 0.13 deg), in the sigmas: steering_offset 0.0335 -> 0.134 deg"
std::string ResolutionLine(const Robot& robot, int c, const ReadingResolution& resolution,
                           const std::vector<double>& sigma_before,
                           const std::vector<double>& sigma_after) {
  const double deg = 180.0 / M_PI;
  const double uniform_sigma = resolution.step_rad / std::sqrt(12.0);
  // Said when the readings' noise shrinks the bias by 1 % or more.
  const std::string dither =
      resolution.BiasSigma() < 0.99 * uniform_sigma
          ? "; its noise, " + StrFormat("%.2g", resolution.NoiseOverStep()) +
                " of a step, dithers that to sigma " +
                StrFormat("%.3g", resolution.BiasSigma() * deg) + " deg"
          : "";
  std::string line = "channel '" + robot.channels[c].name + "' reads in steps of " +
                     StrFormat("%.3g", resolution.step_rad * deg) +
                     " deg: a held angle's reading is off by a constant (uniform over a step, "
                     "sigma " + StrFormat("%.3g", uniform_sigma * deg) + " deg" + dither +
                     "), in the sigmas:";
  bool any = false;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    if (!(sigma_after[k] > 1.01 * sigma_before[k])) continue;
    line += std::string(any ? "," : "") + " " + info.name + " " +
            StrFormat("%.3g", sigma_before[k] * info.DisplayScale()) + " -> " +
            StrFormat("%.3g", sigma_after[k] * info.DisplayScale()) + " " + info.DisplayUnit();
    any = true;
  }
  return any ? line : line + " no parameter's sigma grows by 1 % or more";
}

}  // namespace

void AddReadingResolutionUncertainty(
    const FitMethod& method, const FitMethodSettings& settings, const RobotModelInterface& model,
    const std::vector<AlignedRun>& training, const std::vector<ReadingResolution>& resolutions,
    const std::vector<double>& parameters, SelectedFit* fit) {
  const Robot& robot = model.robot();
  const auto quantised = [](const ReadingResolution& r) { return r.step_rad > 0.0; };
  if (!fit->has_covariance ||
      std::none_of(resolutions.begin(), resolutions.end(), quantised)) {
    return;  // the fit's own sigmas and correlation, untouched
  }
  const Eigen::Index n = robot.NumParameters();
  Eigen::MatrixXd covariance(n, n);
  for (Eigen::Index r = 0; r < n; ++r) {
    for (Eigen::Index k = 0; k < n; ++k) {
      covariance(r, k) = fit->correlation(r, k) * fit->sigma[r] * fit->sigma[k];
    }
  }
  for (int c = 0; c < robot.NumChannels(); ++c) {
    const ReadingResolution resolution =
        c < static_cast<int>(resolutions.size()) ? resolutions[c] : ReadingResolution{};
    if (!quantised(resolution)) continue;
    if (!IsCeresMethod(method.name)) {
      fit->sigma_notes.push_back("channel '" + robot.channels[c].name + "' reads in steps of " +
                                 StrFormat("%.3g", resolution.step_rad * 180.0 / M_PI) + " deg; " +
                                 method.name +
                                 " takes no start, so the sigmas leave that resolution out "
                                 "(--method ceres includes it)");
      continue;
    }
    const std::optional<Eigen::VectorXd> move = MoveOfAShiftedChannel(
        method, settings, model, training, c, resolution.BiasSigma(), parameters);
    if (!move) {
      fit->sigma_notes.push_back("channel '" + robot.channels[c].name +
                                 "': the fit with its readings shifted did not converge, so the "
                                 "sigmas leave its resolution out");
      continue;
    }
    const std::vector<double> before = SigmasOf(covariance);
    covariance += *move * move->transpose();
    fit->sigma_notes.push_back(ResolutionLine(robot, c, resolution, before, SigmasOf(covariance)));
  }
  fit->sigma = SigmasOf(covariance);
  fit->correlation = CorrelationOf(covariance);
}

}  // namespace fitcal
