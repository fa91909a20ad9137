#include "validation/time_blocks.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace fitcal {

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
  std::vector<double> t(n + 1), s(n + 1, 0.0);
  t[0] = run.t_start_s;
  Pose2d previous = InterpolateGroundTruth(track, t[0]);
  for (std::size_t k = 0; k < n; ++k) {
    t[k + 1] = t[k] + run.samples[k].dt_s;
    const Pose2d q = InterpolateGroundTruth(track, t[k + 1]);
    s[k + 1] = s[k] + std::hypot(q.x - previous.x, q.y - previous.y);
    previous = q;
  }
  std::vector<std::size_t> cut = {0};
  for (int b = 1; b < num_blocks; ++b) {
    const double target_m = s[n] * b / num_blocks;
    std::size_t k = cut.back() + 1;
    while (k < n && s[k] < target_m) ++k;
    cut.push_back(k);
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
    block.start = InterpolateGroundTruth(track, t[begin]);
    block.final_ground_truth = InterpolateGroundTruth(track, t[end]);
    block.track = run.track;  // a block replays against its run's track
    block.samples = EncoderSamples(run.samples.num_channels());
    for (std::size_t k = begin; k < end; ++k) block.samples.push_back(run.samples[k]);
    blocks.push_back(std::move(block));
  }
  return blocks;
}

}  // namespace fitcal
