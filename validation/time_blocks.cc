#include "validation/time_blocks.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "fit/track_residual.h"
#include "odometry/pose2.h"

namespace fitcal {
namespace {

// How far a boundary may move from its equal-path place, as a fraction of a block's path: the
// blocks stay between half and one and a half of the equal length.
constexpr double kBoundaryReach = 0.25;

// What a clock error of up to `lag_s` moves the ground truth's pose at t by, in Palacin Eq. 14's
// units (m and rad alike): |Q(t - lag)^-1 Q(t + lag)|.
double PoseChangeAround(const GroundTruthTrack& track, double t_s, double lag_s) {
  const Pose2d a = InterpolateGroundTruth(track, t_s - lag_s);
  const Pose2d b = InterpolateGroundTruth(track, t_s + lag_s);
  const double turn = WrapAngle(b.theta - a.theta);  // not 2 pi where the heading wraps
  return std::sqrt((b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y) + turn * turn);
}

// The boundary (after sample k) near `at` whose ground-truth pose a clock error moves least,
// within `reach_m` of path of it and after `first`: scanning outwards from `at`, a later candidate
// wins only by more than the ground truth resolves (1e-6: a micrometre, a microradian).
std::size_t SteadiestBoundary(const GroundTruthTrack& track, const std::vector<double>& t,
                              const std::vector<double>& s, std::size_t at, std::size_t first,
                              double reach_m) {
  const double lag_s = kMaxClockOffsetS;
  const std::size_t n = s.size() - 1;
  if (at >= n) return at;
  std::size_t best = at;
  double best_change = PoseChangeAround(track, t[at], lag_s);
  for (std::size_t d = 1;; ++d) {
    bool any = false;
    for (std::size_t k : {at + d, at >= d ? at - d : n}) {
      if (k < first || k >= n || std::abs(s[k] - s[at]) > reach_m) continue;
      any = true;
      const double change = PoseChangeAround(track, t[k], lag_s);
      if (change < best_change - 1e-6) best = k, best_change = change;
    }
    if (!any) return best;
  }
}

}  // namespace

std::vector<AlignedRun> CutIntoTimeBlocks(const AlignedRun& run, int num_blocks) {
  const std::size_t n = run.samples.size();
  if (num_blocks < 1 || n < static_cast<std::size_t>(num_blocks)) {
    throw std::invalid_argument("CutIntoTimeBlocks: run " + run.id + " has too few samples");
  }
  if (run.track == nullptr) {
    throw std::invalid_argument("CutIntoTimeBlocks: run " + run.id + " has no ground-truth track");
  }
  const GroundTruthTrack& track = *run.track;
  // Boundary b lies after b samples; its ground-truth path length from the start.
  const BoundaryGroundTruth boundaries = GroundTruthAtBoundaries(run, track);
  const std::vector<double>& t = boundaries.t_s;
  const std::vector<double>& s = boundaries.path_m;
  std::vector<std::size_t> cut = {0};
  const double reach_m = s[n] / num_blocks * kBoundaryReach;
  for (int b = 1; b < num_blocks; ++b) {
    const double target_m = s[n] * b / num_blocks;
    std::size_t k = cut.back() + 1;
    while (k < n && s[k] < target_m) ++k;
    cut.push_back(SteadiestBoundary(track, t, s, k, cut.back() + 1, reach_m));
  }
  cut.push_back(n);
  std::vector<AlignedRun> blocks;
  for (int b = 0; b < num_blocks; ++b) {
    const std::size_t begin = cut[b], end = cut[b + 1];
    if (end <= begin) continue;  // a path that stalls: fewer blocks
    AlignedRun block;
    block.id = run.id + "-block" + std::to_string(b + 1);
    block.trajectory = run.trajectory;
    block.repetition = b + 1;
    block.t_start_s = t[begin];
    block.t_final_s = t[end];
    block.start = boundaries.pose[begin];
    block.final_ground_truth = boundaries.pose[end];
    block.track = run.track;  // a block replays against its run's track
    block.samples = EncoderSamples(run.samples.num_channels());
    for (std::size_t k = begin; k < end; ++k) block.samples.push_back(run.samples[k]);
    blocks.push_back(std::move(block));
  }
  return blocks;
}

}  // namespace fitcal
