#pragma once
// Which runs of a data set trained a calibration. A calibrated YAML records its training runs by
// id and a fingerprint of their encoder logs (calibration.training_run_ids,
// calibration.training_fingerprint); a data set's run trains only when it is one of those runs
// with the same data. Every other run validates: on another data set all of them, whatever their
// repetition numbers or trajectory labels (README, "Validation report").

#include <string>
#include <vector>

#include "fit/run_split.h"
#include "odometry/run_log.h"

namespace fitcal {

// 16 hex digits: FNV-1a 64 over the id and the encoder log (times and channel values, bit for
// bit) of each run named in `training_ids`, in the order of the sorted ids. The ground truth is
// left out: `diagnose --clock-map` re-stamps it, and the encoders alone tell two data sets apart
// (another recording, another simulator seed). Empty when no run is named.
std::string TrainingFingerprint(const std::vector<RunLog>& runs,
                                const std::vector<std::string>& training_ids);

// What a calibration recorded about its training runs (io/calibration_yaml.h reads it).
struct RecordedTraining {
  std::vector<std::string> run_ids;
  std::string fingerprint;       // empty in files written before it was recorded
  std::vector<int> repetitions;  // files written before run ids were recorded
};

struct TrainingSplit {
  RunSplit split;
  // How the training runs were found, for the report: "by id", "by repetition", "none".
  std::string how;
};

// The split of `aligned` (AlignRuns of `logs`): the recorded training runs when this data set
// holds them (every id present and, when recorded, the same fingerprint), by repetition for
// files that record repetitions only, otherwise no training run at all.
TrainingSplit SplitAsRecorded(const std::vector<RunLog>& logs, std::vector<AlignedRun> aligned,
                              const RecordedTraining& recorded);

}  // namespace fitcal
