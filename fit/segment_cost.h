#pragma once
// Windows of long runs and the clock map.
//
// 1. Segments: windows of a set ground-truth path length, started every stride_fraction * length
//    along the path (evo/KITTI-style relative pose error); each model's SegmentCost
//    (models/model_interface.h, models/pose_errors.h) compares them, FitModel (fit/model_fit.h,
//    ModelFitOptions::segments) minimises them.
// 2. Clock mapping. Encoders and ground truth are often on different clocks linearly mapped by
//    hand (OptiOdom: start/end instants picked in each stream; the mapped spans differ by ~2 %).
//    Final poses (robot at rest) do not care, but a window's end points do: a misalignment of
//    dt moves each end by |v| dt. EstimateClockMap refines the mapping per run, t_gt = t + a +
//    b (t - t_mid), by matching the speed profiles |v| and omega of odometry and ground truth
//    (both independent of where the robot is, so robust to the calibration errors being fitted);
//    ApplyClockMap re-stamps the ground truth. Windows are also long (default 1 m) so that a
//    residual dt of a few 10 ms costs |v| dt / L ~ 1 %.

#include <cstddef>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

struct SegmentOptions {
  double length_m = 1.0;         // ground-truth path length of a window
  double stride_fraction = 0.5;  // a new window starts every stride_fraction * length_m
  bool IsValid(std::string* error) const;
};

// Windows of `run` (aligned against `ground_truth`, which must cover the run's window).
std::vector<Segment> MakeSegments(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                                  const SegmentOptions& options);

// Disjoint windows of kDisjointWindowM of every run (runs[i] against tracks[i]): independent
// relative motions, which neither accumulate a run's error (the global start's last start,
// fit/model_fit.h) nor share residuals (the wheel-order check's F test). `*total`: their count.
constexpr double kDisjointWindowM = 0.5;
std::vector<std::vector<Segment>> MakeDisjointWindows(
    const std::vector<AlignedRun>& runs, const std::vector<const GroundTruthTrack*>& tracks,
    std::size_t* total);

// Sousa et al.'s OptiOdom cost ("OptiOdom: a Generic Approach for Odometry Calibration of Wheeled
// Mobile Robots", J. Intell. Robot. Syst. 2022; their simulateRobot_*.m and Rprop_*.m): windows
// that all begin at the run's start and end at a checkpoint after every `spacing_m` of path since
// the previous one, and at the run's end, so each accumulates the whole drift up to its checkpoint.
// The authors count 0.5 m of nominal odometry distance; the ground truth's path length is counted
// here, which does not move with the parameters being fitted. With a heading weight near zero the
// segment residual's squared norm is their cost, the squared position error in the start frame.
// A checkpoint sits at the encoder boundary nearest the ground truth's first sample at or past the
// crossing (OnAGroundTruthSample, segment_cost.cc): where every boundary has a sample, as in
// OptiOdom's logs, that is the crossing itself.
std::vector<Segment> MakeCheckpointsFromStart(const AlignedRun& run,
                                              const GroundTruthTrack& ground_truth,
                                              double spacing_m);

// The windows between consecutive checkpoints of `from_start` (windows that all begin where the
// first does, as MakeCheckpointsFromStart's): [begin, end_0], [end_0, end_1], ..., each with the
// ground truth's motion over it. Their errors are the independent ones a track's checkpoints
// accumulate (fit/serial_covariance.h: the innovations, here exact rather than linearised).
// Empty when the windows do not all begin at the same sample.
std::vector<Segment> StretchesBetweenCheckpoints(const std::vector<Segment>& from_start);

struct ClockMap {
  double offset_s = 0.0;  // a
  double rate = 0.0;      // b: relative rate error of the ground-truth clock
  double t_mid_s = 0.0;
  double Map(double t_s) const { return t_s + offset_s + rate * (t_s - t_mid_s); }
};
// The grid EstimateClockMap searches: offsets a in [-max, max] by the step, rates b likewise.
inline constexpr double kClockMapMaxOffsetS = 0.5;
inline constexpr double kClockMapOffsetStepS = 0.01;
inline constexpr double kClockMapMaxRate = 0.03;  // 3 %: the OptiOdom spans differ by ~2 %
inline constexpr double kClockMapRateStep = 0.0025;
static_assert(kClockMapOffsetStepS > 0.0 && kClockMapRateStep > 0.0 && kClockMapMaxRate < 0.5,
              "clock map search: steps positive, rate < 0.5");
// The map that makes the ground truth's speed profile match the odometry's: the body velocities
// of `model` at p (its body step of each sample over dt), any model.
ClockMap EstimateClockMap(const RobotModelInterface& model, const double* p, const AlignedRun& run,
                          const GroundTruthTrack& ground_truth);
// How EstimateClockMap weighs a yaw-rate mismatch against a speed mismatch: the distance from the
// centre at which a turn moves the wheels as fast as a translation of the same speed,
// |w(rotation 1 rad/s)| / |w(translation 1 m/s)| with w the channel values (ChannelsForTwist; the
// translation forward and, when drivable, sideways, in quadrature). That is R for a symmetric
// omni3 (every wheel at distance R) and half the wheel separation for a differential drive. 1 m
// when the model has angle channels or cannot turn on the spot or drive forward.
double ClockMapLeverArm(const RobotModelInterface& model, const double* p);
// The ground truth re-stamped on the encoder clock: sample at t_gt moves to t with Map(t) = t_gt.
GroundTruthTrack ApplyClockMap(const GroundTruthTrack& ground_truth, const ClockMap& map);

}  // namespace fitcal
