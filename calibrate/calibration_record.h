#pragma once
// The calibration record written beside the calibrated parameters (io/calibration_block.h): how
// the selected candidate was fitted, on which runs, what it scored, its uncertainty and holds.

#include <string>
#include <vector>

#include "calibrate/calibration_request.h"
#include "calibrate/selected_fit.h"
#include "fit/run_split.h"
#include "fitcal/version.h"
#include "io/calibration_block.h"
#include "validation/training_runs.h"

namespace fitcal {

// What every written calibration records of its runs, `fit`'s and `diagnose`'s alike: the data
// set, the tool's version, the split, and the training runs by id with their fingerprint (which
// `report` reads to validate on every other run).
template <typename Run>
void RecordTrainingRuns(const std::string& dataset, const std::vector<RunLog>& runs,
                        const std::string& train_trajectories, const SplitOf<Run>& split,
                        io::CalibrationSource* source) {
  io::CalibrationSource& s = *source;
  s.dataset = dataset;
  s.tool_version = kVersion;
  s.training_repetitions = split.training_repetitions;
  s.validation_repetitions = split.validation_repetitions;
  for (const Run& run : split.training) s.training_run_ids.push_back(AlignedOf(run).id);
  s.training_trajectories = train_trajectories;
  s.training_fingerprint = TrainingFingerprint(runs, s.training_run_ids);
  s.training_runs = static_cast<int>(split.training.size());
  s.validation_runs = static_cast<int>(split.validation.size());
}

io::CalibrationBlock MakeRecord(const CalibrationRequest& request, const RobotModelInterface& model,
                                const RunSplit& split,
                                const std::vector<CalibrationCandidate>& candidates,
                                const GateDecision& gate, const SelectedFit& selected_fit,
                                const CandidateErrors& errors);

// The clock offsets the track fit estimated, into the calibrated YAML's `clock_offsets:` (the
// report and diagnose apply them to runs of the same groups).
void RecordClockOffsets(const ModelFitResult& fit, const TrackFitData& track,
                        ClockGrouping grouping, io::CalibrationBlock* record);

}  // namespace fitcal
