#include "tools/diagnose_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>

#include "calibrate/never_worse_gate.h"
#include "diagnosis/channel_order_check.h"
#include "diagnosis/clock_choice.h"
#include "diagnosis/diagnose.h"
#include "fit/correlation.h"
#include "fit/run_split.h"
#include "fit/segment_cost.h"
#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/calibration_block.h"
#include "io/dataset.h"
#include "io/diagnose_page.h"
#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/staged_directory.h"
#include "models/model_registry.h"
#include "odometry/parallel_for.h"
#include "odometry/text_format.h"
#include "tools/cli_validators.h"
#include "tools/clock_alignment.h"
#include "tools/miswired_error.h"
#include "tools/output_guard.h"
#include "tools/report_command.h"
#include "validation/propagated_uncertainty.h"
#include "validation/training_runs.h"
#include "validation/trajectory_metrics.h"

namespace fitcal::tools {

void AddDiagnoseOptions(CLI::App& cmd, DiagnoseCommandOptions& o) {
  AddDatasetOptions(cmd, o);
  CLI::Option* reps =
      cmd.add_option("--train-reps", o.train_reps,
                     "Training repetitions (e.g. 1-5); auto = the first half; the rest validate")
          ->capture_default_str()
          ->check(RepetitionListValidator(/*allow_auto=*/true));
  cmd.add_option("--train-trajectories", o.train_trajectories,
                 "Split by trajectory label instead: a list of labels or a regular expression "
                 "(e.g. ^circular); matching runs train, the others validate")
      ->excludes(reps);  // as fit: one split, not two that contradict each other
  cmd.add_flag("--clock-map", o.clock_map,
               "Re-stamp each run's ground truth on the encoder clock (speed-profile match)");
  cmd.add_option("--clock-offsets", o.clock_offsets,
                 "Re-stamp the ground truth by clock offsets estimated first per session, run or "
                 "dataset (a track fit of the parameters on every run; only the offsets are kept)")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "session", "run", "dataset"}));
  cmd.add_option("--out", o.out,
                 "Output directory (index.html, metrics.json, diagnose.md, calibrated.yaml)")
      ->capture_default_str();
  cmd.add_flag("--skip-wheel-order-check", o.skip_wheel_order_check,
               "Diagnose even if another channel order explains the runs far better");
  cmd.add_flag("--csv", o.csv,
               "Also write residuals.csv and residuals_declared.csv (every ground-truth sample)");
  cmd.add_option("--max-effects", o.max_effects, "Most effects to add")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--alpha", o.alpha, "Family-wise significance level of the tracing")
      ->capture_default_str()
      ->check(CLI::Range(1e-9, 0.5));
}

namespace {

const std::set<std::string> kDiagnoseFiles = {"index.html",    "metrics.json",
                                              "diagnose.md",   "residuals.csv",
                                              "residuals_declared.csv", "calibrated.yaml"};

// The track runs on each side (fit/run_split.h: by --train-trajectories, else by --train-reps,
// "auto" the first half of the repetitions present), and the split in words for the page.
struct DiagnoseSplit : SplitOf<TrackRun> {
  std::string text;
};

// wheel_mask marks the robot's wheel-rate channels.
DiagnoseSplit SplitRuns(const DiagnoseCommandOptions& options, const std::vector<RunLog>& runs,
                        unsigned wheel_mask) {
  DiagnoseSplit out{SplitForFit(PrepareTrackRuns(runs, wheel_mask), options.train_reps,
                                options.train_trajectories),
                    ""};
  out.text = options.train_trajectories.empty()
                 ? "training repetitions " + FormatRepetitionList(out.training_repetitions)
                 : "training trajectories matching '" + options.train_trajectories + "'";
  return out;
}

// What diagnose may write, judged like the fit's result gate (fit/result_gate.h) on the
// held-out runs by the track replay's final-pose CF: the nominal, the declared final-pose fit,
// the track fit, and the track fit with its effects when they were named. A track fit with
// effects that were not named is not a candidate: the file would claim a CF its parameters reach
// only together with effects it does not carry.
struct DiagnoseChoice {
  std::string name;
  std::vector<double> parameters;
  EffectModel effects;
  double cf_before = 0.0;  // nominal, held-out
  double cf_after = 0.0;
  double cf_training_before = 0.0;  // nominal, training runs (the same track-replay CF)
  double cf_training_after = 0.0;
  // The covariance of the fit that made these parameters, with its effects: empty for the
  // nominal or when the fit had none.
  std::vector<double> sigma = {};
  Eigen::MatrixXd correlation = Eigen::MatrixXd();
};

// The candidate a fit makes, carrying that fit's own uncertainty.
DiagnoseChoice FitChoice(const std::string& name, const std::vector<double>& parameters,
                         const EffectModel& effects, double cf_after, bool has_covariance,
                         const std::vector<double>& sigma, const Eigen::MatrixXd& correlation) {
  DiagnoseChoice c{name, parameters, effects, 0.0, cf_after};
  if (has_covariance && correlation.rows() == static_cast<Eigen::Index>(sigma.size())) {
    c.sigma = sigma;
    c.correlation = correlation;
  }
  return c;
}

DiagnoseChoice GateDiagnosis(const RobotModelInterface& model, const DiagnoseSplit& split,
                             const DiagnoseResult& result, int threads,
                             std::vector<DiagnoseChoice>* gate) {
  const std::vector<double>& nominal = model.robot().nominal;
  const auto cf = [&](const std::vector<double>& p, const EffectModel& e) {
    return ScoreModel(model, p, e, split.validation, {}, threads).cf;
  };
  const ModelFitResult& declared = result.declared;
  const EffectFitResult& base = result.base;
  const EffectFitResult& final_fit = result.final_fit;
  std::vector<DiagnoseChoice> candidates = {
      {"nominal", nominal, {}, 0.0, cf(nominal, {})},
      FitChoice("declared final-pose fit", declared.parameters, {}, result.declared_validation.cf,
                declared.has_covariance, declared.sigma, declared.correlation),
      FitChoice("track fit", base.parameters, {}, cf(base.parameters, {}), base.has_covariance,
                base.sigma, base.correlation)};
  if (result.effects_named) {
    candidates.push_back(FitChoice("track fit + effects", final_fit.parameters, final_fit.effects,
                                   result.final_validation.cf, final_fit.has_covariance,
                                   final_fit.sigma, final_fit.correlation));
  }
  std::size_t best = 0;
  std::printf("\nresult gate, CF on the held-out runs (%zu):\n", split.validation.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (candidates[i].cf_after < candidates[best].cf_after) best = i;
  }
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    std::printf("  %-28s %10.5f%s\n", candidates[i].name.c_str(), candidates[i].cf_after,
                i == best ? "   <- selected" : "");
  }
  candidates[best].cf_before = candidates[0].cf_after;
  const auto cf_training = [&](const DiagnoseChoice& c) {
    return ScoreModel(model, c.parameters, c.effects, split.training, {}, threads).cf;
  };
  candidates[best].cf_training_before = cf_training(candidates[0]);
  candidates[best].cf_training_after = cf_training(candidates[best]);
  *gate = candidates;
  return candidates[best];
}

// The chosen calibration beats the nominal on the held-out runs as a whole; it must not be worse
// on a kind of run, in drift or ATE beyond the runs' scatter either (validation/never_worse.h,
// the rule fit applies). True after one line per such measure on stderr; what rose without
// refusing is said in "warning:" lines, as fit says it.
bool WorseThanNominalBeyondNoise(const RobotModelInterface& model, const DiagnoseSplit& split,
                                 const DiagnoseChoice& nominal, const DiagnoseChoice& choice,
                                 int threads) {
  std::vector<AlignedRun> runs;
  std::vector<const GroundTruthTrack*> tracks;
  for (const TrackRun& r : split.validation) {
    runs.push_back(r.aligned);
    tracks.push_back(&r.track);
  }
  const NeverWorseVerdict verdict = JudgeNeverWorseThanNominal(
      model, {nominal.name, nominal.parameters, true, nominal.effects},
      {choice.name, choice.parameters, true, choice.effects}, runs, tracks, threads);
  for (const std::string& line : verdict.warnings) std::printf("warning: %s\n", line.c_str());
  for (const std::string& line : verdict.refusals) std::cerr << "fitcal: " << line << "\n";
  return !verdict.refusals.empty();
}

// A written calibration never carries sigma: null. When the fit that made the chosen parameters
// had no covariance of its own, they get the one propagated through the training runs' final
// poses (validation/propagated_uncertainty.h); false, after one line, when even that is not
// possible (nothing is written then).
bool WithUncertainty(const RobotModelInterface& model, const DiagnoseSplit& split,
                     DiagnoseChoice* choice) {
  const std::size_t n = model.robot().parameters.size();
  if (choice->sigma.size() == n) return true;
  std::vector<AlignedRun> training;
  for (const TrackRun& r : split.training) training.push_back(r.aligned);
  const PropagatedUncertainty u = PropagateFinalPoseUncertainty(model, choice->parameters, training);
  if (!u.ok || u.sigma.size() != n) {
    std::cerr << "fitcal: the chosen calibration ('" << choice->name
              << "') has no uncertainty: " << u.message << "; nothing written\n";
    return false;
  }
  choice->sigma = u.sigma;
  choice->correlation = CorrelationOf(u.covariance);
  std::printf("uncertainty of '%s': propagated through the training runs' final poses\n",
              choice->name.c_str());
  return true;
}

// "## Written calibration": the chosen candidate's parameters with the sigma calibrated.yaml
// records, in display units.
std::string WrittenCalibrationText(const Robot& robot, const DiagnoseChoice& choice) {
  std::string out = "\n## Written calibration: " + choice.name +
                    "\n\n| parameter | unit | value | +-1 sigma |\n|---|---|---|---|\n";
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    const double s = info.DisplayScale();
    // The unit has its own column (issue 42: "r_right [m] | m" said it twice).
    out += StrFormat("| %s%s | %s | %.6f | %.2g |\n", info.name.c_str(),
                     robot.IsHeld(k) ? " (held)" : "", info.DisplayUnit(), choice.parameters[k] * s,
                     choice.sigma[k] * s);
  }
  return out;
}

std::string ObjectiveOf(const DiagnoseChoice& choice) {
  return choice.name == "declared final-pose fit"
             ? "sum over runs of the squared final-pose error (m and rad)"
             : "sum over runs of the mean squared track error (m and rad)";
}

// What the calibrated YAML records of the diagnosis: the chosen candidate, its objective, the
// training and held-out runs, and the CF before and after on both.
void RecordSource(const DiagnoseCommandOptions& options, const std::vector<RunLog>& logs,
                  const DiagnoseSplit& split, const DiagnoseResult& result,
                  const DiagnoseChoice& choice, io::CalibrationSource* source) {
  io::CalibrationSource& s = *source;
  s.method = "diagnose: " + choice.name;
  s.objective = ObjectiveOf(choice);
  s.dataset = options.logs;
  s.tool_version = kVersion;
  s.termination = result.final_fit.termination;
  s.training_repetitions = split.training_repetitions;
  s.validation_repetitions = split.validation_repetitions;
  for (const TrackRun& r : split.training) s.training_run_ids.push_back(r.aligned.id);
  s.training_trajectories = options.train_trajectories;
  s.training_fingerprint = TrainingFingerprint(logs, s.training_run_ids);
  s.training_runs = static_cast<int>(split.training.size());
  s.validation_runs = static_cast<int>(split.validation.size());
  s.cf_training_before = choice.cf_training_before;
  s.cf_training_after = choice.cf_training_after;
  s.cf_validation_before = choice.cf_before;
  s.cf_validation_after = choice.cf_after;
}

// The model's own YAML (RobotYaml) with the accepted effects and the calibration block, the layout
// `fit` writes.
std::string ModelCalibratedYaml(const DiagnoseCommandOptions& options,
                                const RobotModelInterface& model, const std::vector<RunLog>& logs,
                                const DiagnoseSplit& split, const DiagnoseResult& result,
                                const DiagnoseChoice& choice) {
  const Robot& robot = model.robot();
  io::CalibrationBlock block;
  RecordSource(options, logs, split, result, choice, &block);
  block.selected = choice.name;
  block.selected_on = "held-out runs (" + std::to_string(split.validation.size()) + ")";
  for (const HeldParameter& h : robot.held) block.held.push_back(robot.parameters[h.index].name);
  block.has_uncertainty = static_cast<int>(choice.sigma.size()) == robot.NumParameters();
  if (block.has_uncertainty) {
    block.sigma = choice.sigma;
    block.correlation = choice.correlation;
  }
  return model.RobotYaml(choice.parameters, choice.effects, io::CalibrationBlockYaml(block, robot));
}

// Re-stamps each run's ground truth on the encoder clock (the speed-profile match of the
// model's body velocities at the nominal, fit/segment_cost.h), keeping the map only on the runs
// whose track error under the final-pose fit it lowers (diagnosis/clock_choice.h): a correctly
// clocked data set keeps the identity.
void MapClocks(const RobotModelInterface& model, int threads, std::vector<RunLog>* runs) {
  const std::vector<double>& nominal = model.robot().nominal;
  std::vector<RunLog> mapped = *runs;
  ParallelFor(mapped.size(), threads, [&](std::size_t i) {
    RunLog& run = mapped[i];
    const ClockMap map = EstimateClockMap(model, nominal.data(), AlignRun(run), run.ground_truth);
    run.ground_truth = ApplyClockMap(run.ground_truth, map);
  });
  ModelFitOptions fit_options;
  fit_options.ceres.num_threads = threads;
  const ModelFitResult fit = FitModel(AlignRuns(*runs), model, fit_options);
  const std::vector<double>& p = fit.usable ? fit.parameters : model.robot().nominal;
  const ClockChoice choice =
      ChooseClocks(model, p, *runs, mapped, WheelChannelMask(model.robot()), threads);
  std::printf("clock map kept on %d of %zu runs (the identity fits the others better)\n",
              choice.num_mapped, runs->size());
  *runs = ApplyClockChoice(choice, std::move(*runs), mapped);
}

// The one channel-order check (diagnosis/channel_order_check.h), as `fit` and the importers run
// it: a swapped or sign-flipped column would send the diagnosis after effects that are a wiring
// fault. True after one line on stderr when another order explains the runs far better.
bool ChannelsLookMiswired(const DiagnoseCommandOptions& options, const RobotModelInterface& model,
                          const std::vector<RunLog>& runs) {
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& run : runs) tracks.push_back(&run.ground_truth);
  ChannelOrderOptions order_options;
  order_options.num_threads = options.threads;
  const ChannelOrderReport order =
      CheckRecordedChannelOrder(AlignRuns(runs), tracks, model, order_options);
  if (!order.likely_miswired) return false;
  std::cerr << "fitcal: " << options.logs << ": " << order.message
            << "; nothing written (--skip-wheel-order-check to diagnose anyway)\n";
  return true;
}

std::string Format(const char* format, double v) { return FormatDouble(format, v); }

// The verdict of the page: effects named as causes, effects that only describe part of a
// structure, structure and no effect, or nothing at all.
void SetConclusion(const DiagnoseResult& r, io::DiagnosePageData* page) {
  const bool any_effect = !r.final_fit.effects.empty();
  if (r.effects_named) {
    page->level = "EFFECTS_NAMED";
    page->conclusion = "The residual is explained by the effect(s) accepted below; nothing "
                       "structured remains.";
  } else if (any_effect) {
    page->level = "PARTIAL";
    page->conclusion = "Effects were accepted, but structure remains: they describe part of it "
                       "and may stand in for an effect outside the library.";
  } else if (r.unexplained_structure) {
    page->level = "UNEXPLAINED";
    page->conclusion = "The residual has structure that no candidate effect explains.";
  } else {
    page->level = "NOTHING_FOUND";
    page->conclusion = "No structure beyond the noise and no effect that earns its place: the "
                       "model's parameters are enough for these runs.";
  }
}

void AddStructureTests(const DiagnoseResult& r, io::DiagnosePageData* page) {
  const auto lof = [&](const char* name, const LackOfFit& l) {
    if (!l.available) return;
    page->structure.push_back(
        {name, "F = " + Format("%.2f", l.f) + " on (" + Format("%.0f", l.df_lof) + ", " +
                   Format("%.0f", l.df_pe) + ") dof",
         l.p_value, l.p_value < DiagnoseOptions{}.lof_alpha,
         "the repetitions of a trajectory agree with each other better than with the model"});
  };
  lof("lack of fit, declared fit", r.before.lack_of_fit);
  lof("lack of fit, final model", r.after.lack_of_fit);
  const SensorFloorTest& floor = r.after.sensor_floor;
  if (floor.available) {
    page->structure.push_back({"residual against the sensors' noise, final model",
                               Format("%.2f x the floor", floor.ratio), floor.p_value,
                               r.floor_shows_structure,
                               "the residual is larger than the sensors' own noise and the "
                               "repetitions' own scatter explain"});
  }
  for (const CovariateTest& t : r.covariates.tests) {
    if (!t.tested) continue;
    page->structure.push_back({"residual against " + t.name, "F = " + Format("%.2f", t.f),
                               t.p_value, t.significant, CovariateFinding(t)});
  }
}

void AddCandidates(const DiagnoseResult& r, io::DiagnosePageData* page) {
  for (std::size_t k = 0; k < r.rounds.size(); ++k) {
    const double threshold = r.rounds[k].threshold;  // alpha / (candidates fitted)
    for (const CandidateResult& c : r.rounds[k].candidates) {
      page->candidates.push_back({static_cast<int>(k) + 1, effects::Info(c.id).name,
                                  c.separable_fraction, c.resolvable, c.fitted,
                                  c.mean_improvement, c.p_value, threshold, c.delta_bic,
                                  c.explains, c.accepted, c.verdict});
    }
  }
}

// Nominal and the written calibration on each held-out run, as `report` computes them
// (validation/trajectory_metrics.h), so that both commands print one CF for one calibration.
void AddHeldOut(const RobotModelInterface& model, const DiagnoseSplit& split,
                const DiagnoseChoice& choice, io::DiagnosePageData* page) {
  for (const TrackRun& run : split.validation) {
    const TrajectoryErrors b =
        EvaluateTrajectory(model, run.aligned, run.track, model.robot().nominal, {});
    const TrajectoryErrors a =
        EvaluateTrajectory(model, run.aligned, run.track, choice.parameters, choice.effects);
    const auto start_frame = [&](const TrajectoryErrors& e) {
      const double c = std::cos(run.aligned.start.theta), s = std::sin(run.aligned.start.theta);
      const double dx = e.final_odometry.x - e.final_ground_truth.x;
      const double dy = e.final_odometry.y - e.final_ground_truth.y;
      return io::Point2{c * dx + s * dy, -s * dx + c * dy};
    };
    page->held_out.push_back({run.aligned.id, b.cf, a.cf, b.rms_distance_m, a.rms_distance_m,
                              start_frame(b), start_frame(a)});
  }
}

io::DiagnosePageData MakePage(const DiagnoseCommandOptions& options,
                              const RobotModelInterface& model, const DiagnoseSplit& split,
                              const DiagnoseResult& result, const std::vector<DiagnoseChoice>& gate,
                              const DiagnoseChoice& choice, const std::string& report) {
  io::DiagnosePageData page;
  const Robot& robot = model.robot();
  page.tool_version = kVersion;
  page.dataset = options.logs;
  page.split = split.text;
  page.robot_name = robot.name;
  page.model = robot.model;
  page.selected = choice.name;
  page.text_report = report;
  page.csv_written = options.csv;
  SetConclusion(result, &page);
  AddStructureTests(result, &page);
  AddCandidates(result, &page);
  for (const DiagnoseChoice& c : gate)
    page.gate.push_back({c.name, c.cf_after, c.name == choice.name});
  AddHeldOut(model, split, choice, &page);
  page.unexplained = result.not_identifiable;
  for (const CovariateTest& t : result.covariates.tests) {
    if (t.significant) page.unexplained.push_back(CovariateFinding(t));
  }
  if (result.unexplained_structure && page.unexplained.empty()) {
    page.unexplained.push_back("structure in the residual that no candidate effect explains "
                               "(see the tests above)");
  }
  for (const std::string& line : result.record_next) page.unexplained.push_back(line);
  const bool has_sigma = static_cast<int>(choice.sigma.size()) == robot.NumParameters();
  for (int k = 0; k < robot.NumParameters(); ++k) {
    page.parameters.push_back(ReportParameterOf(robot, k, choice.parameters[k], has_sigma,
                                                has_sigma ? choice.sigma[k] : 0.0));
  }
  for (const effects::EffectValue& value : choice.effects) {
    page.effects.push_back(ReportEffectOf(value));
  }
  return page;
}

void WriteOutputs(const DiagnoseCommandOptions& options, const std::vector<std::string>& inputs,
                  const std::string& report, const DiagnoseResult& result,
                  const io::DiagnosePageData& page, const std::string& yaml) {
  // Written as a set: staged, then renamed over the previous output (report_command.cc).
  io::StagedDirectory staged(options.out);
  const std::filesystem::path dir(staged.path());
  io::WriteFileAtomically((dir / "diagnose.md").string(), report);
  io::WriteFileAtomically((dir / "index.html").string(), io::DiagnoseHtml(page));
  if (options.csv) {
    io::WriteFileAtomically((dir / "residuals.csv").string(), ResidualSamplesCsv(result.after));
    io::WriteFileAtomically((dir / "residuals_declared.csv").string(),
                            ResidualSamplesCsv(result.before));
  }
  io::StopHereForTests("diagnose-staged");
  io::WriteFileAtomically((dir / "metrics.json").string(), io::DiagnoseMetricsJson(page));
  io::WriteFileAtomically((dir / "calibrated.yaml").string(), yaml);
  CommitOutputDirectory(staged, options.out, inputs, kDiagnoseFiles);
}

}  // namespace

int RunDiagnoseCommand(const DiagnoseCommandOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    const OpenedDataset opened = OpenDataset(options);
    const io::DatasetIndex& index = opened.index;
    const std::vector<std::string>& inputs = opened.inputs;
    if (const std::string refusal = OutputDirectoryRefusal(options.out, inputs, kDiagnoseFiles);
        !refusal.empty()) {
      return Refuse(refusal);
    }
    const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
    const Robot& robot = model->robot();
    if (!robot.effects.empty()) {
      std::cerr << "fitcal: " << index.robot_path
                << ": the robot already declares effects; diagnose starts from a robot YAML "
                   "without an effects: list\n";
      return 2;
    }
    std::vector<RunLog> runs = LoadRuns(options, index, &robot).runs;
    const std::string aligned = AlignGroundTruthClocks(options.clock_offsets, *model, nullptr,
                                                       std::nullopt, options.threads, &runs);
    if (!aligned.empty()) std::printf("%s\n", aligned.c_str());
    if (options.clock_map) MapClocks(*model, options.threads, &runs);
    if (!options.skip_wheel_order_check && ChannelsLookMiswired(options, *model, runs)) {
      return kMiswiredExitCode;
    }
    const DiagnoseSplit split = SplitRuns(options, runs, WheelChannelMask(robot));
    if (split.training.empty() || split.validation.empty()) {
      std::cerr << "fitcal: diagnose needs training and held-out runs; got "
                << split.training.size() << " training and " << split.validation.size()
                << " validation runs (" << split.text << ")\n";
      return 2;
    }
    DiagnoseOptions diagnose_options;
    diagnose_options.fit.num_threads = options.threads;
    diagnose_options.max_effects = options.max_effects;
    diagnose_options.alpha = options.alpha;
    const DiagnoseResult result =
        Diagnose(split.training, split.validation, *model, diagnose_options);
    if (!result.declared.usable || !result.final_fit.usable) {
      std::cerr << "fitcal: the fit did not converge (" << result.declared.termination
                << "); nothing written\n";
      return 3;
    }
    const std::string report = "data set: " + options.logs + ", " + split.text +
                               (options.clock_map ? ", ground-truth clocks re-mapped" : "") +
                               ", fitcal " + kVersion + "\n\n" +
                               FormatDiagnoseReport(result, *model);
    std::printf("%s", report.c_str());
    std::vector<DiagnoseChoice> gate;
    DiagnoseChoice choice = GateDiagnosis(*model, split, result, options.threads, &gate);
    if (choice.name == "nominal") {
      std::cerr << "fitcal: no calibration beats the nominal robot on the held-out runs; nothing "
                   "written\n";
      return 5;
    }
    if (WorseThanNominalBeyondNoise(*model, split, gate.front(), choice, options.threads)) {
      return 5;
    }
    if (!WithUncertainty(*model, split, &choice)) return 1;
    const std::string written = WrittenCalibrationText(robot, choice);
    std::printf("%s", written.c_str());
    const std::string yaml = ModelCalibratedYaml(options, *model, runs, split, result, choice);
    const io::DiagnosePageData page =
        MakePage(options, *model, split, result, gate, choice, report);
    WriteOutputs(options, inputs, report + written, result, page, yaml);
    std::printf("\nheld-out runs as `report` computes them: CF %.4f -> %.4f\n",
                io::HeldOutMean(page.held_out, &io::DiagnoseHeldOutRun::cf_before),
                io::HeldOutMean(page.held_out, &io::DiagnoseHeldOutRun::cf_after));
    std::printf("\nwrote %s/{index.html, metrics.json, diagnose.md, calibrated.yaml%s}\n",
                options.out.c_str(), options.csv ? ", residuals.csv, residuals_declared.csv" : "");
    return 0;
  });
}

}  // namespace fitcal::tools
