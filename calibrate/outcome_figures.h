#pragma once
// The figures `fit` prints of a calibration (cli/fit_printout.h) that the outcome does not hold
// itself, computed here so that the command only prints (STYLE.md habit 13): the CF of the nominal
// and the selected calibration on each side of the split, everyday driving on the held-out runs,
// the clock offsets' summary, the training runs far off the others and the glitches dropped.

#include <string>
#include <vector>

#include "calibrate/calibrate.h"
#include "diagnosis/degenerate_data.h"
#include "validation/never_worse.h"

namespace fitcal {

// Palacin Eq. 14's CF with its mean final position and heading errors, nominal and selected.
struct CfRow {
  const char* side;  // "training", "validation"
  FinalPoseErrors nominal, selected;
};
// The training runs, then the validation runs when some are held out.
std::vector<CfRow> CfRows(const RobotModelInterface& model, const CalibrationOutcome& o,
                          int threads);

// Everyday driving (validation/never_worse.h) of the nominal and the selected calibration on the
// held-out runs, on the training runs when none is held out.
struct OutcomeEverydayDriving {
  bool held_out = false;
  EverydayDrivingComparison table;
};
OutcomeEverydayDriving CompareOutcomeEverydayDriving(const RobotModelInterface& model,
                                                     const CalibrationOutcome& o, int threads);

struct ClockOffsetSummary {
  std::vector<double> sigma_s;  // per group; 0: the covariance could not be computed
  // Offsets on the +-bound are where the fit was stopped, not a measured lag.
  std::size_t num_on_bound = 0;
  std::string first_on_bound;  // the first three such groups, comma-separated
  double median_s = 0.0, lo_s = 0.0, hi_s = 0.0, mean_sigma_s = 0.0;
};
ClockOffsetSummary SummariseClockOffsets(const ModelFitResult& fit, const TrackFitData& track);

// Training runs whose final-pose error under the fit is far beyond the others' (gross slip, a
// ground truth of another run: diagnosis/degenerate_data.h); none when the fit is neither usable
// nor stopped early.
std::vector<OutlierRun> OutlierTrainingRuns(const RobotModelInterface& model,
                                            const RunSplit& split, const ModelFitResult& fit,
                                            int threads);

// The counter glitches the loader dropped (io/log_files.h): intervals, and runs with any.
struct DroppedGlitches {
  int intervals = 0, runs = 0;
};
DroppedGlitches CountDroppedGlitches(const std::vector<RunLog>& runs);

}  // namespace fitcal
