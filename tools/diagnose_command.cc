#include "tools/diagnose_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>

#include "calib/diagnose.h"
#include "calib/run_split.h"
#include "calib/segment_cost.h"
#include "calib/trajectory_split.h"
#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/robot_yaml.h"
#include "io/staged_directory.h"
#include "odometry/parallel_for.h"
#include "tools/cli_validators.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

CLI::App* AddDiagnoseCommand(CLI::App& app, DiagnoseCommandOptions& o) {
  CLI::App* cmd = app.add_subcommand(
      "diagnose",
      "Trace the residual of the nine-parameter fit to missing effects (calib/diagnose.h)");
  cmd->add_option("--logs", o.logs, "Data set directory")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--train-reps", o.train_reps,
                  "Training repetitions (e.g. 1-5); auto = the first half; the rest validate")
      ->capture_default_str()
      ->check(RepetitionListValidator(/*allow_auto=*/true));
  cmd->add_option("--train-trajectories", o.train_trajectories,
                  "Split by trajectory label instead: a list of labels or a regular expression "
                  "(e.g. ^circular); matching runs train, the others validate");
  cmd->add_flag("--clock-map", o.clock_map,
                "Re-stamp each run's ground truth on the encoder clock (speed-profile match)");
  cmd->add_option("--out", o.out, "Output directory (diagnose.md, residuals.csv, calibrated.yaml)")
      ->capture_default_str();
  cmd->add_option("--max-effects", o.max_effects, "Most effects to add")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--alpha", o.alpha, "Family-wise significance level of the tracing")
      ->capture_default_str()
      ->check(CLI::Range(1e-9, 0.5));
  cmd->add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("--allow-outside-paths", o.allow_outside_paths,
                "Allow dataset.yaml paths outside the data set directory");
  return cmd;
}

namespace {
const std::set<std::string> kDiagnoseFiles = {"diagnose.md", "residuals.csv",
                                              "residuals_declared.csv", "calibrated.yaml"};
}  // namespace

int RunDiagnoseCommand(const DiagnoseCommandOptions& options) {
  try {
    io::DatasetOptions dataset_options;
    dataset_options.allow_paths_outside = options.allow_outside_paths;
    dataset_options.num_threads = options.threads;
    const io::DatasetIndex index = io::ReadDatasetIndex(options.logs, dataset_options);
    const std::vector<std::string> inputs = DatasetInputs(index);
    if (const std::string refusal = OutputDirectoryRefusal(options.out, inputs, kDiagnoseFiles);
        !refusal.empty()) {
      std::cerr << "fitcal: " << refusal << "\n";
      return 2;
    }
    const io::Dataset dataset = io::LoadDataset(index, dataset_options);
    const std::string model = io::ReadRobotModel(dataset.robot_path);
    if (model != "omni3") {
      throw io::InputError(io::InputErrorKind::kUnknownModel, dataset.robot_path, 0,
                           "model '" + model + "' is not supported by 'diagnose' (known: omni3)");
    }
    const Omni3Robot robot = io::ReadOmni3Robot(dataset.robot_path);
    std::vector<int> train_reps;
    std::vector<RunLog> runs = dataset.runs;
    if (options.clock_map) {
      const auto nominal = robot.nominal.ToArray();
      ParallelFor(runs.size(), options.threads, [&](std::size_t i) {
        const ClockMap map = EstimateClockMap(AlignRun(runs[i]), runs[i].ground_truth, nominal);
        runs[i].ground_truth = ApplyClockMap(runs[i].ground_truth, map);
      });
    }
    std::vector<TrackRun> training, validation;
    std::string split_text;
    if (!options.train_trajectories.empty()) {
      std::vector<std::string> labels;
      for (const RunLog& run : runs) labels.push_back(run.trajectory);
      const TrajectorySelector selector(options.train_trajectories, labels);
      std::set<int> reps;
      for (TrackRun& run : PrepareTrackRuns(runs)) {
        const bool train = selector.Matches(run.aligned.trajectory);
        if (train) reps.insert(run.aligned.repetition);
        (train ? training : validation).push_back(std::move(run));
      }
      train_reps.assign(reps.begin(), reps.end());
      split_text = "training trajectories matching '" + options.train_trajectories + "'";
    } else if (options.train_reps == "auto") {
      std::set<int> reps;
      for (const RunLog& run : dataset.runs) reps.insert(run.repetition);
      const std::vector<int> all(reps.begin(), reps.end());
      train_reps.assign(all.begin(), all.begin() + static_cast<long>((all.size() + 1) / 2));
    } else {
      train_reps = ParseRepetitionList(options.train_reps);
    }
    if (options.train_trajectories.empty()) {
      SplitTrackRuns(PrepareTrackRuns(runs), train_reps, &training, &validation);
      split_text = "training repetitions " + FormatRepetitionList(train_reps);
    }
    if (training.empty() || validation.empty()) {
      std::cerr << "fitcal: diagnose needs training and held-out runs; got " << training.size()
                << " training and " << validation.size() << " validation runs (" << split_text
                << ")\n";
      return 2;
    }
    DiagnoseOptions diagnose_options;
    diagnose_options.fit.num_threads = options.threads;
    diagnose_options.max_effects = options.max_effects;
    diagnose_options.alpha = options.alpha;
    const DiagnoseResult result = Diagnose(training, validation, robot, diagnose_options);
    if (!result.declared.usable || !result.final_fit.usable) {
      std::cerr << "fitcal: the fit did not converge (" << result.declared.termination
                << "); nothing written\n";
      return 3;
    }
    std::string report = FormatDiagnoseReport(result, robot);
    report = "data set: " + options.logs + ", " + split_text +
             (options.clock_map ? ", ground-truth clocks re-mapped" : "") + ", fitcal " + kVersion +
             "\n\n" + report;
    std::printf("%s", report.c_str());

    // Outputs: all text is built first, then written; the YAML last.
    Omni3Robot calibrated = robot;
    calibrated.nominal = omni3::Parameters::FromArray(result.final_fit.parameters.data());
    if (result.effects_named) calibrated.effects = result.final_fit.effects;
    io::CalibrationRecord record;
    record.method = "ceres (track residuals) + diagnose";
    record.objective = "sum over runs of the mean squared track error (m and rad)";
    record.dataset = options.logs;
    record.tool_version = kVersion;
    record.termination = result.final_fit.termination;
    record.training_repetitions = train_reps;
    record.training_runs = static_cast<int>(training.size());
    record.validation_runs = static_cast<int>(validation.size());
    std::set<int> val_reps;
    for (const TrackRun& r : validation) val_reps.insert(r.aligned.repetition);
    record.validation_repetitions.assign(val_reps.begin(), val_reps.end());
    record.cf_validation_before = result.declared_validation.cf;
    record.cf_validation_after = result.final_validation.cf;
    record.has_uncertainty = false;
    record.inverse_kinematic_matrix =
        omni3::InverseKinematicMatrix(result.final_fit.parameters.data());
    const std::string yaml = io::Omni3RobotYaml(calibrated, &record);
    const std::string csv = ResidualSamplesCsv(result.after);
    const std::string csv_declared = ResidualSamplesCsv(result.before);
    {  // written as a set: staged, then renamed over the previous output (report_command.cc)
      io::StagedDirectory staged(options.out);
      const std::filesystem::path dir(staged.path());
      io::WriteFileAtomically((dir / "diagnose.md").string(), report);
      io::WriteFileAtomically((dir / "residuals.csv").string(), csv);
      io::WriteFileAtomically((dir / "residuals_declared.csv").string(), csv_declared);
      io::StopHereForTests("diagnose-staged");
      io::WriteFileAtomically((dir / "calibrated.yaml").string(), yaml);
      CommitOutputDirectory(staged, options.out, inputs, kDiagnoseFiles);
    }
    std::printf(
        "\nwrote %s/{diagnose.md, residuals.csv, residuals_declared.csv, calibrated.yaml}\n",
        options.out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "fitcal: " << io::OneLine(e.what(), 500) << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
