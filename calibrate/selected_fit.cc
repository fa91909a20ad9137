#include "calibrate/selected_fit.h"

#include <cmath>

#include "fit/correlation.h"
#include "fit/determined_directions.h"
#include "models/mounted_model.h"
#include "validation/propagated_uncertainty.h"

namespace fitcal {

namespace {

constexpr const char* kTrackObjective = "sum over runs of the mean squared track error (m and rad)";

// The track fit that made candidate `index`, or null.
const EffectFitResult* TrackFitOf(const std::optional<TrackFits>& track_fits, int index) {
  if (track_fits && index == track_fits->with_index) return &track_fits->with_effects;
  if (track_fits && index == track_fits->without_index) return &track_fits->without_effects;
  return nullptr;
}

// A closed form's own sigmas (ClosedFormCalibration::sigma, e.g. ASOC's spread over hold runs)
// for the parameters it measures, r_c and beta included, which the final-pose residuals cannot
// see (the robot holds them). Their correlation with the others is not estimated: written as 0.
// True when it measured every parameter.
bool UseOwnSigmas(const std::vector<double>& own, SelectedFit* fit) {
  if (own.empty()) return false;
  const auto n = static_cast<Eigen::Index>(own.size());
  if (!fit->has_covariance) {
    fit->sigma.assign(own.size(), 0.0);
    fit->correlation = Eigen::MatrixXd::Identity(n, n);
  }
  bool all = true;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!std::isfinite(own[k])) {
      all = false;
      continue;
    }
    fit->sigma[k] = own[k];
    fit->correlation.row(k).setZero();
    fit->correlation.col(k).setZero();
    fit->correlation(k, k) = 1.0;
  }
  fit->has_covariance = fit->has_covariance || all;
  return all;
}

}  // namespace

SelectedFit DescribeSelected(const Robot& robot,
                             const std::vector<CalibrationCandidate>& candidates,
                             int selected_index, const std::string& method,
                             const std::string& method_objective, const ModelFitResult& fit,
                             const std::optional<TrackFits>& track_fits) {
  const CalibrationCandidate& selected = candidates[selected_index];
  const std::size_t n = robot.nominal.size();
  SelectedFit out;
  out.at_bound.assign(n, false);
  out.held.assign(n, false);
  out.objective = method_objective;
  out.termination = fit.termination;
  if (const EffectFitResult* track_fit = TrackFitOf(track_fits, selected_index)) {
    out.has_covariance = track_fit->has_covariance;
    out.sigma = track_fit->sigma;
    out.correlation = track_fit->correlation;
    // The effect fit reports only whether some parameter ended on a bound: which ones, by the
    // fit's own rule.
    out.at_bound = ParametersAtBound(robot, selected.parameters);
    out.held = robot.HeldFlags();
    out.objective = kTrackObjective;
    out.termination = track_fit->termination;
  } else if (selected.name == method) {
    out.noise_levels = fit.noise_levels;
    out.has_covariance = fit.has_covariance;
    out.sigma = fit.sigma;
    out.correlation = fit.correlation;
    out.at_bound = fit.at_bound;
    out.held = fit.held;
    out.not_determined = NotDeterminedParameters(fit);
  } else if (selected.name == method + " without holds") {
    out.at_bound = ParametersAtBound(robot, selected.parameters);  // its own, not the held fit's
    out.held = fit.held;  // the parameters' holds (gauge, --hold) stay; the directions' go
  } else if (selected_index > 0) {
    // A closed form measures the base; the pose source's frame is the nominal it was handed
    // (MountedModel::ClosedForms), so it is held, not given a sigma the runs never measured
    // (propagated through the final poses it came out 1.9e3 deg for an ASOC's yaw).
    for (int k : MountParameterIndices(robot)) out.held[k] = true;
    out.held_reason =
        selected.name + " measures the base only: kept at the robot YAML's ground_truth_frame";
  }
  return out;
}

std::string AddPropagatedUncertainty(const RobotModelInterface& model,
                                     const CalibrationCandidate& selected,
                                     const std::vector<AlignedRun>& training, SelectedFit* fit) {
  if (fit->has_covariance) return "";
  if (UseOwnSigmas(selected.sigma, fit)) return "";
  const PropagatedUncertainty u =
      PropagateFinalPoseUncertainty(model, selected.parameters, training, fit->held);
  if (!u.ok) {
    return "no uncertainty for the selected calibration (" + u.message +
           "); nothing written (record more runs, or runs that excite every parameter)";
  }
  fit->has_covariance = true;
  fit->sigma = u.sigma;
  fit->correlation = CorrelationOf(u.covariance);
  UseOwnSigmas(selected.sigma, fit);
  return "";
}

void MarkWiderThanTheBounds(const Robot& robot, SelectedFit* fit) {
  const Eigen::VectorXd prior = PriorSigma(robot);
  const std::size_t n = static_cast<std::size_t>(robot.NumParameters());
  if (fit->sigma.size() != n) return;
  fit->not_determined.resize(n, false);
  for (std::size_t k = 0; k < n; ++k) {
    const double bounds_sigma = prior[static_cast<Eigen::Index>(k)];
    if (bounds_sigma > 0.0 && fit->sigma[k] > bounds_sigma) fit->not_determined[k] = true;
  }
}

}  // namespace fitcal
