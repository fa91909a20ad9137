#include "tools/import_optiodom.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "fit/final_pose_errors.h"
#include "fit/segment_cost.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/input_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/aligned_run.h"
#include "tools/import_channel_order.h"
#include "tools/import_optiodom_models.h"
#include "tools/import_optiodom_omni4.h"
#include "tools/import_optiodom_tricycle.h"
#include "tools/miswired_error.h"
#include "tools/optiodom_format.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

using io::InputError;
using io::InputErrorKind;

namespace {

// Our wheel angles (deg) for the authors' wheels 1, 2, 3; see the header.
constexpr double kWheelAngleDeg[3] = {300.0, 60.0, 180.0};
// Our wheel rate = kTickSign * the authors' (the header derives it).
constexpr double kTickSign = -1.0;

OptiOdomMetadata ReadMetadata(const std::string& path) {
  const optiodom::Metadata rows = optiodom::ReadMetadata(path, "omni3");
  OptiOdomMetadata meta;
  meta.type = rows.type;
  meta.gear_ratio = rows.Value("ngear", true);
  meta.encoder_counts_per_rev = rows.Value("encRes", true);
  meta.distance_m = rows.Value("Li", true);
  const std::vector<double> d = rows.Values("Di", 3, true);
  std::copy(d.begin(), d.end(), meta.diameter_m.begin());
  meta.num_runs = rows.NumRuns();
  const std::size_t runs = static_cast<std::size_t>(meta.num_runs);
  meta.gt_ti_s = rows.Values("gt_ti", runs, false);
  meta.gt_tf_s = rows.Values("gt_tf", runs, false);
  meta.odo_ti_s = rows.Values("odo_ti", runs, false);
  meta.odo_tf_s = rows.Values("odo_tf", runs, false);
  return meta;
}

OptiOdomRun ReadRun(const std::string& path, int number) {
  OptiOdomRun run = optiodom::ReadRun(path, number, 3, "ticks_1, ticks_2, ticks_3");
  for (std::vector<double>& ticks : run.encoder) {
    for (double& t : ticks) t = kTickSign * t + 0.0;  // + 0.0 keeps a flipped 0 at 0
  }
  return run;
}

}  // namespace

OptiOdomSession ReadOptiOdomSession(const std::string& directory) {
  return optiodom::ReadSession<OptiOdomMetadata, OptiOdomRun>(
      directory, ReadMetadata,
      [](const std::string& path, int number, const auto&) { return ReadRun(path, number); });
}

Omni3Robot OptiOdomNominalRobot(const OptiOdomMetadata& metadata) {
  Omni3Robot robot;
  robot.name = "optiodom_omni3";
  robot.wheel_names = {"a", "b", "c"};
  for (int i = 0; i < 3; ++i) {
    robot.nominal.distance_m[i] = metadata.distance_m;
    robot.nominal.radius_m[i] = 0.5 * metadata.diameter_m[i];
    robot.nominal.angle_rad[i] = DegToRad(kWheelAngleDeg[i]);
  }
  // Palacin Eq. 16 gives R +- 0.025 m, r +- 0.010 m on r = 0.148 m (6.8 %), delta +- 2 deg: the
  // same physical box scaled to this robot's wheels, with R widened by kTrackedPointOffset_m: the
  // ground truth tracks the marker centroid, not the kinematic centre, and an offset e shifts
  // every fitted R_i by up to |e| (README, "Why the distances run into their bounds"; ~3 cm on
  // this robot, which left a distance on Eq. 16's bound and the fit without convergence).
  constexpr double kTrackedPointOffset_m = 0.025;
  const double r_min =
      *std::min_element(robot.nominal.radius_m.begin(), robot.nominal.radius_m.end());
  const double r_max =
      *std::max_element(robot.nominal.radius_m.begin(), robot.nominal.radius_m.end());
  robot.bounds.distance_m = {metadata.distance_m - 0.025 - kTrackedPointOffset_m,
                             metadata.distance_m + 0.025 + kTrackedPointOffset_m};
  robot.bounds.radius_m = {r_min * (1.0 - 0.01 / 0.148), r_max * (1.0 + 0.01 / 0.148)};
  robot.bounds.angle_offset_rad = {DegToRad(-2.0), DegToRad(2.0)};
  robot.encoder = EncoderTicks{metadata.TicksPerWheelRev(), false};
  return robot;
}

RunLog OptiOdomRunLog(const OptiOdomSession& session, const OptiOdomRun& run) {
  return optiodom::RunLogOf(session.path_type, session.name, run,
                            session.metadata.TicksPerWheelRev());
}

namespace {

void ImportOmni3(const ImportOptiOdomOptions& options) {
  const std::vector<OptiOdomSession> sessions = optiodom::ReadSessions<OptiOdomSession>(
      options.sessions, options.out, options.force, ReadOptiOdomSession);
  optiodom::CheckOneRobot(sessions, [](const OptiOdomMetadata& a, const OptiOdomMetadata& b) {
    return a.gear_ratio == b.gear_ratio && a.encoder_counts_per_rev == b.encoder_counts_per_rev &&
           a.distance_m == b.distance_m && a.diameter_m == b.diameter_m;
  });
  const std::shared_ptr<const Omni3Model> robot =
      Omni3ModelOf(OptiOdomNominalRobot(sessions.front().metadata));
  std::vector<RunLog> logs;
  std::vector<const OptiOdomRun*> sources;
  for (const OptiOdomSession& s : sessions) {
    for (const OptiOdomRun& run : s.runs) {
      logs.push_back(OptiOdomRunLog(s, run));
      sources.push_back(&run);
    }
  }
  optiodom::CheckUniqueRunIds(logs, options.out);
  std::printf("%s\n", CheckImportedChannelOrder(logs, *robot, options.skip_mapping_check).c_str());
  optiodom::DatasetText text;
  text.encoder_csv = [&](std::size_t i) {
    return optiodom::IncrementsCsv("t,ticks_a,ticks_b,ticks_c", *sources[i], 6);
  };
  optiodom::WriteDataset(logs, *robot, text, options.out, options.force, options.sessions);
  std::printf("wrote %zu runs of %zu sessions to %s\n", logs.size(), sessions.size(),
              options.out.c_str());
}

void ImportDiff(const ImportOptiOdomOptions& options) {
  ImportOptiOdomDiffOptions diff;
  diff.force = options.force;
  diff.skip_mapping_check = options.skip_mapping_check;
  ImportOptiOdomDiff(options.sessions, options.out, diff);  // prints its own summary
}

void ImportTricycle(const ImportOptiOdomOptions& options) {
  ImportOptiOdomTricycleOptions tricycle;
  tricycle.force = options.force;
  tricycle.skip_sign_check = options.skip_mapping_check;
  const ImportOptiOdomTricycleSummary s =
      ImportOptiOdomTricycle(options.sessions, options.out, tricycle);
  std::printf("%s\n", s.channel_order.c_str());
  std::printf("imported %zu runs of %d tricycle sessions into %s; nominal CF (Eq. 14) %.4f\n",
              s.runs.size(), s.num_sessions, options.out.c_str(), s.nominal_cf);
}

void ImportOmni4(const ImportOptiOdomOptions& options) {
  const Omni4ImportResult s =
      ImportOptiOdomOmni4(options.sessions, options.out, options.force, options.skip_mapping_check);
  for (const std::string& note : s.notes) std::printf("note: %s\n", note.c_str());
  std::printf("%s\n", s.channel_order.c_str());
  std::printf("imported %d runs of %d omni4 sessions into %s; nominal CF (Eq. 14) %.4f\n",
              s.num_runs, s.num_sessions, options.out.c_str(), s.nominal_mean_cf);
}

// The robots of the OptiOdom study by their metadata `type`. Each importer reads, checks and
// writes through the one reader and writer (tools/optiodom_format.h) and prints its summary;
// what differs is which metadata keys make the nominal robot and what the encoder columns are.
struct OptiOdomRobot {
  const char* type;
  void (*import)(const ImportOptiOdomOptions&);
};
constexpr OptiOdomRobot kRobots[] = {{"omni3", ImportOmni3},
                                     {"omni4", ImportOmni4},
                                     {"diff", ImportDiff},
                                     {"tricyc", ImportTricycle}};

const OptiOdomRobot& RobotOfType(const std::string& type, const std::string& session) {
  for (const OptiOdomRobot& robot : kRobots) {
    if (type == robot.type) return robot;
  }
  throw InputError(InputErrorKind::kUnknownModel, session, 0,
                   "type '" + type +
                       "' is not an OptiOdom robot fitcal imports (omni3, omni4, "
                       "diff, tricyc)");
}

}  // namespace

void AddImportOptiOdomOptions(CLI::App& app, ImportOptiOdomOptions& o) {
  app.add_option("sessions", o.sessions, "Session directories")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--out", o.out, "Output data set directory")->required();
  app.add_flag("--force", o.force, "Overwrite an existing data set");
  app.add_flag("--skip-mapping-check", o.skip_mapping_check,
               "Write even if another wheel order/sign explains the ground truth better");
}

int RunImportOptiOdomCommand(const ImportOptiOdomOptions& options) {
  try {
    if (options.sessions.empty()) {
      std::cerr << "fitcal: import optiodom needs at least one session directory\n";
      return 2;
    }
    const std::string type = optiodom::SessionType(options.sessions.front());
    for (const std::string& dir : options.sessions) {
      if (optiodom::SessionType(dir) != type) {
        std::cerr << "fitcal: " << dir << ": a " << optiodom::SessionType(dir) << " session among "
                  << type << " sessions; import one robot at a time\n";
        return 2;
      }
    }
    // The recordings are inputs: no data set may replace, hold or sit inside one.
    for (const std::string& dir : options.sessions) io::RegisterInputDirectory(dir);
    if (const std::string refusal =
            DirectoryOutputRefusal(options.out, kDatasetKind, options.force, options.sessions);
        !refusal.empty()) {
      std::cerr << "fitcal: " << refusal << "\n";
      return 2;
    }
    RobotOfType(type, options.sessions.front()).import(options);
    return 0;
  } catch (const MiswiredError& e) {
    std::cerr << "fitcal: " << e.what() << "\n";
    return kMiswiredExitCode;
  } catch (const std::exception& e) {
    std::cerr << "fitcal: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
