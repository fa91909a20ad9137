#include "calibrate/track_residuals.h"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include "fit/parameter_tying.h"
#include "validation/residual_dof.h"

namespace fitcal {

std::string PrepareTrackResiduals(const std::string& method,
                                  const std::vector<AlignedRun>& training,
                                  FitMethodSettings* settings, std::optional<TrackFitData>* data) {
  const std::vector<const GroundTruthTrack*> tracks = TracksOf(training);
  ResolveAutoResiduals(training, tracks, method, settings);
  if (settings->residuals == ResidualKind::kFinalPose) return "";
  if (!IsCeresMethod(method)) {
    return std::string("--residuals ") + ToString(settings->residuals) +
           " needs a Ceres method (--method ceres or ceres-dogleg); " + method +
           " fits final poses only";
  }
  TrackResidualOptions track_options;
  track_options.heading = settings->track_heading;
  data->emplace(MakeTrackFitData(training, tracks, settings->clock_grouping, track_options));
  settings->track = &**data;
  return "";
}

std::string DegreesOfFreedomRefusal(const RunSplit& split, const FitMethodSettings& settings,
                                    const std::optional<TrackFitData>& track,
                                    std::size_t num_parameters) {
  if (!track) return FinalPoseDofRefusal(split.training.size(), num_parameters);
  std::size_t checkpoints = 0;
  for (const TrackCheckpoints& run : track->runs) checkpoints += run.segments.size();
  std::size_t residuals = 3 * checkpoints;
  if (settings.residuals == ResidualKind::kBoth) residuals += 3 * split.training.size();
  if (track->estimate_clock_offsets) num_parameters += track->clock_groups.size();
  const std::size_t runs = std::max<std::size_t>(1, split.training.size());
  return ResidualDofRefusal(residuals, num_parameters, split.training.size(), "track",
                            residuals / runs);
}

std::optional<std::vector<TrackRun>> TrainingTracks(const std::string& dataset, const Robot& robot,
                                                    const std::vector<RunLog>& logs,
                                                    const RunSplit& split, std::string* refusal) {
  std::unordered_map<std::string, const RunLog*> by_id;
  for (const RunLog& log : logs) by_id[log.id] = &log;
  std::vector<RunLog> training;
  for (const AlignedRun& run : split.training) training.push_back(*by_id.at(run.id));
  try {
    return PrepareTrackRuns(training, WheelChannelMask(robot));
  } catch (const std::invalid_argument& e) {
    *refusal = "fit: " + dataset +
               ": effects are fitted on the ground truth along each run (a track): " + e.what() +
               "; nothing written";
    return std::nullopt;
  }
}

std::size_t NumFreeWithTying(const RobotModelInterface& model, const ParameterTying& tying) {
  if (tying.empty()) return model.robot().NumFree();
  return TiedModel(model, tying).robot().NumFree();
}

}  // namespace fitcal
