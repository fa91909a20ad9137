#include "fit/clock_alignment.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "fit/model_fit.h"
#include "fit/residual_choice.h"
#include "fit/track_residual.h"
#include "io/command_failure.h"
#include "odometry/aligned_run.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

// "n of m runs re-stamped ..., offsets median x s, range [a, b] s"
std::string Summary(const std::string& what, int moved, std::size_t runs,
                    const std::vector<std::pair<std::string, double>>& offsets) {
  double lo = 0.0, hi = 0.0;
  for (std::size_t g = 0; g < offsets.size(); ++g) {
    lo = g == 0 ? offsets[g].second : std::min(lo, offsets[g].second);
    hi = g == 0 ? offsets[g].second : std::max(hi, offsets[g].second);
  }
  // An offset on the fit's bound is where the solver stopped, not a measured lag: said, so that
  // a re-stamp by it is not taken for one (the runs then determine no offset of that group).
  const double bound_s = kMaxClockOffsetS;
  int on_bound = 0;
  for (const auto& [group, offset_s] : offsets) on_bound += std::abs(offset_s) >= bound_s - 1e-6;
  const std::string line = StrFormat(
      "clock offsets: %s, %zu groups in [%+.3f, %+.3f] s; ground truth of %d of %zu runs "
      "re-stamped",
      what.c_str(), offsets.size(), lo, hi, moved, runs);
  if (on_bound == 0) return line;
  return line + "; " + std::to_string(on_bound) + " of them on the +-" +
         StrFormat("%g", bound_s) +
         " s bound: not determined by these runs (--clock-offsets none keeps the stamps)";
}

// Offsets estimated on the logs' tracks, `parameters` held (or fitted with them when null).
std::vector<std::pair<std::string, double>> Estimate(ClockGrouping grouping,
                                                     const RobotModelInterface& model,
                                                     const std::vector<double>* parameters,
                                                     int threads, const std::vector<RunLog>& logs) {
  const std::vector<AlignedRun> runs = AlignRuns(logs);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
  const TrackFitData data = MakeTrackFitData(runs, tracks, grouping);
  ModelFitOptions options;
  options.residuals = ResidualKind::kTrack;
  options.track = &data;
  options.ceres.num_threads = threads;
  options.ceres.compute_covariance = false;
  std::vector<double> offsets_s;
  if (parameters != nullptr) {
    offsets_s = EstimateClockOffsets(model, *parameters, options);
  } else {
    const ModelFitResult fit = FitModel(runs, model, options);
    if (!fit.usable)
      throw std::runtime_error("the track fit for the clock offsets did not converge");
    offsets_s = fit.clock_offsets_s;
  }
  std::vector<std::pair<std::string, double>> out;
  for (std::size_t g = 0; g < data.clock_groups.size(); ++g)
    out.emplace_back(data.clock_groups[g], offsets_s[g]);
  return out;
}

// "recorded, none, session, run, dataset" (with_recorded) or without "recorded".
std::string ClockOffsetModes(bool with_recorded) {
  return with_recorded ? "recorded, none, session, run, dataset" : "none, session, run, dataset";
}

}  // namespace

std::string AlignGroundTruthClocks(const std::string& mode, const RobotModelInterface& model,
                                   const std::vector<double>* parameters,
                                   const std::optional<io::CalibrationProvenance>& recorded,
                                   int threads, std::vector<RunLog>* logs) {
  if (mode == "none") return "";
  if (mode == "recorded") {
    if (!recorded || recorded->clock_offsets.empty()) return "";
    ClockGrouping grouping;
    if (!ParseClockGrouping(recorded->clock_offset_grouping, &grouping)) {
      throw std::invalid_argument("calibration.clock_offsets.grouping '" +
                                  recorded->clock_offset_grouping + "' is not one of " +
                                  ClockOffsetModes(false));
    }
    std::vector<std::pair<std::string, double>> offsets;
    for (const auto& c : recorded->clock_offsets) offsets.emplace_back(c.group, c.offset_s);
    const int moved = ShiftGroundTruthClocks(offsets, grouping, logs);
    if (moved == 0) {
      return "clock offsets: the calibration's " + std::to_string(offsets.size()) + " " +
             recorded->clock_offset_grouping +
             " offsets name none of these runs' groups; ground truth as stamped (estimate "
             "them here with --clock-offsets " + recorded->clock_offset_grouping + ")";
    }
    return Summary("recorded by the calibration", moved, logs->size(), offsets);
  }
  ClockGrouping grouping;
  if (!ParseClockGrouping(mode, &grouping) || grouping == ClockGrouping::kNone) {
    throw std::invalid_argument("--clock-offsets " + mode + ": expected one of " +
                                ClockOffsetModes(true));
  }
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : *logs) tracks.push_back(&log.ground_truth);
  // An offset moves a pose along the path by speed x offset; the poses of a ground truth of
  // start and end only (the robot at rest there) do not move with it: nothing to estimate, and a
  // fit of it ends on the bound (report re-stamped by +-0.5 s without a word).
  const TrackDensity density = MeasureTrackDensity(AlignRuns(*logs), tracks);
  if (!density.SamplesThePath()) {
    throw UsageError("--clock-offsets " + mode +
                     " is estimated on a ground-truth track, and these runs' ground truth has " +
                     StrFormat("%.0f", density.median_intervals) +
                     " sample intervals between a run's ends (median; start and end poses only?): "
                     "no offset to estimate (--clock-offsets none)");
  }
  const auto offsets = Estimate(grouping, model, parameters, threads, *logs);
  const int moved = ShiftGroundTruthClocks(offsets, grouping, logs);
  const std::string how = parameters != nullptr ? " with the calibrated parameters held"
                                                : " with a track fit of the parameters";
  return Summary("estimated per " + mode + how, moved, logs->size(), offsets);
}

}  // namespace fitcal
