#pragma once
// Drift per distance travelled: the relative pose error over windows of a set ground-truth path
// length, the metric of the KITTI odometry benchmark (Geiger et al. 2012, devkit evaluate_odometry:
// translation error in % of the length, rotation error per metre) and of evo_rpe with a delta in
// metres. For a window from ground-truth sample i to the first sample j at least `length_m` of
// path further,
//   E = (gt_i^-1 gt_j)^-1 (odo_i^-1 odo_j),
//   translation error = |t(E)| / length_m,   rotation error = |wrap(theta(E))| / length_m.
// A window starts at every sample (KITTI: every 10th frame at 10 Hz, i.e. once a second); the
// means weigh every window alike.

#include <cstddef>
#include <vector>

#include "odometry/pose2.h"

namespace fitcal {

// One window of one run: samples start..end of the run, the errors of E above.
struct RelativePoseErrorWindow {
  std::size_t start = 0, end = 0;
  double translation_ratio = 0.0;  // |t(E)| / length (unitless; x 100 for %)
  double rotation_rad_per_m = 0.0;  // |wrap(theta(E))| / length
};

struct RelativePoseErrorSum {
  int windows = 0;
  double translation_ratio_sum = 0.0;  // sum of |t(E)| / length (unitless)
  double rotation_rad_per_m_sum = 0.0;
  void Add(const RelativePoseErrorWindow& w) {
    translation_ratio_sum += w.translation_ratio;
    rotation_rad_per_m_sum += w.rotation_rad_per_m;
    ++windows;
  }
  double MeanTranslationPercent() const {
    return windows > 0 ? 100.0 * translation_ratio_sum / windows : 0.0;
  }
  double MeanRotationRadPerM() const {
    return windows > 0 ? rotation_rad_per_m_sum / windows : 0.0;
  }
};

// The ground-truth side of one run's windows, for windows of any length: its poses, its path
// length from its first sample and each pose's heading as (cos, sin). It depends on the ground
// truth alone: made once per run, it serves every odometry replayed against it (a window needs
// the heading at its start; each length's windows start at most samples).
class RelativePoseErrorTruth {
 public:
  explicit RelativePoseErrorTruth(std::vector<Pose2d> ground_truth);

 private:
  friend class RelativePoseErrorRun;
  struct Heading {
    double c, s;
  };
  std::vector<Pose2d> poses_;
  std::vector<double> path_m_;  // path length from sample 0
  std::vector<Heading> heading_;
};

// One run's odometry against its ground truth's side, at the same times in any one world frame
// each; both must outlive this. The run is the first min(sizes) samples of both.
class RelativePoseErrorRun {
 public:
  RelativePoseErrorRun(const RelativePoseErrorTruth& truth, const std::vector<Pose2d>& odometry);

  // Every window (the pictures draw them one by one; their sum is the mean). Runs shorter than
  // length_m have none.
  std::vector<RelativePoseErrorWindow> Windows(double length_m) const;
  void Add(double length_m, RelativePoseErrorSum* sum) const;

 private:
  // Calls window(w) for each window of `length_m`, in the order of their start.
  template <typename Visit>
  void ForEachWindow(double length_m, Visit&& window) const;

  const RelativePoseErrorTruth& truth_;
  const std::vector<Pose2d>& odometry_;
  std::size_t n_;
  std::vector<RelativePoseErrorTruth::Heading> odometry_heading_;
};

// Window lengths for runs of this median path length: the largest three of 0.25, 0.5, 1, 2, 5,
// 10, 20, 50, 100 m that fit twice into it (so that every run holds windows of each).
std::vector<double> RelativePoseErrorLengths(double median_path_length_m);

}  // namespace fitcal
