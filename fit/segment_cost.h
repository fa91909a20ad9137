#pragma once
// Costs for long runs and the fit that minimises them.
//
// 1. Segments (segment_residual.h): windows of a set ground-truth path length, started every
//    stride_fraction * length along the path (evo/KITTI-style relative pose error).
// 2. Clock mapping. Encoders and ground truth are often on different clocks linearly mapped by
//    hand (OptiOdom: start/end instants picked in each stream; the mapped spans differ by ~2 %).
//    Final poses (robot at rest) do not care, but a window's end points do: a misalignment of
//    dt moves each end by |v| dt. EstimateClockMap refines the mapping per run, t_gt = t + a +
//    b (t - t_mid), by matching the speed profiles |v| and omega of odometry and ground truth
//    (both independent of where the robot is, so robust to the calibration errors being fitted);
//    ApplyClockMap re-stamps the ground truth. Windows are also long (default 1 m) so that a
//    residual dt of a few 10 ms costs |v| dt / L ~ 1 %.
// 3. FitOmni3 minimises either cost over the nine parameters or a tied/fixed subset of them
//    (ParameterTying: e.g. OptiOdom's reduced model, one common distance + three radii, angles
//    fixed at nominal).

#include <array>
#include <string>
#include <vector>

#include "fit/final_pose_cost.h"
#include "fit/final_pose_residual.h"
#include "fit/segment_residual.h"
#include "odometry/aligned_run.h"
#include "odometry/robot_description.h"

namespace fitcal {

struct SegmentOptions {
  double length_m = 1.0;         // ground-truth path length of a window
  double stride_fraction = 0.5;  // a new window starts every stride_fraction * length_m
  bool IsValid(std::string* error) const;
};

// Windows of `run` (aligned against `ground_truth`, which must cover the run's window).
std::vector<Segment> MakeSegments(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                                  const SegmentOptions& options);

// Sousa et al.'s OptiOdom cost ("OptiOdom: a Generic Approach for Odometry Calibration of Wheeled
// Mobile Robots", J. Intell. Robot. Syst. 2022; their simulateRobot_*.m and Rprop_*.m): windows
// that all begin at the run's start and end at a checkpoint after every `spacing_m` of path since
// the previous one, and at the run's end, so each accumulates the whole drift up to its checkpoint.
// The authors count 0.5 m of nominal odometry distance; the ground truth's path length is counted
// here, which does not move with the parameters being fitted. With a heading weight near zero the
// segment residual's squared norm is their cost, the squared position error in the start frame.
std::vector<Segment> MakeCheckpointsFromStart(const AlignedRun& run,
                                              const GroundTruthTrack& ground_truth,
                                              double spacing_m);

struct SegmentErrors {
  double cf = 0.0;  // mean over windows of |r| (metres and radians, Eq. 14 per window)
  double mean_translation_error_m = 0.0;
  double mean_abs_heading_error_rad = 0.0;
  int num_segments = 0;
};
SegmentErrors EvaluateSegmentErrors(const Omni3ParameterArray& p,
                                    const std::vector<SegmentedRun>& runs, int num_threads = 0);

struct ClockMap {
  double offset_s = 0.0;  // a
  double rate = 0.0;      // b: relative rate error of the ground-truth clock
  double t_mid_s = 0.0;
  double Map(double t_s) const { return t_s + offset_s + rate * (t_s - t_mid_s); }
};
struct ClockMapOptions {
  double max_offset_s = 0.5;
  double offset_step_s = 0.01;
  double max_rate = 0.03;  // 3 %: the OptiOdom spans differ by ~2 %
  double rate_step = 0.0025;
  bool IsValid(std::string* error) const;
};
// The map that makes the ground truth's speed profile match the odometry's (replayed with p).
ClockMap EstimateClockMap(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                          const Omni3ParameterArray& p, const ClockMapOptions& options = {});
// The ground truth re-stamped on the encoder clock: sample at t_gt moves to t with Map(t) = t_gt.
GroundTruthTrack ApplyClockMap(const GroundTruthTrack& ground_truth, const ClockMap& map);

// Which parameters the fit moves: group[k] = j >= 0 ties flat parameter k to free parameter j;
// -1 holds it at the nominal. The nine-parameter model is {0, 1, ..., 8}.
struct ParameterTying {
  std::string name = "nine";
  std::array<int, omni3::kNumParameters> group{0, 1, 2, 3, 4, 5, 6, 7, 8};
  int NumFree() const;
  static ParameterTying Nine();
  // OptiOdom's reduced model (Sousa et al. 2022): common R, three r_i, angles fixed.
  static ParameterTying CommonDistanceThreeRadii();
};

enum class CostKind { kFinalPose, kSegment };

struct FitOptions {
  CostKind cost = CostKind::kFinalPose;
  ResidualWeights weights;
  ParameterTying tying;
  int max_num_iterations = 100;
  int num_threads = 0;
  bool IsValid(std::string* error) const;
};

struct FitResult {
  bool usable = false;
  std::string termination;
  std::string message;
  int iterations = 0;
  Omni3ParameterArray parameters{};
  std::array<bool, omni3::kNumParameters> at_bound{};  // only free parameters can be at a bound
  int NumAtBound() const;
};

// `segmented` is used for CostKind::kSegment, `final_runs` for kFinalPose.
FitResult FitOmni3(const std::vector<AlignedRun>& final_runs,
                   const std::vector<SegmentedRun>& segmented, const Omni3Robot& robot,
                   const FitOptions& options);

}  // namespace fitcal
