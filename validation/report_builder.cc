#include "validation/report_builder.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <set>

#include "fit/determined_directions.h"
#include "fit/model_fit.h"
#include "fit/run_split.h"
#include "fitcal/version.h"
#include "io/command_failure.h"
#include "io/input_error.h"
#include "io/warnings.h"
#include "models/mounted_model.h"
#include "odometry/text_format.h"
#include "validation/calibration_match.h"
#include "validation/never_worse.h"
#include "validation/relative_pose_error.h"
#include "validation/trajectory_family.h"
#include "validation/verdict.h"

namespace fitcal {

namespace {

// The Eq. 8-14 fields of one run or of a group's averages (AverageOf).
io::ReportMetrics MetricsOf(const TrajectoryErrors& e) {
  return {e.rms_distance_m,   e.rms_angle_rad,   e.max_distance_m, e.max_angle_rad,
          e.final_distance_m, e.final_angle_rad, e.cf};  // io::ReportMetrics' order
}

io::ReportStatistics StatsOf(const SummaryStatistics& s) {
  return {s.rmse, s.mean, s.median, s.std, s.min, s.max};
}

// A world vector in the frame of `start` (+x along its heading).
io::Point2 VectorInStartFrame(const Pose2d& start, double dx, double dy) {
  const double c = std::cos(start.theta), s = std::sin(start.theta);
  return {c * dx + s * dy, -s * dx + c * dy};
}
// A world point in the frame of `start` (origin at the start position).
io::Point2 InStartFrame(const Pose2d& start, double x, double y) {
  return VectorInStartFrame(start, x - start.x, y - start.y);
}

// The validation runs of one report, each replayed with the nominal and the calibrated model.
struct EvaluatedRuns {
  TrainingSplit split;
  std::vector<TrajectoryErrors> before, after;
  std::vector<double> cf_parameters_only;  // calibrated parameters without the effects
};

// --train-reps may choose other training runs than the recorded ones, never validate on a run the
// calibration recorded (by id and fingerprint) as one it was fitted on: its "held-out" figures
// would be training figures (--train-reps 2 on a calibration of repetition 1 passed it on its own
// training runs). Throws UsageError naming the first such run.
void RefuseValidatingOnTrainingRuns(const std::string& train_reps, const CalibrationInput& cal,
                                    const TrainingSplit& chosen, const TrainingSplit& recorded) {
  if (recorded.how != "by id") return;
  for (const AlignedRun& run : chosen.split.validation) {
    for (const AlignedRun& trained : recorded.split.training) {
      if (run.id != trained.id) continue;
      throw UsageError("--train-reps " + train_reps + " would judge " + cal.path + " on run '" +
                       run.id + "', one of the " +
                       std::to_string(recorded.split.training.size()) +
                       " runs it was fitted on (its calibration block records them): leave "
                       "--train-reps out to judge it on the others");
    }
  }
}

TrainingSplit SplitForReport(const std::string& train_reps, const ReportInputs& in,
                             const CalibrationInput& cal) {
  RecordedTraining recorded;
  if (cal.provenance) {
    recorded.run_ids = cal.provenance->training_run_ids;
    recorded.fingerprint = cal.provenance->training_fingerprint;
    recorded.repetitions = cal.provenance->training_repetitions;
  }
  TrainingSplit as_recorded =
      SplitAsRecorded(in.dataset.runs, AlignRuns(in.dataset.runs), recorded);
  if (train_reps.empty()) return as_recorded;
  TrainingSplit chosen{
      SplitByRepetition(AlignRuns(in.dataset.runs), ParseRepetitionList(train_reps)),
      "by repetition (--train-reps)"};
  RefuseValidatingOnTrainingRuns(train_reps, cal, chosen, as_recorded);
  return chosen;
}

std::string TrainingSource(const CalibrationInput& cal, const TrainingSplit& t) {
  const std::string n = std::to_string(t.split.training.size());
  const std::string reps = FormatRepetitionList(t.split.training_repetitions);
  if (t.how == "by id") {
    const std::string& selector = cal.provenance->training_trajectories;
    return n + " runs of this data set, recorded by id (repetitions " + reps +
           (selector.empty() ? "" : "; trajectories matching '" + selector + "'") + ")";
  }
  if (t.how != "none")
    return n + " runs of this data set, " + t.how + " (repetitions " + reps + ")";
  if (!cal.provenance) return "none recorded (a robot YAML without a calibration block)";
  return "another data set (" + cal.provenance->dataset + "): every run here validates";
}

EvaluatedRuns EvaluateRuns(const ReportInputs& in, const CalibrationInput& cal, TrainingSplit split,
                           OdometrySampling sampling) {
  EvaluatedRuns e;
  e.split = std::move(split);
  std::map<std::string, const RunLog*> logs_by_id;
  for (const RunLog& log : in.dataset.runs) logs_by_id[log.id] = &log;
  const std::vector<double>& nominal = in.model->robot().nominal;
  const std::vector<double>& p = cal.calibrated.nominal;
  const std::vector<effects::EffectValue>& effects = cal.calibrated.effects;
  const auto evaluate = [&](const AlignedRun& run, const GroundTruthTrack& track,
                            const std::vector<double>& q,
                            const std::vector<effects::EffectValue>& with) {
    return EvaluateTrajectory(*in.model, run, track, q, with, sampling);
  };
  for (const AlignedRun& run : e.split.split.validation) {
    const GroundTruthTrack& track = logs_by_id.at(run.id)->ground_truth;
    e.before.push_back(evaluate(run, track, nominal, {}));
    // The calibrated model as the YAML describes it: the parameters and any effects `fitcal
    // diagnose` accepted (the replay honours them, latency included).
    e.after.push_back(evaluate(run, track, p, effects));
    e.cf_parameters_only.push_back(effects.empty() ? e.after.back().cf
                                                   : evaluate(run, track, p, {}).cf);
  }
  return e;
}

io::ReportRun MakeReportRun(const AlignedRun& run, const TrajectoryErrors& b,
                            const TrajectoryErrors& a) {
  io::ReportRun r;
  r.id = run.id;
  r.trajectory = run.trajectory;
  r.repetition = run.repetition;
  r.ground_truth_xy.push_back({0.0, 0.0});
  r.before_xy.push_back({0.0, 0.0});
  r.after_xy.push_back({0.0, 0.0});
  for (std::size_t i = 0; i < b.t_s.size(); ++i) {
    r.t_s.push_back(b.t_s[i] - run.t_start_s);
    r.ground_truth_xy.push_back(InStartFrame(run.start, b.ground_truth[i].x, b.ground_truth[i].y));
    r.before_xy.push_back(InStartFrame(run.start, b.odometry[i].x, b.odometry[i].y));
    r.after_xy.push_back(InStartFrame(run.start, a.odometry[i].x, a.odometry[i].y));
  }
  r.ground_truth_xy.push_back(
      InStartFrame(run.start, run.final_ground_truth.x, run.final_ground_truth.y));
  r.before_xy.push_back(InStartFrame(run.start, b.final_odometry.x, b.final_odometry.y));
  r.after_xy.push_back(InStartFrame(run.start, a.final_odometry.x, a.final_odometry.y));
  for (std::size_t i = 1; i < r.ground_truth_xy.size(); ++i) {
    r.path_length_m += std::hypot(r.ground_truth_xy[i].x - r.ground_truth_xy[i - 1].x,
                                  r.ground_truth_xy[i].y - r.ground_truth_xy[i - 1].y);
  }
  // Distance travelled along the ground truth at each sample (the drift windows' measure).
  r.along_m.assign(b.ground_truth.size(), 0.0);
  for (std::size_t i = 1; i < b.ground_truth.size(); ++i) {
    r.along_m[i] = r.along_m[i - 1] + std::hypot(b.ground_truth[i].x - b.ground_truth[i - 1].x,
                                                 b.ground_truth[i].y - b.ground_truth[i - 1].y);
  }
  r.before_distance_m = b.distance_error_m;
  r.after_distance_m = a.distance_error_m;
  r.before_angle_rad = b.angle_error_rad;
  r.after_angle_rad = a.angle_error_rad;
  r.before_final_error = VectorInStartFrame(run.start, b.final_odometry.x - b.final_ground_truth.x,
                                            b.final_odometry.y - b.final_ground_truth.y);
  r.after_final_error = VectorInStartFrame(run.start, a.final_odometry.x - a.final_ground_truth.x,
                                           a.final_odometry.y - a.final_ground_truth.y);
  r.before_final_heading_rad = WrapAngle(b.final_odometry.theta - b.final_ground_truth.theta);
  r.after_final_heading_rad = WrapAngle(a.final_odometry.theta - a.final_ground_truth.theta);
  r.before = MetricsOf(b);
  r.after = MetricsOf(a);
  return r;
}

// Table 6 rows (per family when there are several, then all runs) and one row per trajectory.
void AddGroupRows(const EvaluatedRuns& e, io::ReportData* data) {
  const std::vector<AlignedRun>& runs = e.split.split.validation;
  const auto row = [&](const std::string& name, const std::function<bool(const AlignedRun&)>& in) {
    std::vector<const TrajectoryErrors*> b, a;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (!in(runs[i])) continue;
      b.push_back(&e.before[i]);
      a.push_back(&e.after[i]);
    }
    return io::ReportSummaryRow{name, static_cast<int>(b.size()), MetricsOf(AverageOf(b)),
                                MetricsOf(AverageOf(a))};
  };
  std::vector<std::string> families, labels;
  for (const AlignedRun& run : runs) {
    const std::string f = TrajectoryFamily(run.trajectory);
    if (std::find(families.begin(), families.end(), f) == families.end()) families.push_back(f);
    if (std::find(labels.begin(), labels.end(), run.trajectory) == labels.end()) {
      labels.push_back(run.trajectory);
    }
  }
  if (families.size() > 1) {
    for (const std::string& f : families) {
      data->summary.push_back(row("trajectories " + f + "*", [&](const AlignedRun& r) {
        return TrajectoryFamily(r.trajectory) == f;
      }));
    }
  }
  data->summary.push_back(row("all validation runs", [](const AlignedRun&) { return true; }));
  for (const std::string& label : labels) {
    data->trajectories.push_back(
        row(label, [&](const AlignedRun& r) { return r.trajectory == label; }));
  }
}

// evo-style statistics of the per-run quantities.
void AddStatistics(const EvaluatedRuns& e, io::ReportData* data) {
  struct StatDef {
    const char* name;
    bool is_angle;
    double TrajectoryErrors::*field;
  };
  const StatDef stat_defs[] = {{"rms_distance_m", false, &TrajectoryErrors::rms_distance_m},
                               {"rms_angle", true, &TrajectoryErrors::rms_angle_rad},
                               {"final_distance_m", false, &TrajectoryErrors::final_distance_m},
                               {"final_angle", true, &TrajectoryErrors::final_angle_rad},
                               {"cf", false, &TrajectoryErrors::cf}};
  for (const StatDef& s : stat_defs) {
    std::vector<double> vb, va;
    for (std::size_t i = 0; i < e.before.size(); ++i) {
      vb.push_back(e.before[i].*s.field);
      va.push_back(e.after[i].*s.field);
    }
    data->statistics.push_back(io::ReportStatisticsRow{s.name, s.is_angle, StatsOf(Summarize(vb)),
                                                       StatsOf(Summarize(va))});
  }
}

// One drift length's windows of every validation run (validation/relative_pose_error.h), before
// and after calibration: computed once, read by the drift table and the never-worse judgement.
struct DriftWindows {
  double length_m = 0.0;
  std::vector<std::vector<RelativePoseErrorWindow>> before, after;  // per run
};

// The report's drift lengths: those suited to these runs (RelativePoseErrorLengths of the median
// path length) and the everyday 1, 2 and 5 m wherever some run is long enough for them.
std::vector<DriftWindows> DriftWindowsOf(const EvaluatedRuns& e, const io::ReportData& data) {
  std::vector<double> path_lengths;
  for (const io::ReportRun& r : data.runs) path_lengths.push_back(r.path_length_m);
  const std::vector<double> suited = RelativePoseErrorLengths(Summarize(path_lengths).median);
  std::set<double> lengths(suited.begin(), suited.end());
  lengths.insert({1.0, 2.0, 5.0});
  // Both calibrations are compared with the same ground truth samples of a run.
  std::vector<RelativePoseErrorTruth> truths;
  truths.reserve(e.before.size());  // the runs below keep references into it
  std::vector<RelativePoseErrorRun> before, after;
  for (std::size_t i = 0; i < e.before.size(); ++i) {
    truths.emplace_back(e.before[i].ground_truth);
    before.emplace_back(truths.back(), e.before[i].odometry);
    after.emplace_back(truths.back(), e.after[i].odometry);
  }
  std::vector<DriftWindows> out;
  for (double length : lengths) {
    DriftWindows d{length, {}, {}};
    bool some_run_long_enough = false;
    for (std::size_t i = 0; i < before.size(); ++i) {
      d.before.push_back(before[i].Windows(length));
      d.after.push_back(after[i].Windows(length));
      some_run_long_enough = some_run_long_enough || !d.before.back().empty();
    }
    const bool is_suited = std::find(suited.begin(), suited.end(), length) != suited.end();
    if (is_suited || some_run_long_enough) out.push_back(std::move(d));
  }
  return out;
}

// Relative pose error: the mean over every window of every validation run, and each window for
// the box plots.
void AddDrift(const std::vector<DriftWindows>& drift, io::ReportData* data) {
  for (const DriftWindows& d : drift) {
    io::ReportDriftRow row;
    row.length_m = d.length_m;
    RelativePoseErrorSum before, after;
    for (std::size_t i = 0; i < d.before.size(); ++i) {
      const std::vector<RelativePoseErrorWindow>& wb = d.before[i];
      const std::vector<RelativePoseErrorWindow>& wa = d.after[i];
      for (const RelativePoseErrorWindow& w : wb) before.Add(w);
      for (const RelativePoseErrorWindow& w : wa) after.Add(w);
      for (std::size_t k = 0; k < std::min(wb.size(), wa.size()); ++k) {
        row.before_translation_percent_windows.push_back(100.0 * wb[k].translation_ratio);
        row.after_translation_percent_windows.push_back(100.0 * wa[k].translation_ratio);
        row.before_rotation_rad_per_m_windows.push_back(wb[k].rotation_rad_per_m);
        row.after_rotation_rad_per_m_windows.push_back(wa[k].rotation_rad_per_m);
        row.windows_worse += wa[k].translation_ratio > wb[k].translation_ratio ? 1 : 0;
      }
    }
    row.windows = before.windows;
    row.before_translation_percent = before.MeanTranslationPercent();
    row.after_translation_percent = after.MeanTranslationPercent();
    row.before_rotation_rad_per_m = before.MeanRotationRadPerM();
    row.after_rotation_rad_per_m = after.MeanRotationRadPerM();
    data->drift.push_back(std::move(row));
  }
}

// One run's drift at one length, as the never-worse judgement reads it.
void AddRunDrift(const std::vector<RelativePoseErrorWindow>& windows, DriftAtLength* drift) {
  RelativePoseErrorSum sum;
  for (const RelativePoseErrorWindow& w : windows) sum.Add(w);
  drift->AddRun(sum.MeanTranslationPercent(), sum.windows);
}

// fit's never-worse judgement (validation/never_worse.h) on the report's runs and drift lengths:
// the drift rows that rose say whether the runs' scatter explains it, and every measure and
// family worse than the nominal, beyond the scatter or by more than 5 % within it, is one line
// (issue 42: a circles-only fit's squares drifted 13 % more at 1 m, unsaid).
void AddNeverWorse(const EvaluatedRuns& e, const std::vector<DriftWindows>& drift,
                   io::ReportData* data) {
  EverydayDrivingMetrics before, after;
  for (std::size_t i = 0; i < e.before.size(); ++i) {
    before.per_run_cf.push_back(e.before[i].cf);
    after.per_run_cf.push_back(e.after[i].cf);
    before.per_run_ate_m.push_back(e.before[i].rms_distance_m);
    after.per_run_ate_m.push_back(e.after[i].rms_distance_m);
  }
  for (const DriftWindows& d : drift) {
    DriftAtLength b{d.length_m}, a{d.length_m};
    for (std::size_t i = 0; i < d.before.size(); ++i) {
      AddRunDrift(d.before[i], &b);
      AddRunDrift(d.after[i], &a);
    }
    before.drift.push_back(std::move(b));
    after.drift.push_back(std::move(a));
  }
  const std::vector<NeverWorseJudgement> judged =
      JudgeNeverWorse(e.split.split.validation, before, after);
  const std::map<std::string, std::string> notes = NeverWorseRowNotes(judged);
  for (io::ReportDriftRow& row : data->drift) {
    const auto note = notes.find(StrFormat("drift %g m [%%]", row.length_m));
    if (note != notes.end()) row.never_worse_note = note->second;
  }
  for (bool refusing : {true, false}) {
    for (const std::string& line : NeverWorseRefusals("the calibration", judged, refusing)) {
      data->never_worse_lines.push_back(line);
    }
  }
  for (const std::string& line : NeverWorseWithinScatter("the calibration", judged)) {
    data->never_worse_lines.push_back(line);
  }
}

// Which directions of the model's parameter space the training runs determine
// (fit/determined_directions.h, as `fit` holds them), named in parameter terms with the training
// trajectory that sees each most. The covariance is the fit's (`fitcal fit` prints it).
void AddModelIdentifiability(const ReportInputs& in, const CalibrationInput& cal,
                             const std::vector<AlignedRun>& training, int threads,
                             io::ReportData* data) {
  const DirectionAnalysis d = AnalyseDeterminedDirections(
      training, *in.model, cal.calibrated.nominal,
      std::vector<ResidualWeights>(training.size()), nullptr, threads);
  data->condition_number = d.condition_number;
  for (const UndeterminedDirection& u : d.undetermined) {
    data->identifiability_lines.push_back("not determined by the training runs: " + u.description);
  }
  if (!d.ok) data->identifiability_lines.push_back("no Jacobian at the calibrated parameters");
  const std::vector<ParameterInfo>& names = in.model->robot().parameters;
  if (d.ok && d.max_abs_correlation > kMaxAbsCorrelation) {
    data->identifiability_lines.push_back(StrFormat(
        "%s and %s correlate %.4f in the training runs' final poses (1 m against 1 rad; above "
        "%.2f; the fit's correlation comes from the residuals it fitted): the runs see mostly "
        "their combination, each alone is less certain than its sigma suggests",
        names[d.correlated_a].name.c_str(), names[d.correlated_b].name.c_str(),
        d.max_abs_correlation, kMaxAbsCorrelation));
  }
  if (d.ok && d.condition_number > kMaxConditionNumber) {
    data->identifiability_lines.push_back(
        StrFormat("condition number %.3g of the training runs' J^T J in relative units (above "
                  "%.0f): some combination of parameters is barely seen",
                  d.condition_number, kMaxConditionNumber));
  }
  data->identifiable = data->identifiability_lines.empty();
  data->uncertainty_note = "No parameter sigma here: this report does not refit a " +
                           in.model->robot().model + " robot, and the calibration records none.";
}

// The sigmas and correlation the fit recorded in the calibration's YAML, matched to this robot's
// parameters by their written key; false (nothing set) unless every parameter has one. They are
// the fit's, from its own training runs, so they hold whichever data set this report validates on.
bool AddRecordedUncertainty(const CalibrationInput& cal, io::ReportData* data,
                            std::vector<double>* sigma, bool* has_sigma) {
  if (!cal.provenance || cal.provenance->sigma.empty()) return false;
  std::vector<double> values = io::RecordedSigmas(*cal.provenance, cal.calibrated.parameters);
  if (values.empty()) return false;
  *sigma = std::move(values);
  *has_sigma = true;
  data->has_correlation = !cal.provenance->correlation.empty();
  data->correlation = cal.provenance->correlation;
  const std::string& method = cal.provenance->method;
  data->uncertainty_note = "One sigma as the fit" + (method.empty() ? "" : " (" + method + ")") +
                           " recorded it in the calibration: the covariance of its residuals on "
                           "its own training runs at the calibrated parameters.";
  return true;
}

// Uncertainty and identifiability from the training runs, only when they are in this data set.
void AddUncertainty(const ReportInputs& in, const CalibrationInput& cal,
                    const std::vector<AlignedRun>& training, int threads, io::ReportData* data,
                    std::vector<double>* sigma, bool* has_sigma) {
  *has_sigma = false;
  data->identifiability_checked = !training.empty();
  if (training.empty()) {
    data->uncertainty_note =
        "No uncertainty from this data set: the calibration's training runs are not in it.";
    AddRecordedUncertainty(cal, data, sigma, has_sigma);
    return;
  }
  AddModelIdentifiability(in, cal, training, threads, data);
  AddRecordedUncertainty(cal, data, sigma, has_sigma);
}

void AddParameters(const ReportInputs& in, const CalibrationInput& cal,
                   const std::optional<CrossValidationResult>& cv, const std::vector<double>& sigma,
                   bool has_sigma, io::ReportData* data) {
  const Robot& robot = in.model->robot();
  std::set<std::string> recorded_at_bound;
  if (cal.provenance) {
    recorded_at_bound.insert(cal.provenance->at_bound.begin(), cal.provenance->at_bound.end());
  }
  for (int k = 0; k < robot.NumParameters(); ++k) {
    io::ReportParameter rp = ReportParameterOf(robot, k, cal.calibrated.nominal[k], has_sigma,
                                               has_sigma ? sigma[k] : 0.0);
    rp.at_bound = recorded_at_bound.count(rp.name) > 0 ||
                  (!robot.IsHeld(k) && AtBound(rp.calibrated, robot.bounds[k]));
    if (cv) {
      const SummaryStatistics& s = cv->parameter_spread[k];
      rp.has_cv = s.count > 0;
      rp.cv_mean = s.mean;
      rp.cv_std = s.std;
      rp.cv_min = s.min;
      rp.cv_max = s.max;
    }
    data->parameters.push_back(rp);
  }
}

void AddEffects(const CalibrationInput& cal, const EvaluatedRuns& e, io::ReportData* data) {
  for (const effects::EffectValue& value : cal.calibrated.effects) {
    data->effects.push_back(ReportEffectOf(value));
  }
  double sum = 0.0;
  for (double cf : e.cf_parameters_only) sum += cf;
  data->cf_parameters_only = e.cf_parameters_only.empty() ? 0.0 : sum / e.cf_parameters_only.size();
}

GroupOutcome OutcomeOf(const io::ReportSummaryRow& row) {
  return {row.group,
          row.runs,
          row.before.cf,
          row.after.cf,
          row.before.final_distance_m,
          row.after.final_distance_m};
}

void AddVerdict(const CalibrationInput& cal, io::ReportData* data) {
  VerdictInputs v;
  if (cal.provenance) {
    v.termination = cal.provenance->termination;
    v.has_training_cf = cal.provenance->has_training_cf;
    v.training_cf_after = cal.provenance->cf_training_after;
  }
  for (const io::ReportParameter& p : data->parameters) {
    if (p.at_bound) v.at_bound.push_back(p.name);
  }
  v.overall = OutcomeOf(data->summary.back());
  for (std::size_t i = 0; i + 1 < data->summary.size(); ++i) {
    v.families.push_back(OutcomeOf(data->summary[i]));
  }
  for (const io::ReportSummaryRow& row : data->trajectories) {
    v.trajectories.push_back(OutcomeOf(row));
  }
  std::vector<FinalErrorSample> errors;
  for (const io::ReportRun& r : data->runs) {
    errors.push_back({r.trajectory, r.after_final_error.x, r.after_final_error.y});
  }
  v.noise_floor = TestAgainstNoiseFloor(errors);
  data->noise_floor = {v.noise_floor.available, v.noise_floor.noise_sigma_m,
                       v.noise_floor.systematic_rms_m, v.noise_floor.f_statistic,
                       v.noise_floor.p_value};
  v.identifiability_checked = data->identifiability_checked;
  v.identifiable = data->identifiable;
  v.drift_measured = !data->drift.empty();
  for (const io::ReportRun& r : data->runs) {
    v.longest_path_m = std::max(v.longest_path_m, r.path_length_m);
  }
  const Verdict verdict = JudgeCalibration(v);
  data->verdict = ToString(verdict.level);
  for (const VerdictReason& r : verdict.reasons) {
    data->verdict_reasons.push_back({ToString(r.level), r.check, r.section, r.message});
  }
}

std::string CalibrationNote(const CalibrationInput& cal) {
  if (!cal.provenance) return "a robot YAML without a calibration block";
  const io::CalibrationProvenance& p = *cal.provenance;
  return "method " + (p.method.empty() ? std::string("not recorded") : p.method) +
         ", solver termination " + (p.termination.empty() ? "not recorded" : p.termination) +
         ", trained on data set " + (p.dataset.empty() ? "not recorded" : p.dataset);
}

std::optional<CrossValidationResult> AddCrossValidation(const ReportBuildOptions& options,
                                                        const ReportInputs& in,
                                                        io::ReportData* data) {
  if (!options.cross_validate) return std::nullopt;
  // The refit `fitcal fit` makes for this model (fit/model_fit.h).
  ModelFitOptions fit_options;
  fit_options.ceres.num_threads = options.threads;
  const CrossValidationResult cv =
      LeaveOneRepetitionOut(AlignRuns(in.dataset.runs), *in.model, fit_options);
  data->has_cv = true;
  // Said: a track-fit calibration sat 13 CV std from the folds' wheelbase on the OptiOdom
  // tricycle, read as an outlier of its own cross-validation.
  data->cv_objective =
      "each fold is a bounded Ceres fit of the final poses (the sum of squared final-pose "
      "residuals), whatever objective made the calibration: a calibration fitted on tracks is "
      "another estimator, and its values may lie outside the folds' range";
  data->cv_cf_after = StatsOf(cv.cf_validation_after);
  data->cv_cf_before = StatsOf(cv.cf_validation_before);
  for (const CrossValidationFold& f : cv.folds) {
    data->folds.push_back(io::ReportFold{f.held_out_repetition, f.usable, f.cf_training,
                                         f.cf_validation_before, f.cf_validation_after});
  }
  return cv;
}

// The world tracks `report --tum` writes (pages/report_tum.h): the samples the ATE and drift are
// computed on, the odometry started at the ground truth's start pose.
void AddWorldTracks(const EvaluatedRuns& e, io::ReportData* data) {
  for (std::size_t i = 0; i < e.before.size(); ++i) {
    data->world_tracks.push_back({e.split.split.validation[i].id, e.before[i].t_s,
                                  e.before[i].ground_truth, e.before[i].odometry,
                                  e.after[i].odometry});
  }
}

// Mean signed final error (bias) of the runs in their start frames, nominal or calibrated.
io::ReportBias MeanFinalError(const std::vector<io::ReportRun>& runs, bool after) {
  io::ReportBias b;
  for (const io::ReportRun& r : runs) {
    const io::Point2& e = after ? r.after_final_error : r.before_final_error;
    b.x_m += e.x;
    b.y_m += e.y;
    b.heading_rad += after ? r.after_final_heading_rad : r.before_final_heading_rad;
  }
  const double n = std::max<double>(1.0, static_cast<double>(runs.size()));
  return {b.x_m / n, b.y_m / n, b.heading_rad / n};
}

// Linear interpolation of y(x) at x0 along non-decreasing x; NaN outside [x.front(), x.back()].
double InterpolateAt(const std::vector<double>& x, const std::vector<double>& y, double x0) {
  if (x.empty() || x0 < x.front() || x0 > x.back()) return std::nan("");
  const std::size_t j =
      static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), x0) - x.begin());
  if (j == 0) return y[0];
  const double span = x[j] - x[j - 1];
  const double f = span > 0.0 ? (x0 - x[j - 1]) / span : 1.0;
  return y[j - 1] + f * (y[j] - y[j - 1]);
}

// One error of the runs (`error`, sampled at their along_m) over the runs that reach each
// distance: quartiles and median on a grid of 80 distances up to where half the runs still go
// (the median of the runs' lengths).
io::ReportErrorBand ErrorBandOf(const std::vector<io::ReportRun>& runs,
                                const std::vector<double> io::ReportRun::*error) {
  std::vector<double> ends;
  for (const io::ReportRun& r : runs) {
    const std::vector<double>& e = r.*error;
    if (r.along_m.size() == e.size() && !e.empty()) ends.push_back(r.along_m.back());
  }
  const double reach = io::Quantile(ends, 0.5);
  io::ReportErrorBand band;
  for (int k = 0; k <= 80 && reach > 0.0; ++k) {
    const double at = reach * k / 80.0;
    std::vector<double> v;
    for (const io::ReportRun& r : runs) {
      const std::vector<double>& e = r.*error;
      if (r.along_m.size() != e.size()) continue;
      const double y = InterpolateAt(r.along_m, e, at);
      if (std::isfinite(y)) v.push_back(y);
    }
    if (v.empty()) continue;
    band.distance_m.push_back(at);
    band.lower_quartile.push_back(io::Quantile(v, 0.25));
    band.median.push_back(io::Quantile(v, 0.5));
    band.upper_quartile.push_back(io::Quantile(v, 0.75));
  }
  return band;
}

void AddBiasAndErrorBands(io::ReportData* data) {
  data->bias_before = MeanFinalError(data->runs, false);
  data->bias_after = MeanFinalError(data->runs, true);
  io::ReportErrorBands& b = data->error_bands;
  b.position_before = ErrorBandOf(data->runs, &io::ReportRun::before_distance_m);
  b.position_after = ErrorBandOf(data->runs, &io::ReportRun::after_distance_m);
  b.heading_before = ErrorBandOf(data->runs, &io::ReportRun::before_angle_rad);
  b.heading_after = ErrorBandOf(data->runs, &io::ReportRun::after_angle_rad);
}

// The whole report of one calibration on its validation runs, with the cross-validation when
// `with_cv` and it is asked for (the first calibration's only: it does not depend on the
// calibration).
io::ReportData BuildReportData(const ReportBuildOptions& options, const ReportInputs& in,
                               const CalibrationInput& cal, TrainingSplit split, bool with_cv) {
  const EvaluatedRuns e = EvaluateRuns(in, cal, std::move(split), options.sampling);
  const std::vector<AlignedRun>& training = e.split.split.training;
  io::ReportData data;
  data.tool_version = kVersion;
  data.dataset = options.dataset;
  data.calibration = cal.path;
  data.robot_name = cal.calibrated.name;
  data.sampling = ToString(options.sampling);
  data.worst_runs_drawn = options.worst_runs;
  data.training_source = TrainingSource(cal, e.split);
  data.calibration_note = CalibrationNote(cal);
  data.training_repetitions = FormatRepetitionList(e.split.split.training_repetitions);
  data.validation_repetitions = FormatRepetitionList(e.split.split.validation_repetitions);
  data.training_runs = static_cast<int>(training.size());
  for (std::size_t i = 0; i < e.before.size(); ++i) {
    data.runs.push_back(MakeReportRun(e.split.split.validation[i], e.before[i], e.after[i]));
  }
  AddWorldTracks(e, &data);
  AddBiasAndErrorBands(&data);
  AddGroupRows(e, &data);
  AddStatistics(e, &data);
  const std::vector<DriftWindows> drift = DriftWindowsOf(e, data);
  AddDrift(drift, &data);
  AddNeverWorse(e, drift, &data);
  std::vector<double> sigma;
  bool has_sigma = false;
  AddUncertainty(in, cal, training, options.threads, &data, &sigma, &has_sigma);
  const std::optional<CrossValidationResult> cv =
      with_cv ? AddCrossValidation(options, in, &data) : std::nullopt;
  AddParameters(in, cal, cv, sigma, has_sigma, &data);
  AddEffects(cal, e, &data);
  AddVerdict(cal, &data);
  return data;
}

io::ReportComparisonRow ComparisonRowOf(const io::ReportData& d) {
  io::ReportComparisonRow row;
  row.calibration = d.calibration;
  row.verdict = d.verdict;
  row.training_source = d.training_source;
  row.all = d.summary.back();
  for (const io::ReportSummaryRow& t : d.trajectories)
    row.trajectory_cf_after.push_back(t.after.cf);
  if (!d.drift.empty()) row.drift = d.drift.back();
  return row;
}

// The recorded sigmas and correlation of a mounted calibration's base parameters alone: they
// come first (models/mounted_model.h), so their block of the correlation.
void KeepTheBasesUncertainty(const Robot& base, io::CalibrationProvenance* provenance) {
  std::set<std::string> keys;
  for (const ParameterInfo& info : base.parameters) keys.insert(info.KeyName());
  std::vector<std::pair<std::string, double>> sigma;
  std::vector<int> lines;
  for (std::size_t i = 0; i < provenance->sigma.size(); ++i) {
    if (keys.count(provenance->sigma[i].first) == 0) continue;
    sigma.push_back(provenance->sigma[i]);
    if (i < provenance->sigma_lines.size()) lines.push_back(provenance->sigma_lines[i]);
  }
  provenance->sigma = std::move(sigma);
  provenance->sigma_lines = std::move(lines);
  std::vector<std::vector<double>>& correlation = provenance->correlation;
  const std::size_t n = static_cast<std::size_t>(base.NumParameters());
  if (correlation.size() > n) correlation.resize(n);
  for (std::vector<double>& row : correlation) row.resize(std::min(row.size(), n));
}

}  // namespace

CalibrationInput ReadCalibrationFor(const std::string& path, const Robot& dataset_robot) {
  const RobotModelPtr model = ReadRobotModelFile(path);
  const bool mounted = !MountParameterIndices(model->robot()).empty();
  const bool dataset_mounted = !MountParameterIndices(dataset_robot).empty();
  if (model->robot().model == dataset_robot.model && !mounted && dataset_mounted) {
    throw io::InputError(io::InputErrorKind::kBadValue, path, 0,
                         "calibrated without a ground_truth_frame, but the data set's ground "
                         "truth is a mounted sensor's (its robot YAML declares one): calibrate "
                         "on runs of that sensor to report on them");
  }
  // A calibration made from a mounted sensor, judged on ground truth of the base: its wheels are
  // the base model's parameters (models/mounted_model.h); the frame does not apply.
  Robot calibrated = mounted && !dataset_mounted ? BaseModel(*model).robot() : model->robot();
  if (calibrated.model != dataset_robot.model ||
      calibrated.NumParameters() != dataset_robot.NumParameters()) {
    throw io::InputError(io::InputErrorKind::kBadValue, path, 0,
                         "a " + calibrated.model + " robot with " +
                             std::to_string(calibrated.NumParameters()) +
                             " parameters cannot calibrate the data set's " +
                             dataset_robot.model + " robot");
  }
  if (const std::string refusal = ChannelOrderRefusal(calibrated, dataset_robot);
      !refusal.empty()) {
    throw io::InputError(io::InputErrorKind::kBadValue, path, 0, refusal);
  }
  std::optional<io::CalibrationProvenance> provenance = io::ReadCalibrationProvenance(path);
  if (mounted && !dataset_mounted) {
    io::Warn(path, 0,
             "its ground_truth_frame is not used: the data set's robot YAML declares none, so "
             "its ground truth is the base's; the wheels are judged alone");
    if (provenance) KeepTheBasesUncertainty(calibrated, &*provenance);
  }
  return {path, std::move(calibrated), std::move(provenance)};
}

std::string NothingToValidateRefusal(const std::vector<TrainingSplit>& splits,
                                     const std::string& dataset) {
  if (!splits.front().split.validation.empty()) return "";
  return "every run of " + dataset +
         (splits.size() > 1
              ? " trained at least one of the calibrations"
              : " trained the calibration (repetitions " +
                    FormatRepetitionList(splits.front().split.training_repetitions) + ")") +
         "; nothing to validate on: pass runs it did not train on as --logs (another session's "
         "import, say); with nothing held out `fit` judged it on halves of its runs (the "
         "calibration's selected_on)";
}

std::vector<TrainingSplit> CommonSplits(const std::string& train_reps, const ReportInputs& in) {
  std::vector<TrainingSplit> splits;
  std::map<std::string, int> validating;  // run id -> calibrations it validates
  for (const CalibrationInput& cal : in.calibrations) {
    splits.push_back(SplitForReport(train_reps, in, cal));
    for (const AlignedRun& run : splits.back().split.validation) ++validating[run.id];
  }
  const int all = static_cast<int>(in.calibrations.size());
  for (TrainingSplit& t : splits) {
    std::vector<AlignedRun> kept;
    std::set<int> reps;
    for (AlignedRun& run : t.split.validation) {
      if (validating[run.id] != all) continue;
      reps.insert(run.repetition);
      kept.push_back(std::move(run));
    }
    t.split.validation = std::move(kept);
    t.split.validation_repetitions.assign(reps.begin(), reps.end());
  }
  return splits;
}

io::ReportParameter ReportParameterOf(const Robot& robot, int k, double calibrated, bool has_sigma,
                                      double sigma) {
  io::ReportParameter p;
  p.name = robot.parameters[k].name;
  p.is_angle = robot.parameters[k].unit == ParameterUnit::kAngle;
  p.is_position = IsMountPosition(robot, k);
  p.unit = robot.parameters[k].DisplayUnit();
  p.held = robot.IsHeld(k);
  p.nominal = robot.nominal[k];
  p.calibrated = calibrated;
  p.has_sigma = has_sigma && !p.held;
  p.sigma = sigma;
  return p;
}

io::ReportEffect ReportEffectOf(const effects::EffectValue& value) {
  const effects::EffectInfo& info = effects::Info(value.id);
  io::ReportEffect effect;
  effect.name = info.name;
  for (int k = 0; k < info.num_parameters; ++k) {
    effect.parameter_names.push_back(info.parameter_names[k]);
    effect.values.push_back(value.value[k]);
    effect.sigmas.push_back(value.sigma[k]);
  }
  return effect;
}

io::ReportData BuildReport(const ReportInputs& in, std::vector<TrainingSplit> splits,
                           const ReportBuildOptions& options) {
  io::ReportData data =
      BuildReportData(options, in, in.calibrations.front(), std::move(splits.front()), true);
  for (std::size_t i = 1; i < in.calibrations.size(); ++i) {
    if (i == 1) data.comparison.push_back(ComparisonRowOf(data));
    data.comparison.push_back(ComparisonRowOf(
        BuildReportData(options, in, in.calibrations[i], std::move(splits[i]), false)));
  }
  return data;
}

}  // namespace fitcal
