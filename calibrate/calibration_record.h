#pragma once
// The calibration record written beside the calibrated parameters (io/calibration_block.h): how
// the selected candidate was fitted, on which runs, what it scored, its uncertainty and holds.

#include <vector>

#include "calibrate/calibration_request.h"
#include "calibrate/selected_fit.h"
#include "io/calibration_block.h"

namespace fitcal {

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
