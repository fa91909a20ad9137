#include "calibrate/calibration_record.h"

#include <string>

namespace fitcal {

namespace {

// The weights in words: the noise levels the fit estimated, or the sigmas it was given.
std::string WeightsText(const CalibrationRequest& request, const NoiseLevels& levels) {
  if (levels.estimated) return "weights from the data: " + NoiseLevelsText(levels);
  return "sigma_xy " + std::to_string(request.position_sigma_m) + " m, sigma_theta " +
         std::to_string(request.heading_sigma_deg) + " deg";
}

}  // namespace

io::CalibrationBlock MakeRecord(const CalibrationRequest& request, const RobotModelInterface& model,
                                const RunSplit& split,
                                const std::vector<CalibrationCandidate>& candidates,
                                const GateDecision& gate, const SelectedFit& selected_fit,
                                const CandidateErrors& errors) {
  const Robot& robot = model.robot();
  const CalibrationCandidate& nominal = candidates[0];
  const CalibrationCandidate& selected = candidates[gate.selected];
  io::CalibrationBlock r;
  r.method = selected.name;
  r.objective =
      selected_fit.objective + " (" + WeightsText(request, selected_fit.noise_levels) + ")";
  r.termination = selected_fit.termination;
  RecordTrainingRuns(request.dataset, request.runs, request.train_trajectories, split, &r);
  r.cf_training_before = errors(nominal, split.training).cf;
  r.cf_training_after = errors(selected, split.training).cf;
  r.cf_validation_before = errors(nominal, split.validation).cf;
  r.cf_validation_after = errors(selected, split.validation).cf;
  r.selected = selected.name;
  r.selected_on = gate.judged_on;
  for (const HeldParameter& h : robot.held) r.held.push_back(robot.parameters[h.index].name);
  for (int k = 0; k < robot.NumParameters(); ++k) {
    // Held by --hold (fit/parameter_tying.h) beside the model's own holds.
    if (selected_fit.held[k] && !robot.IsHeld(k)) r.held.push_back(robot.parameters[k].name);
  }
  for (const std::vector<std::string>& group : request.settings.tying.groups) {
    std::string names;
    for (const std::string& name : group) names += (names.empty() ? "" : "=") + name;
    r.tied.push_back(names);
  }
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (selected_fit.at_bound[k]) r.at_bound.push_back(robot.parameters[k].name);
  }
  for (std::size_t k = 0; k < selected_fit.not_determined.size(); ++k) {
    if (selected_fit.not_determined[k]) r.not_determined.push_back(robot.parameters[k].name);
  }
  // The uncertainty is the selected fit's (with its effects, when it carries some; the effects'
  // own sigmas are written with them).
  r.has_uncertainty = selected_fit.has_covariance;
  r.sigma = selected_fit.sigma;
  r.correlation = selected_fit.correlation;
  return r;
}

void RecordClockOffsets(const ModelFitResult& fit, const TrackFitData& track,
                        ClockGrouping grouping, io::CalibrationBlock* record) {
  if (!track.estimate_clock_offsets) return;
  record->clock_offset_grouping = ToString(grouping);
  for (std::size_t g = 0; g < track.clock_groups.size() && g < fit.clock_offsets_s.size(); ++g) {
    const double sigma = g < fit.clock_offset_sigma_s.size() ? fit.clock_offset_sigma_s[g] : 0.0;
    record->clock_offsets.push_back({track.clock_groups[g], fit.clock_offsets_s[g], sigma});
  }
}

}  // namespace fitcal
