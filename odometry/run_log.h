#pragma once
// The recorded data of one calibration run, as the loaders hand it over: encoder wheel rates and
// the ground-truth track on the same clock. No file knowledge here (io/ fills these).

#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "odometry/encoder_samples.h"
#include "odometry/pose2.h"
#include "odometry/reading_resolution.h"

namespace fitcal {

// Encoder log: t_s[0] only sets the start time; samples[k] covers (t_s[k], t_s[k+1]] with
// dt_s = t_s[k+1] - t_s[k] and the mean wheel rates over that interval.
struct EncoderLog {
  std::vector<double> t_s;
  EncoderSamples samples{3};
  // The absolute wheel angle at t_s[0], one per channel (rad, in [0, 2 pi)): known when the
  // recorder logs cumulative counts that are not reset between runs (the count's zero is then a
  // fixed mark on the wheel); NaN for a channel without it (angle channels, rate columns). Empty:
  // the log carries none. One value per channel per run: the per-sample memory is unchanged.
  std::vector<double> start_angle_rad;
  // Intervals whose counts were glitches of the recorder's counter (io/log_files.h), named on
  // load and bridged by their neighbours instead of replayed.
  int dropped_glitches = 0;
  // Per channel: the resolution of an angle channel's readings - its absolute encoder's count, or
  // the grid the recorded readings lie on, and their noise over it (odometry/reading_resolution.h)
  // - step 0 when none is seen and for wheel rates. Empty: the loader did not look (logs made in
  // memory).
  std::vector<ReadingResolution> reading_resolution;
};

// Ground truth (SLAM, motion capture): poses in the world frame at strictly increasing times.
struct GroundTruthTrack {
  std::vector<double> t_s;
  std::vector<Pose2d> world_T_robot;
};

struct RunLog {
  std::string id;
  std::string trajectory;  // e.g. "R1", "G12": repetitions of a trajectory share this label
  int repetition = 0;
  EncoderLog encoders;
  GroundTruthTrack ground_truth;
  std::optional<Pose2d> start_pose;  // the pose at the first encoder time, when the user knows it
  // The file the ground truth was read from, named when the data lack something the fit needs
  // ("" for runs made in memory).
  std::string ground_truth_path;
};

// The typical interval between encoder samples: the median over the runs of each run's median
// (s; 0 without intervals), blind to a logger's pauses. No calibration log is slower than 1 Hz:
// beyond a second, the times are in ms or us.
inline double TypicalEncoderInterval(const std::vector<RunLog>& runs) {
  std::vector<double> medians;
  for (const RunLog& log : runs) {
    std::vector<double> dt;
    for (std::size_t k = 1; k < log.encoders.t_s.size(); ++k)
      dt.push_back(log.encoders.t_s[k] - log.encoders.t_s[k - 1]);
    if (dt.empty()) continue;
    std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
    medians.push_back(dt[dt.size() / 2]);
  }
  if (medians.empty()) return 0.0;
  std::nth_element(medians.begin(), medians.begin() + medians.size() / 2, medians.end());
  return medians[medians.size() / 2];
}

// The index of the first sample after v in the times t (t.front() <= v < t.back()), as
// std::upper_bound. With `from` (the bracket an earlier, not later, time found: times asked in
// order, as a run's samples and checkpoints are) the search starts there and doubles its step -
// a few comparisons where the samples are dense, not a bisection of the whole track - and
// leaves the new bracket's start there. The same index either way.
inline std::size_t FirstSampleAfter(const std::vector<double>& t, double v, std::size_t* from) {
  auto begin = t.begin(), end = t.end();
  if (from != nullptr && *from < t.size() && t[*from] <= v) {
    std::size_t lo = *from, step = 1;
    while (lo + step < t.size() && t[lo + step] <= v) {
      lo += step;
      step *= 2;
    }
    begin = t.begin() + static_cast<std::ptrdiff_t>(lo + 1);  // t[lo] <= v
    end = t.begin() + static_cast<std::ptrdiff_t>(std::min(lo + step + 1, t.size()));
  }
  const std::size_t hi = static_cast<std::size_t>(std::upper_bound(begin, end, v) - t.begin());
  if (from != nullptr) *from = hi - 1;
  return hi;
}

// Ground truth at time t_s by linear interpolation (heading along the shorter arc); clamps to the
// first/last sample outside the track. The track must hold at least one sample. T is double or a
// ceres::Jet (a time differentiated in a clock offset or a latency): the bracket is chosen on the
// value, the fraction keeps the derivatives. `from`: FirstSampleAfter's, for times asked in order.
template <typename T>
Pose2<T> InterpolateGroundTruth(const GroundTruthTrack& track, const T& t_s,
                                std::size_t* from = nullptr) {
  const std::vector<double>& t = track.t_s;
  const double v = ScalarPart(t_s);
  const auto sample = [](const Pose2d& q) { return Pose2<T>{T(q.x), T(q.y), T(q.theta)}; };
  if (v <= t.front()) return sample(track.world_T_robot.front());
  if (v >= t.back()) return sample(track.world_T_robot.back());
  const std::size_t hi = FirstSampleAfter(t, v, from);
  const std::size_t lo = hi - 1;
  const T u = (t_s - t[lo]) / (t[hi] - t[lo]);
  const Pose2d& a = track.world_T_robot[lo];
  const Pose2d& b = track.world_T_robot[hi];
  return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.theta + u * WrapAngle(b.theta - a.theta)};
}

}  // namespace fitcal
