#pragma once
// `fit --residuals auto` (the default): track residuals (fit/track_residual.h) where the training
// runs' ground truth is a dense track along long enough paths, final poses otherwise.
//
// Why: on the real OptiOdom robots the track transferred best to free driving for every model
// (docs/everyday_driving.md): closed loops judged at their ends cannot see a common scale of the
// wheels and the track, checkpoints along the path can. The track needs the ground truth between
// the ends, densely enough that a checkpoint's interpolated pose is a measured one (a sample at
// least every kMaxSampleSpacingFraction of the checkpoint spacing), and runs of several
// checkpoints (kMinCheckpointsPerRun): on a run of one or two checkpoints the track adds hardly
// anything to the final pose and its clock sensitivity stays (the shipped flower runs, ~1 m).

#include <vector>

#include "fit/track_residual.h"
#include "odometry/aligned_run.h"
#include "odometry/run_log.h"

namespace fitcal {

inline constexpr double kMaxSampleSpacingFraction = 0.2;  // 0.1 m for 0.5 m checkpoints
inline constexpr double kMinCheckpointsPerRun = 4.0;      // 2 m of path for 0.5 m checkpoints

struct TrackDensity {
  double median_path_m = 0.0;            // ground-truth path inside each run's window
  double median_sample_spacing_m = 0.0;  // path per ground-truth sample interval
  double median_intervals = 0.0;         // ground-truth sample intervals inside each window
  bool dense = false;                    // both above pass the thresholds
  // Whether the ground truth samples the path between the ends at all (a looser test than
  // `dense`): what comparing motion along it needs - the wheel-order check's windows, a clock
  // offset. Start and end poses only fail it even on a closed loop (whose one interval is short),
  // as does a pose every half loop.
  bool SamplesThePath() const {
    return median_intervals >= kMinIntervalsAlongPath &&
           median_sample_spacing_m <= kMaxSpacingAlongPathM;
  }
  static constexpr double kMinIntervalsAlongPath = 4.0;
  static constexpr double kMaxSpacingAlongPathM = 0.5;  // fit/segment_cost.h kDisjointWindowM
};

// tracks[i] is runs[i]'s ground truth.
TrackDensity MeasureTrackDensity(const std::vector<AlignedRun>& runs,
                                 const std::vector<const GroundTruthTrack*>& tracks,
                                 const TrackResidualOptions& options = {});

}  // namespace fitcal
