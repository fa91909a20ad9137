#include "tools/report_command.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>

#include "diagnosis/identifiability.h"
#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/report_writer.h"
#include "io/robot_yaml.h"
#include "io/staged_directory.h"
#include "odometry/effects.h"
#include "tools/output_guard.h"
#include "tools/sim/flower_candidates.h"
#include "validation/cross_validation.h"
#include "validation/run_split.h"
#include "validation/trajectory_metrics.h"

namespace fitcal::tools {

namespace {

// TrajectoryErrors (one run) and Table6Averages (a group) carry the same Eq. 8-14 fields.
template <typename Metrics>
io::ReportMetrics MetricsOf(const Metrics& e) {
  io::ReportMetrics m;
  m.rms_distance_m = e.rms_distance_m;
  m.rms_angle_rad = e.rms_angle_rad;
  m.max_distance_m = e.max_distance_m;
  m.max_angle_rad = e.max_angle_rad;
  m.final_distance_m = e.final_distance_m;
  m.final_angle_rad = e.final_angle_rad;
  m.cf = e.cf;
  return m;
}

io::ReportStatistics StatsOf(const SummaryStatistics& s) {
  return {s.rmse, s.mean, s.median, s.std, s.min, s.max};
}

// A world point in the frame of `start` (origin at the start position, +x along its heading).
io::Point2 InStartFrame(const Pose2d& start, double x, double y) {
  const double c = std::cos(start.theta), s = std::sin(start.theta);
  const double dx = x - start.x, dy = y - start.y;
  return {c * dx + s * dy, -s * dx + c * dy};
}
io::Point2 VectorInStartFrame(const Pose2d& start, double dx, double dy) {
  const double c = std::cos(start.theta), s = std::sin(start.theta);
  return {c * dx + s * dy, -s * dx + c * dy};
}

// Family of a trajectory label for the Table 6 rows: the label without its trailing number
// ("R12" -> "R"); labels without a number form their own group.
std::string FamilyOf(const std::string& label) {
  std::size_t end = label.size();
  while (end > 0 && std::isdigit(static_cast<unsigned char>(label[end - 1]))) --end;
  return end == 0 ? label : label.substr(0, end);
}

}  // namespace

namespace {
const std::set<std::string> kReportFiles = {"index.html", "summary.md", "metrics.csv",
                                            "metrics.json"};
}  // namespace

int RunReportCommand(const ReportCommandOptions& options) {
  OdometrySampling sampling;
  if (options.sampling == "nearest") {
    sampling = OdometrySampling::kNearestTime;
  } else if (options.sampling == "linear") {
    sampling = OdometrySampling::kLinearInterpolation;
  } else {
    std::cerr << "fitcal report: unknown --sampling '" << options.sampling
              << "' (nearest or linear)\n";
    return 2;
  }
  try {
    io::DatasetOptions dataset_options;
    dataset_options.allow_paths_outside = options.allow_outside_paths;
    dataset_options.num_threads = options.threads;
    const io::DatasetIndex index = io::ReadDatasetIndex(options.logs, dataset_options);
    std::vector<std::string> inputs = DatasetInputs(index);
    inputs.push_back(options.calibration);
    if (const std::string refusal = OutputDirectoryRefusal(options.out, inputs, kReportFiles);
        !refusal.empty()) {
      std::cerr << "fitcal: " << refusal << "\n";
      return 2;
    }
    const io::Dataset dataset = io::LoadDataset(index, dataset_options);
    for (const std::string& path : {dataset.robot_path, options.calibration}) {
      const std::string model = io::ReadRobotModel(path);
      if (model != "omni3") {
        throw io::InputError(io::InputErrorKind::kUnknownModel, path, 0,
                             "model '" + model + "' is not supported by 'report' (known: omni3)");
      }
    }
    const Omni3Robot robot = io::ReadOmni3Robot(dataset.robot_path);
    const Omni3Robot calibrated = io::ReadOmni3Robot(options.calibration);
    std::vector<int> train_reps;
    if (!options.train_reps.empty()) {
      train_reps = ParseRepetitionList(options.train_reps);
    } else if (auto recorded = io::ReadCalibrationTrainingRepetitions(options.calibration)) {
      train_reps = *recorded;
    } else {
      train_reps = ParseRepetitionList("1-5");
    }
    const std::vector<AlignedRun> aligned = AlignRuns(dataset.runs);
    const RunSplit split = SplitByRepetition(aligned, train_reps);
    if (split.validation.empty()) {
      std::cerr << "fitcal report: no run of " << options.logs
                << " is outside the training repetitions (" << FormatRepetitionList(train_reps)
                << "); nothing to validate on\n";
      return 2;
    }
    const Omni3ParameterArray nominal = robot.nominal.ToArray();
    const Omni3ParameterArray p = calibrated.nominal.ToArray();

    io::ReportData data;
    data.tool_version = kVersion;
    data.dataset = options.logs;
    data.calibration = options.calibration;
    data.robot_name = calibrated.name;
    data.sampling = ToString(sampling);
    for (const effects::EffectValue& e : calibrated.effects) {
      const effects::EffectInfo& info = effects::Info(e.id);
      std::string text = std::string(info.name) + ":";
      for (int k = 0; k < info.num_parameters; ++k) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "%s %s = %.4g +- %.2g", k ? "," : "",
                      info.parameter_names[k], e.value[k], e.sigma[k]);
        text += buf;
      }
      data.calibrated_effects.push_back(text);
    }
    data.training_repetitions = FormatRepetitionList(split.training_repetitions);
    data.validation_repetitions = FormatRepetitionList(split.validation_repetitions);
    data.training_runs = static_cast<int>(split.training.size());

    // Trajectory metrics of every validation run (the RunLog holds the ground-truth track).
    std::map<std::string, const RunLog*> logs_by_id;
    for (const RunLog& log : dataset.runs) logs_by_id[log.id] = &log;
    std::vector<TrajectoryErrors> before, after;
    for (const AlignedRun& run : split.validation) {
      const GroundTruthTrack& track = logs_by_id.at(run.id)->ground_truth;
      before.push_back(EvaluateTrajectory(run, track, nominal, sampling));
      // The calibrated model as the YAML describes it: nine parameters and any effects
      // `fitcal diagnose` accepted (the replay honours them, latency included).
      after.push_back(EvaluateTrajectory(run, track, p, calibrated.effects, sampling));
      const TrajectoryErrors& b = before.back();
      const TrajectoryErrors& a = after.back();
      io::ReportRun r;
      r.id = run.id;
      r.trajectory = run.trajectory;
      r.repetition = run.repetition;
      r.ground_truth_xy.push_back({0.0, 0.0});
      r.before_xy.push_back({0.0, 0.0});
      r.after_xy.push_back({0.0, 0.0});
      for (std::size_t i = 0; i < b.t_s.size(); ++i) {
        r.t_s.push_back(b.t_s[i] - run.t_start_s);
        r.ground_truth_xy.push_back(
            InStartFrame(run.start, b.ground_truth[i].x, b.ground_truth[i].y));
        r.before_xy.push_back(InStartFrame(run.start, b.odometry[i].x, b.odometry[i].y));
        r.after_xy.push_back(InStartFrame(run.start, a.odometry[i].x, a.odometry[i].y));
      }
      r.ground_truth_xy.push_back(
          InStartFrame(run.start, run.final_ground_truth.x, run.final_ground_truth.y));
      r.before_xy.push_back(InStartFrame(run.start, b.final_odometry.x, b.final_odometry.y));
      r.after_xy.push_back(InStartFrame(run.start, a.final_odometry.x, a.final_odometry.y));
      r.before_distance_m = b.distance_error_m;
      r.after_distance_m = a.distance_error_m;
      r.before_angle_rad = b.angle_error_rad;
      r.after_angle_rad = a.angle_error_rad;
      r.before_final_error =
          VectorInStartFrame(run.start, b.final_odometry.x - b.final_ground_truth.x,
                             b.final_odometry.y - b.final_ground_truth.y);
      r.after_final_error =
          VectorInStartFrame(run.start, a.final_odometry.x - a.final_ground_truth.x,
                             a.final_odometry.y - a.final_ground_truth.y);
      r.before = MetricsOf(b);
      r.after = MetricsOf(a);
      data.runs.push_back(std::move(r));
    }

    // Table 6 rows: per family (in order of appearance) and overall.
    std::vector<std::string> families;
    for (const AlignedRun& run : split.validation) {
      const std::string f = FamilyOf(run.trajectory);
      if (std::find(families.begin(), families.end(), f) == families.end()) families.push_back(f);
    }
    auto add_row = [&](const std::string& name, const std::string& family) {
      std::vector<const TrajectoryErrors*> b, a;
      for (std::size_t i = 0; i < split.validation.size(); ++i) {
        if (family.empty() || FamilyOf(split.validation[i].trajectory) == family) {
          b.push_back(&before[i]);
          a.push_back(&after[i]);
        }
      }
      data.summary.push_back(io::ReportSummaryRow{
          name, static_cast<int>(b.size()), MetricsOf(AverageOf(b)), MetricsOf(AverageOf(a))});
    };
    if (families.size() > 1) {
      for (const std::string& f : families) add_row("trajectories " + f + "*", f);
    }
    add_row("all validation runs", "");

    // evo-style statistics of the per-run quantities.
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
      for (std::size_t i = 0; i < before.size(); ++i) {
        vb.push_back(before[i].*s.field);
        va.push_back(after[i].*s.field);
      }
      data.statistics.push_back(io::ReportStatisticsRow{s.name, s.is_angle, StatsOf(Summarize(vb)),
                                                        StatsOf(Summarize(va))});
    }

    // Uncertainty at the calibrated parameters from the training runs: covariance
    // s^2 (J^T J)^-1 with s^2 = |r|^2 / (3 N - 9), the same as the fit's (omni3_ceres_fit.h).
    const Eigen::MatrixXd jacobian =
        FinalPoseJacobian(p, split.training, ResidualWeights{}, options.threads);
    const IdentifiabilityReport ident =
        AnalyseIdentifiability(jacobian, p, sim::FlowerCandidateMotions(), nominal);
    data.identifiable = ident.identifiable;
    data.condition_number = ident.condition_number;
    data.identifiability_lines = IdentifiabilityLines(ident);
    const int dof = 3 * static_cast<int>(split.training.size()) - omni3::kNumParameters;
    Omni3ParameterArray sigma{};
    const bool has_sigma = dof > 0 && !ident.rank_deficient;
    if (has_sigma) {
      double sum_r2 = 0.0;
      for (const AlignedRun& run : split.training) {
        double r[3];
        Omni3FinalPoseResidual(run, ResidualWeights{})(p.data(), r);
        sum_r2 += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      }
      const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
      const Eigen::MatrixXd cov =
          (sum_r2 / dof) * jtj.ldlt().solve(Eigen::MatrixXd::Identity(jtj.rows(), jtj.cols()));
      data.has_correlation = true;
      data.correlation.assign(omni3::kNumParameters, std::vector<double>(omni3::kNumParameters));
      for (int k = 0; k < omni3::kNumParameters; ++k)
        sigma[k] = std::sqrt(std::max(0.0, cov(k, k)));
      for (int a = 0; a < omni3::kNumParameters; ++a) {
        for (int b = 0; b < omni3::kNumParameters; ++b) {
          const double den = sigma[a] * sigma[b];
          data.correlation[a][b] = den > 0.0 ? cov(a, b) / den : (a == b ? 1.0 : 0.0);
        }
      }
      char note[256];
      std::snprintf(note, sizeof note,
                    "One sigma from the covariance s^2 (J^T J)^-1 of the final-pose residuals of "
                    "the %zu training runs at the calibrated parameters, scaled by their residual "
                    "variance (s = %.3g, metres and radians weighed 1:1 as Eq. 14).",
                    split.training.size(), std::sqrt(sum_r2 / dof));
      data.uncertainty_note = note;
      if (!calibrated.effects.empty()) {
        data.uncertainty_note +=
            " The calibration also carries effects; this covariance is that of the nine "
            "parameters alone (the effects' one-sigma is in the YAML's effects: list).";
      }
    } else {
      data.uncertainty_note = dof <= 0 ? "No uncertainty: too few training runs (need more than 3)."
                                       : "No uncertainty: the covariance is rank deficient (see "
                                         "Identifiability below).";
    }
    std::optional<CrossValidationResult> cv;
    if (options.cross_validate) {
      CeresFitOptions fit_options;
      fit_options.num_threads = options.threads;
      cv = LeaveOneRepetitionOut(aligned, robot, fit_options);
      data.has_cv = true;
      data.cv_cf_after = StatsOf(cv->cf_validation_after);
      data.cv_cf_before = StatsOf(cv->cf_validation_before);
      for (const CrossValidationFold& f : cv->folds) {
        data.folds.push_back(io::ReportFold{f.held_out_repetition, f.usable, f.cf_training,
                                            f.cf_validation_before, f.cf_validation_after});
      }
    }
    for (int k = 0; k < omni3::kNumParameters; ++k) {
      io::ReportParameter rp;
      rp.name = ParameterName(k);
      rp.is_angle = k >= omni3::kAngleIndex;
      rp.unit = rp.is_angle ? "deg" : "m";
      rp.nominal = nominal[k];
      rp.calibrated = p[k];
      rp.has_sigma = has_sigma;
      rp.sigma = sigma[k];
      if (cv) {
        const SummaryStatistics& s = cv->parameter_spread[k];
        rp.has_cv = s.count > 0;
        rp.cv_mean = s.mean;
        rp.cv_std = s.std;
        rp.cv_min = s.min;
        rp.cv_max = s.max;
      }
      data.parameters.push_back(rp);
    }

    // Everything is computed; only now touch the output directory, as a set (README, "Nothing
    // lost"): the files go into a staged sibling renamed over the previous report, so a signal,
    // a full disk or a second writer never leaves a mix of old and new files.
    {
      namespace fs = std::filesystem;
      io::StagedDirectory staged(options.out);
      const fs::path out(staged.path());
      io::WriteFileAtomically((out / "index.html").string(), io::ReportHtml(data));
      io::WriteFileAtomically((out / "summary.md").string(), io::ReportMarkdown(data));
      io::WriteFileAtomically((out / "metrics.csv").string(), io::MetricsCsv(data));
      io::StopHereForTests("report-staged");
      io::WriteFileAtomically((out / "metrics.json").string(), io::MetricsJson(data));
      CommitOutputDirectory(staged, options.out, inputs, kReportFiles);
    }

    const io::ReportSummaryRow& all = data.summary.back();
    std::printf("validation: %zu runs (repetitions %s), odometry sampled by %s time\n",
                data.runs.size(), data.validation_repetitions.c_str(), data.sampling.c_str());
    std::printf("  CF (Eq. 14)            %.4f -> %.4f  (%+.1f %%)\n", all.before.cf, all.after.cf,
                ImprovementPercent(all.before.cf, all.after.cf));
    std::printf("  RMS distance error [m] %.4f -> %.4f  (%+.1f %%)\n", all.before.rms_distance_m,
                all.after.rms_distance_m,
                ImprovementPercent(all.before.rms_distance_m, all.after.rms_distance_m));
    for (const std::string& line : data.identifiability_lines) std::printf("%s\n", line.c_str());
    if (cv) {
      std::printf("cross-validation: %zu folds, validation CF %.4f +- %.4f (min %.4f, max %.4f)\n",
                  cv->folds.size(), cv->cf_validation_after.mean, cv->cf_validation_after.std,
                  cv->cf_validation_after.min, cv->cf_validation_after.max);
    }
    std::printf("wrote %s/{index.html, summary.md, metrics.csv, metrics.json}\n",
                options.out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "fitcal report: " << io::OneLine(e.what(), 500) << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
