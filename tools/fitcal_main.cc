// fitcal: offline calibration of wheeled odometry. Subcommands are registered in a table below;
// `fitcal --logs <dir> --method ceres` without a subcommand runs `fit`.

#include <glog/logging.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/input_error.h"
#include "tools/asoc_commands.h"
#include "tools/cli_validators.h"
#include "tools/compare_command.h"
#include "tools/diagnose_command.h"
#include "tools/export_ros2_control.h"
#include "tools/fit_command.h"
#include "tools/fit_methods.h"
#include "tools/generalisation_command.h"
#include "tools/import_optiodom.h"
#include "tools/import_rosbag2.h"
#include "tools/report_command.h"
#include "tools/simulate_command.h"

namespace {

CLI::App* AddImportRosbag2(CLI::App& import_cmd, fitcal::tools::ImportRosbag2Options& o) {
  CLI::App* cmd = import_cmd.add_subcommand(
      "rosbag2", "A ROS 2 bag (sqlite3 or MCAP, split or not): JointState + ground truth");
  cmd->add_option("bag", o.bag, "Bag directory, its metadata.yaml, or one .db3 / .mcap file")
      ->required();
  cmd->add_option("--out", o.out, "Output data set directory (written atomically)")->required();
  cmd->add_option("--robot", o.robot, "Robot YAML (any model); copied into the data set")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--encoders", o.encoders, "sensor_msgs/msg/JointState topic")
      ->capture_default_str();
  cmd->add_option("--joints", o.joints,
                  "Joint names in the robot's channel order (default: the channel names)")
      ->delimiter(',');
  cmd->add_option("--ground-truth", o.ground_truth,
                  "Ground-truth topic: geometry_msgs/msg/PoseStamped, nav_msgs/msg/Odometry or "
                  "tf2_msgs/msg/TFMessage")
      ->required();
  cmd->add_option("--ground-truth-frames", o.ground_truth_frames,
                  "For a TFMessage topic: parent:child of the transform, e.g. world:base_link");
  cmd->add_option("--stamp", o.stamp,
                  "header (default: when the driver measured; the recording time adds each "
                  "topic's own transport latency and jitter) or recorded")
      ->capture_default_str();
  cmd->add_option("--runs", o.runs, "Cut runs at these spans: t0:t1,t2:t3 (s since the bag start)");
  cmd->add_option("--split-at-rest", o.split_at_rest_s,
                  "Cut runs in the middle of every rest at least this long (s)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--rest-rate", o.rest_rate_rad_s, "A wheel slower than this is at rest (rad/s)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--label", o.label, "Trajectory label of the runs (default: the bag's name)");
  cmd->add_flag("--force", o.force, "Replace an existing data set");
  return cmd;
}

CLI::App* AddExportRos2Control(CLI::App& app, fitcal::tools::ExportRos2ControlOptions& o) {
  CLI::App* export_cmd = app.add_subcommand("export", "Write a calibration for another tool");
  export_cmd->require_subcommand(1);
  CLI::App* cmd = export_cmd->add_subcommand(
      "ros2-control", "The parameter YAML of a ros2_controllers drive controller");
  cmd->add_option("--calibration", o.calibration, "Calibrated robot YAML (from fit)")
      ->required()
      ->check(CLI::ExistingFile);
  std::string names;
  for (const std::string& c : fitcal::tools::Ros2Controllers())
    names += (names.empty() ? "" : ", ") + c;
  cmd->add_option("--controller", o.controller, "One of " + names)->required();
  cmd->add_option("--node-name", o.node_name, "Top-level key (default: the controller's name)");
  cmd->add_option("--joints", o.joints,
                  "URDF joint names in the robot's channel order (default: the channel names)")
      ->delimiter(',');
  cmd->add_option("--out", o.out, "File to write (atomically; default: stdout)");
  cmd->add_option("--logs", o.logs,
                  "Data set: print the held-out CF of the exact and the exported parameters")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--force", o.force, "Overwrite --out");
  return cmd;
}

void AddFitOptions(CLI::App& app, fitcal::tools::FitCommandOptions& o) {
  app.add_option("--logs", o.logs, "Data set directory (holds dataset.yaml)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--method", o.method, "Solver: " + fitcal::tools::FitMethodNames())
      ->capture_default_str();
  app.add_option("--objective", o.objective,
                 "squares (sum of squared residuals; Ceres default) or eq14 (sum of per-run "
                 "norms, Palacin Eq. 14; NLopt default)");
  app.add_option("--loss", o.loss, "Ceres robust loss: none, huber, cauchy")->capture_default_str();
  app.add_option("--loss-scale", o.loss_scale, "Robust loss scale (residual units: m and rad)")
      ->capture_default_str();
  app.add_option("--seed", o.seed, "NLopt random seed (same seed, same result)")
      ->capture_default_str();
  app.add_option("--max-evaluations", o.max_evaluations, "NLopt evaluation budget")
      ->capture_default_str();
  app.add_option("--max-iterations", o.max_iterations, "Ceres iterations per solve")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--polish", o.polish,
               "NLopt global methods: polish the best point with SLSQP (autodiff gradient)");
  CLI::Option* reps =
      app.add_option("--train-reps", o.train_reps,
                     "Repetitions used for fitting, e.g. 1-5 or 1,3,5; the others validate")
          ->capture_default_str()
          ->check(fitcal::tools::RepetitionListValidator());
  app.add_option("--train-trajectories", o.train_trajectories,
                 "Fit on the runs whose trajectory label matches (list or regular expression); "
                 "the others validate")
      ->excludes(reps);
  app.add_option("--out", o.out, "Calibrated robot YAML to write (atomically)")
      ->capture_default_str();
  app.add_flag("--no-output", o.no_output, "Do not write the calibrated YAML");
  app.add_flag("--force", o.force, "Overwrite --out even if it holds another robot's calibration");
  app.add_flag("--skip-wheel-order-check", o.skip_wheel_order_check,
               "Fit even if another encoder column order/sign explains the data far better");
  app.add_flag("--allow-outside-paths", o.allow_outside_paths,
               "Allow dataset.yaml paths that are absolute or leave the data set directory");
  app.add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  app.add_option("--position-sigma-m", o.position_sigma_m,
                 "Weight of the position residual as a standard deviation (m); with the default "
                 "1 m and 57.3 deg the objective weighs metres and radians as Eq. 14")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--heading-sigma-deg", o.heading_sigma_deg,
                 "Weight of the heading residual as a standard deviation (deg)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
}

// Usage errors exit 2 in one line, as the README says; CLI11's own codes (105 for a validation,
// 106 for a missing option, ...) and its second "Run with --help" line would say otherwise.
// Help and version requests keep CLI11's output and exit 0. Returns -1 when parsing succeeded.
int ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "fitcal: " << fitcal::io::OneLine(e.what(), 300) << " (see fitcal --help)\n";
    return 2;
  }
  return -1;
}

// Ceres logs through glog, which writes WARNING and above to stderr before InitGoogleLogging:
// lines such as "W... Ceres was compiled without ..." would break fitcal's one line per problem.
// What Ceres reports (termination, failure) reaches fitcal through its Summary instead.
void SilenceLibraryLogging(const char* argv0) {
  FLAGS_logtostderr = false;
  FLAGS_alsologtostderr = false;
  FLAGS_stderrthreshold = google::GLOG_FATAL;
  FLAGS_minloglevel = google::GLOG_FATAL;
  google::InitGoogleLogging(argv0);
  // For refusal_test: a library line at every severity below FATAL, as Ceres writes them on an
  // ill-posed problem (e.g. "W... residual_block.cc:129] Error in evaluating the ResidualBlock").
  if (std::getenv("FITCAL_TEST_LIBRARY_LOG") != nullptr) {
    LOG(INFO) << "test info line";
    LOG(WARNING) << "test warning line";
    LOG(ERROR) << "test error line";
  }
}

}  // namespace

int main(int argc, char** argv) {
  SilenceLibraryLogging(argv[0]);
  // Ctrl-C or a scheduler's SIGTERM while an output is being written leaves no temporary behind.
  fitcal::io::RemoveTemporaryFilesOnSignals();
  CLI::App app{"fitcal " + std::string(fitcal::kVersion) +
               ": calibrate the kinematic parameters of a wheeled robot's odometry from encoder "
               "logs and ground truth"};
  app.set_version_flag("--version", std::string(fitcal::kVersion));
  app.require_subcommand(0, 1);

  fitcal::tools::FitCommandOptions fit;
  AddFitOptions(app, fit);
  fitcal::tools::AsocCommands asoc_commands;  // asoc-simulate, asoc-geometric, asoc-tables
  asoc_commands.Register(app);
  CLI::App* fit_cmd = app.add_subcommand(
      "fit", "Fit, validate on held-out repetitions, write the calibrated YAML (default)");
  // The same options on `fit` itself, bound to the same settings, so `fitcal fit --help` lists
  // every flag (`fitcal --logs ...` without a subcommand keeps working).
  AddFitOptions(*fit_cmd, fit);

  fitcal::tools::SimulateCommandOptions simulate;
  CLI::App* sim_cmd = app.add_subcommand(
      "simulate",
      "Write a simulated data set: omni3 flower, or --model's trajectories (README.md, Simulator)");
  sim_cmd->add_option("--out", simulate.out, "Output data set directory")->required();
  sim_cmd->add_option("--model", simulate.model,
                      "Robot model (" + fitcal::sim::ScenarioModelNames() +
                          "; default: the omni3 flower simulator)");
  sim_cmd->add_option("--robot", simulate.robot, "Nominal robot YAML (commands and fit start)")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  sim_cmd
      ->add_option("--truth", simulate.truth,
                   "Robot YAML of the true robot (default: Palacin Table 5)")
      ->check(CLI::ExistingFile);
  sim_cmd->add_option("--repetitions", simulate.sim.repetitions, "Repetitions of each trajectory")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sim_cmd->add_option("--seed", simulate.sim.seed, "Random seed")->capture_default_str();
  sim_cmd
      ->add_option("--encoder-counts-per-rev", simulate.sim.encoder_counts_per_rev,
                   "Encoder resolution")
      ->capture_default_str();
  sim_cmd
      ->add_option("--gt-position-sigma-m", simulate.sim.gt_position_sigma_m,
                   "Ground-truth position noise (m)")
      ->capture_default_str();
  double gt_heading_sigma_deg = simulate.sim.gt_heading_sigma_rad * 180.0 / M_PI;
  sim_cmd
      ->add_option("--gt-heading-sigma-deg", gt_heading_sigma_deg,
                   "Ground-truth heading noise (deg)")
      ->capture_default_str();
  sim_cmd->add_option("--slip-sigma", simulate.sim.slip_sigma, "Relative wheel slip noise")
      ->capture_default_str();
  sim_cmd
      ->add_option("--wheel-rate-sigma-rad-s", simulate.wheel_rate_sigma_rad_s,
                   "--model: white noise on each interval's mean wheel rate (rad/s)")
      ->capture_default_str();
  sim_cmd
      ->add_option("--angle-sigma-deg", simulate.angle_sigma_deg,
                   "--model: noise of an angle channel's readings, e.g. steering (deg)")
      ->capture_default_str();
  sim_cmd->add_flag("--force", simulate.force, "Overwrite an existing data set");
  sim_cmd->add_option(
      "--inject", simulate.inject,
      "Inject a library effect, name=value[,value] (odometry/effects.h); repeatable; "
      "the data set does not name it");

  fitcal::tools::ImportOptiOdomOptions import_optiodom;
  CLI::App* import_cmd =
      app.add_subcommand("import", "Convert published recordings into a fitcal data set");
  import_cmd->require_subcommand(1);
  CLI::App* optiodom_cmd = import_cmd->add_subcommand(
      "optiodom",
      "OptiOdom sessions of one robot: omni3, omni4, diff or tricyc (Sousa et al. 2022)");
  optiodom_cmd->add_option("sessions", import_optiodom.sessions, "Session directories")
      ->required()
      ->check(CLI::ExistingDirectory);
  optiodom_cmd->add_option("--out", import_optiodom.out, "Output data set directory")->required();
  optiodom_cmd->add_flag("--force", import_optiodom.force, "Overwrite an existing data set");
  optiodom_cmd->add_flag("--skip-mapping-check", import_optiodom.skip_mapping_check,
                         "Write even if another wheel order/sign explains the ground truth better");

  fitcal::tools::ImportRosbag2Options import_rosbag2;
  CLI::App* rosbag2_cmd = AddImportRosbag2(*import_cmd, import_rosbag2);
  fitcal::tools::ExportRos2ControlOptions export_ros2;
  CLI::App* ros2_control_cmd = AddExportRos2Control(app, export_ros2);

  fitcal::tools::GeneraliseCommandOptions generalise;
  CLI::App* gen_cmd = app.add_subcommand(
      "generalise",
      "Train on one path type / session, test on the others (tools/generalisation_command.h)");
  gen_cmd->add_option("--logs", generalise.logs, "Data set directory")
      ->required()
      ->check(CLI::ExistingDirectory);
  gen_cmd
      ->add_option("--segment-length-m", generalise.segment_length_m,
                   "Ground-truth path length of a segment-cost window (m)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  gen_cmd->add_flag("!--no-clock-map", generalise.clock_map,
                    "Do not refine the ground-truth clock before cutting segments");
  gen_cmd->add_flag("!--no-loso", generalise.leave_one_session_out, "Skip leave-one-session-out");
  gen_cmd->add_option("--threads", generalise.threads, "Worker threads (0 = all cores)");
  gen_cmd->add_option("--train-trajectories", generalise.train_trajectories,
                      "Train on labels matching (list or regular expression), test on the rest, "
                      "and the other way round");
  gen_cmd
      ->add_option("--effects", generalise.effects,
                   "Library effects to add as a further model (nine + effects, track cost)")
      ->delimiter(',');
  gen_cmd->add_option("--train-reps", generalise.train_reps,
                      "Models other than omni3: repetitions of every path type that train the "
                      "split against the other repetitions (default: the first half present)");
  gen_cmd
      ->add_option("--sessions", generalise.sessions,
                   "Models other than omni3: a leave-one-session-out session is a trajectory "
                   "label (label) or a path type + repetition number (repetition)")
      ->capture_default_str();

  fitcal::tools::ReportCommandOptions report;
  CLI::App* report_cmd = app.add_subcommand(
      "report", "Validation report of a calibration: index.html, summary.md, metrics.csv/json");
  report_cmd->add_option("--logs", report.logs, "Data set directory")
      ->required()
      ->check(CLI::ExistingDirectory);
  report_cmd
      ->add_option("--calibration", report.calibrations,
                   "Calibrated robot YAML (from fit or diagnose); repeat it to compare several "
                   "calibrations on the same runs (the first is reported in full)")
      ->required()
      ->check(CLI::ExistingFile);
  report_cmd->add_option("--out", report.out, "Output directory for the report")->required();
  report_cmd
      ->add_option("--train-reps", report.train_reps,
                   "Training repetitions of this data set (default: the runs the calibration "
                   "YAML records; on another data set every run validates)")
      ->check(fitcal::tools::RepetitionListValidator());
  report_cmd
      ->add_option("--sampling", report.sampling,
                   "Odometry at ground-truth times: nearest (default, as the paper) or linear")
      ->capture_default_str();
  report_cmd->add_flag("--cv", report.cross_validate,
                       "Also run leave-one-repetition-out cross-validation");
  report_cmd->add_flag("--strict", report.strict,
                       "Exit 7 when the verdict is FAIL and 8 when it is WARN (the report is "
                       "written either way), for CI pipelines");
  report_cmd
      ->add_option("--worst-runs", report.worst_runs,
                   "Draw the error along time of this many of the worst validation runs")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  report_cmd->add_flag("--allow-outside-paths", report.allow_outside_paths,
                       "Allow dataset.yaml paths outside the data set directory");
  report_cmd->add_option("--threads", report.threads, "Worker threads (0 = all cores)");

  fitcal::tools::CompareCommandOptions compare;
  CLI::App* compare_cmd = app.add_subcommand(
      "compare", "Palacin Table 4 on your data: strategies x methods x {1, 5} repetitions");
  compare_cmd->add_option("--logs", compare.logs, "Data set directory")
      ->required()
      ->check(CLI::ExistingDirectory);
  compare_cmd
      ->add_option("--strategies", compare.strategies,
                   "STA..STE, trajectory lists such as R1,R5,G4 or B1-B12, all, or a label "
                   "prefix such as circular/* (one per item)")
      ->capture_default_str();
  compare_cmd
      ->add_option("--methods", compare.methods,
                   "Methods (" + fitcal::tools::FitMethodNames() + ") or all")
      ->capture_default_str();
  compare_cmd
      ->add_option("--repetitions", compare.repetitions,
                   "Train on the first k repetitions, for each k")
      ->capture_default_str();
  compare_cmd
      ->add_option("--validation-reps", compare.validation_reps,
                   "Validation repetitions (default: those after the largest k)")
      ->check(fitcal::tools::RepetitionListValidator());
  compare_cmd
      ->add_option("--out", compare.out, "Output prefix: <out>.csv, <out>.md, <out>_trace.csv")
      ->capture_default_str();
  compare_cmd->add_flag("--no-output", compare.no_output, "Print the table only");
  compare_cmd->add_flag("--quiet", compare.quiet, "No progress on stderr");
  compare_cmd->add_option("--seed", compare.seed, "NLopt random seed")->capture_default_str();
  compare_cmd->add_option("--max-evaluations", compare.max_evaluations, "NLopt budget per fit")
      ->capture_default_str();
  compare_cmd->add_flag("--polish", compare.polish, "NLopt global methods: SLSQP polish");
  compare_cmd->add_option("--objective", compare.objective,
                          "squares or eq14 (default: per method)");
  compare_cmd->add_option("--threads", compare.threads, "Worker threads (0 = all cores)");
  compare_cmd->add_flag("--allow-outside-paths", compare.allow_outside_paths,
                        "Allow dataset.yaml paths outside the data set directory");

  fitcal::tools::DiagnoseCommandOptions diagnose;
  CLI::App* diagnose_cmd = fitcal::tools::AddDiagnoseCommand(app, diagnose);

  if (const int usage_rc = ParseCommandLine(app, argc, argv); usage_rc >= 0) return usage_rc;

  if (diagnose_cmd->parsed()) return fitcal::tools::RunDiagnoseCommand(diagnose);

  if (compare_cmd->parsed()) {
    compare.strategies_given = compare_cmd->count("--strategies") > 0;
    return fitcal::tools::RunCompareCommand(compare);
  }

  if (report_cmd->parsed()) return fitcal::tools::RunReportCommand(report);
  if (const int asoc_rc = asoc_commands.Dispatch(app); asoc_rc >= 0) return asoc_rc;

  if (gen_cmd->parsed()) return fitcal::tools::RunGeneraliseCommand(generalise);

  if (optiodom_cmd->parsed()) return fitcal::tools::RunImportOptiOdomCommand(import_optiodom);
  if (rosbag2_cmd->parsed()) return fitcal::tools::RunImportRosbag2Command(import_rosbag2);
  if (ros2_control_cmd->parsed()) return fitcal::tools::RunExportRos2ControlCommand(export_ros2);

  if (app.got_subcommand(sim_cmd)) {
    simulate.sim.gt_heading_sigma_rad = gt_heading_sigma_deg * M_PI / 180.0;
    simulate.robot_given = sim_cmd->count("--robot") > 0;
    for (const char* flag : {"--slip-sigma", "--inject"}) {
      if (sim_cmd->count(flag) > 0) simulate.omni3_only_flags.push_back(flag);
    }
    return fitcal::tools::RunSimulateCommand(simulate);
  }
  if (fit.logs.empty()) {
    std::cerr << "fitcal: --logs <data set directory> is required (see fitcal --help)\n";
    return 2;
  }
  return fitcal::tools::RunFitCommand(fit);
}
