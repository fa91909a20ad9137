#pragma once
// Measures of everyday driving for a set of runs replayed with one calibration: what a robot's
// dead reckoning does between closed-loop ends, beside Palacin's final-pose CF (Eq. 14).
//   - drift per distance travelled (relative_pose_error.h: KITTI's translation error in % of the
//     window's length and rotation error per metre) over windows of 1, 2 and 5 m of ground-truth
//     path, every window of every run weighing alike;
//   - ATE RMSE: each run's RMS position error over its ground-truth samples (Palacin Eq. 12,
//     trajectory_metrics.h), the odometry started at the ground truth's start pose, no other
//     alignment and never a scale (a scale alignment would absorb the wheel radius); the mean
//     over runs.

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"
#include "odometry/run_log.h"
#include "validation/relative_pose_error.h"
#include "validation/trajectory_metrics.h"

namespace fitcal {

struct DriftAtLength {
  double length_m = 0.0;
  int windows = 0;
  double translation_percent = 0.0;
  double rotation_deg_per_m = 0.0;
  // Each run's own mean over its windows and its number of windows (0 for a run shorter than
  // the window): the scatter between repetitions the never-worse judgement reads
  // (validation/never_worse.h); translation_percent is their mean weighted by the windows.
  std::vector<double> per_run_translation_percent = {};
  std::vector<int> per_run_windows = {};
  // Appends one run's mean over its windows and their number, and counts them in `windows`.
  void AddRun(double run_translation_percent, int run_windows) {
    per_run_translation_percent.push_back(run_translation_percent);
    per_run_windows.push_back(run_windows);
    windows += run_windows;
  }
};

struct EverydayDrivingMetrics {
  int runs = 0;
  double cf = 0.0;               // mean per-run Eq. 14 (m and rad)
  double mean_ate_rmse_m = 0.0;  // mean over runs of Eq. 12
  std::vector<DriftAtLength> drift;
  std::vector<double> per_run_cf = {};     // in the order of the runs
  std::vector<double> per_run_ate_m = {};  // each run's Eq. 12
};

// The lengths printed by default: 0.5 (the track residual's checkpoint spacing, where short-range
// drift shows first), 1, 2 and 5 m.
std::vector<double> EverydayDriftLengths();

// What scoring a run takes from the run and its ground truth alone, whatever the parameters: the
// replay's time line with the track's samples inside its window (trajectory_metrics.h) and the
// ground-truth side of its drift windows (relative_pose_error.h).
struct EverydayDrivingTruth {
  EverydayDrivingTruth(const AlignedRun& run, const GroundTruthTrack& track);
  RunTimeLine time_line;
  RelativePoseErrorTruth drift;
};

// Each run's EverydayDrivingTruth, made when the run is first scored and kept for the scores of
// other parameters after it (calibrate/choice_by_transfer.h: EverydayDrivingScore owns one for the
// candidates and folds it scores). A run is known by its id, unique in a data set, and its time
// window: the time blocks of a run (validation/time_blocks.h) share an id across block counts.
// Safe to call from several threads.
class EverydayDrivingTruths {
 public:
  const EverydayDrivingTruth& Of(const AlignedRun& run, const GroundTruthTrack& track);

 private:
  using Key = std::tuple<std::string, double, double>;  // id, t_start_s, t_final_s
  std::mutex mutex_;
  std::map<Key, std::unique_ptr<const EverydayDrivingTruth>> by_run_;
};

// tracks[i] is runs[i]'s ground truth. Runs shorter than a window add nothing to its drift. Each
// run's truth is taken from `truths` when given, else made for this call.
EverydayDrivingMetrics EvaluateEverydayDriving(
    const RobotModelInterface& model, const std::vector<double>& p,
    const std::vector<effects::EffectValue>& effects, const std::vector<AlignedRun>& runs,
    const std::vector<const GroundTruthTrack*>& tracks, const std::vector<double>& lengths_m,
    int num_threads = 0, EverydayDrivingTruths* truths = nullptr);

// Table rows "  drift 1 m [%]  nominal  calibrated  change" etc. for two calibrations on the same
// runs; a measure named in `notes` ("ATE RMSE [m]", "drift 1 m [%]") has its note after the
// change (the never-worse judgement's, validation/never_worse.h: NeverWorseRowNotes).
std::vector<std::string> EverydayDrivingRows(const EverydayDrivingMetrics& before,
                                             const EverydayDrivingMetrics& after,
                                             const std::map<std::string, std::string>& notes = {});

}  // namespace fitcal
