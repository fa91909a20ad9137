#include "odometry/aligned_run.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fitcal {

namespace {
// Every channel of the sample reads zero (wheel rates and angles alike: an interval with a
// non-zero angle channel is kept as it is, whatever the model makes of it).
bool IsRest(const double* values, int num_channels) {
  return std::all_of(values, values + num_channels, [](double v) { return v == 0.0; });
}
}  // namespace

AlignedRun AlignRun(const RunLog& run) {
  const std::vector<double>& t = run.encoders.t_s;
  const GroundTruthTrack& gt = run.ground_truth;
  AlignedRun out;
  out.id = run.id;
  out.trajectory = run.trajectory;
  out.repetition = run.repetition;
  if (run.start_pose) {
    out.t_start_s = t.front();
    out.start = *run.start_pose;
  } else {
    out.t_start_s = std::max(t.front(), gt.t_s.front());
    out.start = InterpolateGroundTruth(gt, out.t_start_s);
  }
  out.t_final_s = std::min(t.back(), gt.t_s.back());
  if (!(out.t_final_s > out.t_start_s)) {
    throw std::invalid_argument("run " + run.id + ": encoders and ground truth share no time");
  }
  out.final_ground_truth = InterpolateGroundTruth(gt, out.t_final_s);
  out.track = std::make_shared<const GroundTruthTrack>(gt);
  const int channels = run.encoders.samples.num_channels();
  out.samples = EncoderSamples(channels);
  out.samples.reserve(run.encoders.samples.size());
  for (std::size_t k = 0; k < run.encoders.samples.size(); ++k) {
    const double begin = std::max(t[k], out.t_start_s);
    const double end = std::min(t[k + 1], out.t_final_s);
    if (end <= begin) continue;
    const ConstSampleView sample = run.encoders.samples[k];
    const double dt = end - begin;
    // Consecutive intervals with all wheels at rest move nothing under any model: one interval
    // of their summed length keeps the time line and saves the replay the work (robots log
    // long rests before and after each run).
    if (IsRest(sample.value, channels) && !out.samples.empty() &&
        IsRest(out.samples.back().value, channels)) {
      out.samples.back().dt_s += dt;
      continue;
    }
    out.samples.push_back(dt, sample.value);
  }
  return out;
}

std::vector<AlignedRun> AlignRuns(const std::vector<RunLog>& runs) {
  std::vector<AlignedRun> out;
  out.reserve(runs.size());
  for (const RunLog& run : runs) out.push_back(AlignRun(run));
  return out;
}

std::vector<const GroundTruthTrack*> TracksOf(const std::vector<AlignedRun>& runs) {
  std::vector<const GroundTruthTrack*> tracks;
  tracks.reserve(runs.size());
  for (const AlignedRun& run : runs) {
    if (run.track == nullptr) {
      throw std::invalid_argument("run " + run.id + " was aligned without its ground-truth track");
    }
    tracks.push_back(run.track.get());
  }
  return tracks;
}

std::vector<double> BoundaryTimes(const AlignedRun& run) {
  std::vector<double> t(run.samples.size() + 1);
  t[0] = run.t_start_s;
  for (std::size_t k = 0; k < run.samples.size(); ++k) t[k + 1] = t[k] + run.samples[k].dt_s;
  return t;
}

BoundaryGroundTruth GroundTruthAtBoundaries(const AlignedRun& run, const GroundTruthTrack& track) {
  BoundaryGroundTruth out;
  out.t_s = BoundaryTimes(run);
  out.pose.resize(out.t_s.size());
  out.path_m.assign(out.t_s.size(), 0.0);
  std::size_t bracket = 0;  // the times rise: each search starts where the last one ended
  for (std::size_t b = 0; b < out.t_s.size(); ++b) {
    out.pose[b] = InterpolateGroundTruth(track, out.t_s[b], &bracket);
    if (b == 0) continue;
    const Pose2d& from = out.pose[b - 1];
    out.path_m[b] = out.path_m[b - 1] + std::hypot(out.pose[b].x - from.x, out.pose[b].y - from.y);
  }
  return out;
}

}  // namespace fitcal
