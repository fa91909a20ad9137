#include "validation/everyday_driving.h"

#include <stdexcept>
#include <utility>

#include "odometry/parallel_for.h"
#include "odometry/text_format.h"
#include "validation/relative_pose_error.h"
#include "validation/trajectory_metrics.h"

namespace fitcal {

std::vector<double> EverydayDriftLengths() { return {0.5, 1.0, 2.0, 5.0}; }

EverydayDrivingMetrics EvaluateEverydayDriving(const RobotModelInterface& model,
                                               const std::vector<double>& p,
                                               const std::vector<effects::EffectValue>& effects,
                                               const std::vector<AlignedRun>& runs,
                                               const std::vector<const GroundTruthTrack*>& tracks,
                                               const std::vector<double>& lengths_m,
                                               int num_threads) {
  if (runs.size() != tracks.size()) {
    throw std::invalid_argument("EvaluateEverydayDriving: not one ground truth per run");
  }
  std::vector<TrajectoryErrors> per_run(runs.size());
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    per_run[i] = EvaluateTrajectory(model, runs[i], *tracks[i], p, effects);
  });
  EverydayDrivingMetrics out;
  out.runs = static_cast<int>(runs.size());
  for (const TrajectoryErrors& e : per_run) {
    out.cf += e.cf;
    out.mean_ate_rmse_m += e.rms_distance_m;
    out.per_run_cf.push_back(e.cf);
    out.per_run_ate_m.push_back(e.rms_distance_m);
  }
  if (out.runs > 0) {
    out.cf /= out.runs;
    out.mean_ate_rmse_m /= out.runs;
  }
  // Each run's path lengths and headings once for every length.
  std::vector<RelativePoseErrorRun> drift_runs;
  drift_runs.reserve(per_run.size());
  for (const TrajectoryErrors& e : per_run) drift_runs.emplace_back(e.ground_truth, e.odometry);
  for (double length : lengths_m) {
    RelativePoseErrorSum sum;
    DriftAtLength drift;
    for (const RelativePoseErrorRun& drift_run : drift_runs) {
      RelativePoseErrorSum run;
      drift_run.Add(length, &run);
      drift.AddRun(run.MeanTranslationPercent(), run.windows);
      sum.windows += run.windows;
      sum.translation_ratio_sum += run.translation_ratio_sum;
      sum.rotation_rad_per_m_sum += run.rotation_rad_per_m_sum;
    }
    drift.length_m = length;
    drift.translation_percent = sum.MeanTranslationPercent();
    drift.rotation_deg_per_m = RadToDeg(sum.MeanRotationRadPerM());
    out.drift.push_back(std::move(drift));
  }
  return out;
}

std::vector<std::string> EverydayDrivingRows(const EverydayDrivingMetrics& before,
                                             const EverydayDrivingMetrics& after,
                                             const std::map<std::string, std::string>& notes) {
  std::vector<std::string> rows;
  const auto row = [&](const std::string& name, double a, double b, const std::string& values,
                       const std::string& measure = "") {
    const double change = a > 0.0 ? 100.0 * (b - a) / a : 0.0;
    const auto note = notes.find(measure);
    rows.push_back(StrFormat("  %-30s %s %+8.1f%%%s", name.c_str(), values.c_str(), change,
                             note == notes.end() ? "" : ("  " + note->second).c_str()));
  };
  row("ATE RMSE [m] (mean of runs)", before.mean_ate_rmse_m, after.mean_ate_rmse_m,
      StrFormat("%10.4f %10.4f", before.mean_ate_rmse_m, after.mean_ate_rmse_m), "ATE RMSE [m]");
  for (std::size_t k = 0; k < before.drift.size() && k < after.drift.size(); ++k) {
    const DriftAtLength& a = before.drift[k];
    const DriftAtLength& b = after.drift[k];
    if (a.windows == 0) continue;
    row(StrFormat("drift %g m [%%] (%d windows)", a.length_m, a.windows), a.translation_percent,
        b.translation_percent,
        StrFormat("%10.3f %10.3f", a.translation_percent, b.translation_percent),
        StrFormat("drift %g m [%%]", a.length_m));
    row(StrFormat("drift %g m [deg/m]", a.length_m), a.rotation_deg_per_m, b.rotation_deg_per_m,
        StrFormat("%10.3f %10.3f", a.rotation_deg_per_m, b.rotation_deg_per_m));
  }
  return rows;
}

}  // namespace fitcal
