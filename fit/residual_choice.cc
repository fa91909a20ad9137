#include "fit/residual_choice.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fitcal {

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

TrackDensity MeasureTrackDensity(const std::vector<AlignedRun>& runs,
                                 const std::vector<const GroundTruthTrack*>& tracks,
                                 const TrackResidualOptions& options) {
  if (runs.size() != tracks.size()) {
    throw std::invalid_argument("MeasureTrackDensity: not one ground truth per run");
  }
  std::vector<double> paths, spacings, counts;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const GroundTruthTrack& track = *tracks[i];
    double path_m = 0.0;
    int intervals = 0;
    for (std::size_t k = 1; k < track.t_s.size(); ++k) {
      if (track.t_s[k - 1] < runs[i].t_start_s || track.t_s[k] > runs[i].t_final_s) continue;
      const Pose2d& a = track.world_T_robot[k - 1];
      const Pose2d& b = track.world_T_robot[k];
      path_m += std::hypot(b.x - a.x, b.y - a.y);
      ++intervals;
    }
    paths.push_back(path_m);
    counts.push_back(intervals);
    spacings.push_back(intervals > 0 ? path_m / intervals
                                     : std::numeric_limits<double>::infinity());
  }
  TrackDensity out;
  out.median_path_m = Median(paths);
  out.median_sample_spacing_m = Median(spacings);
  out.median_intervals = Median(counts);
  const double spacing = options.checkpoint_spacing_m;
  out.dense = out.median_sample_spacing_m <= kMaxSampleSpacingFraction * spacing &&
              out.median_path_m >= kMinCheckpointsPerRun * spacing;
  return out;
}

}  // namespace fitcal
