#pragma once
// A run prepared for the final-pose cost: encoder samples clipped to the time window that both
// clocks cover, the start pose at the window's start and the ground-truth pose at its end.
//
// Window: [t_start, t_final] with t_start = the first encoder time when the run declares its
// start_pose, else max(first encoder time, first ground-truth time) with the start pose
// interpolated from the ground truth there; t_final = min(last encoder time, last ground-truth
// time). Intervals cut by the window keep their mean rate over the shortened length, so the
// replay covers exactly the span the ground truth measured. Consecutive intervals in which all
// wheels are at rest are merged into one (they move nothing; the time line is kept).

#include <memory>
#include <string>
#include <vector>

#include "odometry/run_log.h"

namespace fitcal {

// Here, below fit/ (whose track fit estimates the offsets) and io/ (which reads them recorded).
inline constexpr double kMaxClockOffsetS = 0.5;  // |dt| bound of the clock offsets

struct AlignedRun {
  std::string id;
  std::string trajectory;
  int repetition = 0;
  double t_start_s = 0.0;
  double t_final_s = 0.0;
  Pose2d start;               // world_T_robot at t_start
  Pose2d final_ground_truth;  // world_T_robot at t_final, from the ground truth
  EncoderSamples samples{3};  // clipped to the window
  // The run's whole ground-truth track (not clipped), shared by the copies of the run, for the
  // measures along it (drift, ATE, effects replayed against it); set by AlignRun, null for a run
  // made without a log.
  std::shared_ptr<const GroundTruthTrack> track;
};

// Throws std::invalid_argument if the two clocks share no time.
AlignedRun AlignRun(const RunLog& run);
std::vector<AlignedRun> AlignRuns(const std::vector<RunLog>& runs);

// The encoder time of each sample boundary of a run: [0] = t_start_s, [k + 1] after sample k.
std::vector<double> BoundaryTimes(const AlignedRun& run);

// The ground truth at each sample boundary: the pose there and the path length from the start,
// summed chord by chord in boundary order - where segments, checkpoints and time blocks cut.
struct BoundaryGroundTruth {
  std::vector<double> t_s;   // BoundaryTimes(run)
  std::vector<Pose2d> pose;  // world_T_robot at t_s[b]
  std::vector<double> path_m;
};
BoundaryGroundTruth GroundTruthAtBoundaries(const AlignedRun& run, const GroundTruthTrack& track);

// Each run's ground-truth track (AlignedRun::track), in the runs' order; throws
// std::invalid_argument naming a run aligned without its log.
std::vector<const GroundTruthTrack*> TracksOf(const std::vector<AlignedRun>& runs);

}  // namespace fitcal
