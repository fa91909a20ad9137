#include "tools/import_optiodom_models.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "fit/final_pose_errors.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/text_file.h"
#include "models/diff_drive/diff_drive_model.h"
#include "odometry/aligned_run.h"
#include "tools/import_channel_order.h"
#include "tools/miswired_error.h"
#include "tools/optiodom_format.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

using io::InputError;
using io::InputErrorKind;

namespace {

// Runs the authors flagged as bad (../shared/data/optiodom/README.md).
struct FlaggedRun {
  const char* path_type;
  const char* session;
  int run;
  const char* reason;
};
constexpr FlaggedRun kFlaggedDiffRuns[] = {
    {"square", "231220200029", 2, "flagged as a bad run by the OptiOdom authors"},
};

struct DiffMetadata {
  double gear_ratio = 0.0;            // ngear
  double counts_per_motor_rev = 0.0;  // encRes
  double separation_m = 0.0;          // Li
  double diameter_right_m = 0.0;      // Di[0]
  double diameter_left_m = 0.0;       // Di[1]
  int num_runs = 0;                   // N
  double TicksPerWheelRev() const { return gear_ratio * counts_per_motor_rev; }
  bool SameRobotAs(const DiffMetadata& o) const {
    return separation_m == o.separation_m && diameter_right_m == o.diameter_right_m &&
           diameter_left_m == o.diameter_left_m;
  }
};

DiffMetadata ReadDiffMetadata(const std::string& path) {
  const optiodom::Metadata rows = optiodom::ReadMetadata(path, "diff");
  DiffMetadata m;
  m.gear_ratio = rows.Value("ngear", true);
  m.counts_per_motor_rev = rows.Value("encRes", true);
  m.separation_m = rows.Value("Li", true);
  const std::vector<double> d = rows.Values("Di", 2, true);
  m.diameter_right_m = d[0];
  m.diameter_left_m = d[1];
  m.num_runs = rows.NumRuns();
  return m;
}

// One run file: t, x, y, theta, ticks_right, ticks_left per row.
using DiffRun = optiodom::RunRows;

DiffRun ReadDiffRun(const std::string& path, int number) {
  return optiodom::ReadRun(path, number, 2, "ticks_right, ticks_left");
}

using DiffSession = optiodom::Session<DiffMetadata, DiffRun>;

DiffSession ReadDiffSession(const std::string& directory) {
  return optiodom::ReadSession<DiffMetadata, DiffRun>(
      directory, ReadDiffMetadata,
      [](const std::string& path, int number, const auto&) { return ReadDiffRun(path, number); });
}

const FlaggedRun* FindFlag(const DiffSession& s, int run) {
  for (const FlaggedRun& f : kFlaggedDiffRuns) {
    if (s.path_type == f.path_type && s.name == f.session && run == f.run) return &f;
  }
  return nullptr;
}

RunLog DiffRunLog(const DiffSession& s, const DiffRun& run, double ticks_per_rev) {
  RunLog log = optiodom::RunLogOf(s.path_type, s.name, run, ticks_per_rev, -1, '-');
  log.trajectory = s.path_type + "/" + s.name;
  return log;
}

RobotModelPtr NominalDiffDriveModel(const DiffMetadata& m) {
  Robot robot = DiffDriveRobotDescription("optiodom_diff", {"right", "left"});
  const double r_right = 0.5 * m.diameter_right_m, r_left = 0.5 * m.diameter_left_m;
  robot.nominal = {r_right, r_left, m.separation_m};
  // +-10 % around the nominal values: holds every value the sessions declare (b 0.2-0.205 m,
  // D 0.084-0.085 m) and any physically plausible calibration of this robot.
  const Interval radius{0.9 * std::min(r_right, r_left), 1.1 * std::max(r_right, r_left)};
  robot.bounds = {radius, radius, {0.9 * m.separation_m, 1.1 * m.separation_m}};
  robot.encoder = EncoderTicks{m.TicksPerWheelRev(), false};
  return std::make_shared<DiffDriveModel>(std::move(robot));
}

// The runs to write, session by session; notes sessions that declare other values and runs left
// out.
std::vector<const DiffRun*> CollectRuns(const std::vector<DiffSession>& sessions,
                                        const DiffMetadata& robot,
                                        const ImportOptiOdomDiffOptions& options,
                                        const std::string& out_dir,
                                        OptiOdomDiffImportSummary* summary) {
  const auto note = [&](const std::string& text) {
    summary->notes.push_back(text);
    if (!options.quiet) std::printf("%s\n", text.c_str());
  };
  std::vector<const DiffRun*> sources;
  for (const DiffSession& s : sessions) {
    if (s.metadata.TicksPerWheelRev() != robot.TicksPerWheelRev()) {
      throw InputError(
          InputErrorKind::kBadValue, s.metadata_path, 0,
          "ngear * encRes differs from the other sessions'; import one robot at a time");
    }
    if (!s.metadata.SameRobotAs(robot)) {
      char text[256];
      std::snprintf(text, sizeof text,
                    "session %s/%s declares b = %g m, D = %g / %g m (the robot YAML keeps the "
                    "majority's b = %g m, D = %g / %g m)",
                    s.path_type.c_str(), s.name.c_str(), s.metadata.separation_m,
                    s.metadata.diameter_right_m, s.metadata.diameter_left_m, robot.separation_m,
                    robot.diameter_right_m, robot.diameter_left_m);
      note(text);
    }
    for (const DiffRun& run : s.runs) {
      RunLog log = DiffRunLog(s, run, robot.TicksPerWheelRev());
      if (const FlaggedRun* flag = FindFlag(s, run.number)) {
        note(std::string(options.include_flagged ? "imported " : "left out ") + log.id + ": " +
             flag->reason);
        if (!options.include_flagged) continue;
      }
      sources.push_back(&run);
      summary->runs.push_back(std::move(log));
    }
  }
  optiodom::CheckUniqueRunIds(summary->runs, out_dir);
  return sources;
}

optiodom::DatasetText DiffDatasetText(const OptiOdomDiffImportSummary& summary,
                                      const std::vector<const DiffRun*>& sources) {
  optiodom::DatasetText text;
  text.encoder_csv = [&sources](std::size_t i) {
    return optiodom::IncrementsCsv("t,ticks_right,ticks_left", *sources[i], 9);
  };
  text.header =
      "# OptiOdom differential drive (Sousa et al. 2022, MIT licence), imported by fitcal\n";
  for (const std::string& n : summary.notes) text.header += "# " + n + "\n";
  return text;
}

}  // namespace

OptiOdomDiffImportSummary ImportOptiOdomDiff(const std::vector<std::string>& session_dirs,
                                             const std::string& out_dir,
                                             const ImportOptiOdomDiffOptions& options) {
  const std::vector<DiffSession> sessions =
      optiodom::ReadSessions<DiffSession>(session_dirs, out_dir, options.force, ReadDiffSession);
  OptiOdomDiffImportSummary summary;
  summary.num_sessions = static_cast<int>(sessions.size());
  const DiffMetadata& robot =
      optiodom::MajorityRobot(sessions, [](const DiffMetadata& a, const DiffMetadata& b) {
        return a.SameRobotAs(b);
      }).metadata;
  summary.separation_m = robot.separation_m;
  summary.diameter_right_m = robot.diameter_right_m;
  summary.diameter_left_m = robot.diameter_left_m;
  summary.ticks_per_rev = robot.TicksPerWheelRev();
  const std::vector<const DiffRun*> sources =
      CollectRuns(sessions, robot, options, out_dir, &summary);
  summary.num_runs = static_cast<int>(sources.size());
  const RobotModelPtr model = NominalDiffDriveModel(robot);
  const std::string order_check =
      CheckImportedChannelOrder(summary.runs, *model, options.skip_mapping_check);
  if (!options.quiet) std::printf("%s\n", order_check.c_str());
  const FinalPoseErrors nominal =
      EvaluateFinalPoseErrors(*model, model->robot().nominal, AlignRuns(summary.runs));
  summary.nominal_cf = nominal.cf;
  summary.nominal_mean_position_error_m = nominal.mean_position_error_m;
  summary.nominal_mean_heading_error_rad = nominal.mean_abs_heading_error_rad;
  optiodom::WriteDataset(summary.runs, *model, DiffDatasetText(summary, sources), out_dir,
                         options.force, session_dirs);
  if (!options.quiet) {
    std::printf(
        "wrote %d runs of %d sessions to %s; nominal CF (Eq. 14) %.4f, mean final "
        "position error %.4f m, heading %.3f deg\n",
        summary.num_runs, summary.num_sessions, out_dir.c_str(), summary.nominal_cf,
        summary.nominal_mean_position_error_m,
        summary.nominal_mean_heading_error_rad * 180.0 / M_PI);
  }
  return summary;
}

}  // namespace fitcal::tools
