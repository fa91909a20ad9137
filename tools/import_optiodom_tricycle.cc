#include "tools/import_optiodom_tricycle.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "fit/final_pose_errors.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "models/tricycle/tricycle_checks.h"
#include "models/tricycle/tricycle_model.h"
#include "odometry/aligned_run.h"
#include "tools/import_channel_order.h"
#include "tools/miswired_error.h"
#include "tools/optiodom_format.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

using io::InputError;
using io::InputErrorKind;
using K = TricycleKinematics;

namespace {

OptiOdomTricycleMetadata ReadMetadata(const std::string& path) {
  const optiodom::Metadata rows = optiodom::ReadMetadata(path, "tricyc");
  OptiOdomTricycleMetadata meta;
  meta.gear_ratio = rows.Value("ngear", true);
  meta.encoder_counts_per_rev = rows.Value("encRes", true);
  meta.wheelbase_m = rows.Value("Li", true);
  meta.diameter_m = rows.Value("Di", true);
  meta.steering_offset_rad = rows.Value("Thi", false);
  meta.num_runs = rows.NumRuns();
  return meta;
}

OptiOdomTricycleRun ReadRun(const std::string& path, int number) {
  static_assert(K::kTractionChannel == 0 && K::kSteeringChannel == 1, "the file's column order");
  OptiOdomTricycleRun run =
      optiodom::ReadRun(path, number, 2, "ticks, steering", ": no steering column");
  std::vector<double> steering_rad;
  for (const std::vector<double>& e : run.encoder) steering_rad.push_back(e[K::kSteeringChannel]);
  tricycle::CheckSteeringReadings(steering_rad, path, run.first_line);
  return run;
}

}  // namespace

OptiOdomTricycleSession ReadOptiOdomTricycleSession(const std::string& directory) {
  return optiodom::ReadSession<OptiOdomTricycleMetadata, OptiOdomTricycleRun>(
      directory, ReadMetadata,
      [](const std::string& path, int number, const auto&) { return ReadRun(path, number); });
}

RobotModelPtr OptiOdomTricycleNominalModel(const OptiOdomTricycleMetadata& metadata) {
  Robot robot = TricycleRobotDescription("optiodom_tricycle", "traction");
  const double radius_m = 0.5 * metadata.diameter_m;
  robot.nominal.resize(K::kNumParameters);
  robot.nominal[K::kRadiusIndex] = radius_m;
  robot.nominal[K::kWheelbaseIndex] = metadata.wheelbase_m;
  robot.nominal[K::kSteeringOffsetIndex] = metadata.steering_offset_rad;
  robot.bounds.resize(K::kNumParameters);
  robot.bounds[K::kRadiusIndex] = {0.9 * radius_m, 1.1 * radius_m};
  robot.bounds[K::kWheelbaseIndex] = {0.85 * metadata.wheelbase_m, 1.15 * metadata.wheelbase_m};
  robot.bounds[K::kSteeringOffsetIndex] = {metadata.steering_offset_rad - DegToRad(10.0),
                                           metadata.steering_offset_rad + DegToRad(10.0)};
  robot.encoder = EncoderTicks{metadata.TicksPerWheelRev(), false};
  return std::make_shared<TricycleModel>(std::move(robot));
}

RunLog OptiOdomTricycleRunLog(const OptiOdomTricycleSession& session,
                              const OptiOdomTricycleRun& run, int session_repetition) {
  RunLog log = optiodom::RunLogOf(session.path_type, session.name, run,
                                  session.metadata.TicksPerWheelRev(), K::kSteeringChannel);
  const double turn_rad =
      run.ground_truth.world_T_robot.back().theta - run.ground_truth.world_T_robot.front().theta;
  log.trajectory = session.path_type + (turn_rad < 0.0 ? "_cw" : "_ccw");
  log.repetition = session_repetition;
  return log;
}

namespace {

// Repetition of each session: its place among the sessions of its path type, by name (the
// names are timestamps, so 1 = earliest).
std::vector<int> SessionRepetitions(const std::vector<OptiOdomTricycleSession>& sessions) {
  std::vector<int> repetition(sessions.size());
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    int earlier = 0;
    for (const OptiOdomTricycleSession& other : sessions) {
      earlier += other.path_type == sessions[i].path_type && other.name < sessions[i].name;
    }
    repetition[i] = earlier + 1;
  }
  return repetition;
}

}  // namespace

ImportOptiOdomTricycleSummary ImportOptiOdomTricycle(const std::vector<std::string>& sessions,
                                                     const std::string& out,
                                                     const ImportOptiOdomTricycleOptions& options) {
  const std::vector<OptiOdomTricycleSession> read = optiodom::ReadSessions<OptiOdomTricycleSession>(
      sessions, out, options.force, ReadOptiOdomTricycleSession);
  optiodom::CheckOneRobot(read, [](const OptiOdomTricycleMetadata& a,
                                   const OptiOdomTricycleMetadata& b) {
    return a.gear_ratio == b.gear_ratio && a.encoder_counts_per_rev == b.encoder_counts_per_rev &&
           a.wheelbase_m == b.wheelbase_m && a.diameter_m == b.diameter_m &&
           a.steering_offset_rad == b.steering_offset_rad;
  });
  const RobotModelPtr model = OptiOdomTricycleNominalModel(read.front().metadata);
  const std::vector<int> repetition = SessionRepetitions(read);

  ImportOptiOdomTricycleSummary summary;
  summary.num_sessions = static_cast<int>(read.size());
  std::vector<const OptiOdomTricycleRun*> sources;
  for (std::size_t i = 0; i < read.size(); ++i) {
    for (const OptiOdomTricycleRun& run : read[i].runs) {
      summary.runs.push_back(OptiOdomTricycleRunLog(read[i], run, repetition[i]));
      sources.push_back(&run);
    }
  }
  optiodom::CheckUniqueRunIds(summary.runs, out);
  summary.channel_order = CheckImportedChannelOrder(summary.runs, *model, options.skip_sign_check);
  const FinalPoseErrors nominal =
      EvaluateFinalPoseErrors(*model, model->robot().nominal, AlignRuns(summary.runs), 1);
  summary.nominal_final_error = nominal.per_run_cf;
  summary.nominal_cf = nominal.cf;

  optiodom::DatasetText text;
  text.encoder_csv = [&](std::size_t i) {
    return optiodom::IncrementsCsv("t,ticks_traction,steering", *sources[i], 6,
                                   K::kSteeringChannel);
  };
  optiodom::WriteDataset(summary.runs, *model, text, out, options.force, sessions);
  return summary;
}

}  // namespace fitcal::tools
