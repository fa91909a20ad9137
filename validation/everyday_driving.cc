#include "validation/everyday_driving.h"

#include <optional>
#include <stdexcept>
#include <utility>

#include "odometry/parallel_for.h"
#include "odometry/text_format.h"

namespace fitcal {

std::vector<double> EverydayDriftLengths() { return {0.5, 1.0, 2.0, 5.0}; }

EverydayDrivingTruth::EverydayDrivingTruth(const AlignedRun& run, const GroundTruthTrack& track)
    : time_line(run, track),
      drift({track.world_T_robot.begin() + time_line.first,
             track.world_T_robot.begin() + time_line.end}) {}

const EverydayDrivingTruth& EverydayDrivingTruths::Of(const AlignedRun& run,
                                                      const GroundTruthTrack& track) {
  Key key{run.id, run.t_start_s, run.t_final_s};
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (const auto found = by_run_.find(key); found != by_run_.end()) return *found->second;
  }
  // Made outside the lock: the runs of one score are made in parallel.
  auto made = std::make_unique<const EverydayDrivingTruth>(run, track);
  const std::lock_guard<std::mutex> lock(mutex_);
  return *by_run_.emplace(std::move(key), std::move(made)).first->second;
}

EverydayDrivingMetrics EvaluateEverydayDriving(const RobotModelInterface& model,
                                               const std::vector<double>& p,
                                               const std::vector<effects::EffectValue>& effects,
                                               const std::vector<AlignedRun>& runs,
                                               const std::vector<const GroundTruthTrack*>& tracks,
                                               const std::vector<double>& lengths_m,
                                               int num_threads, EverydayDrivingTruths* truths) {
  if (runs.size() != tracks.size()) {
    throw std::invalid_argument("EvaluateEverydayDriving: not one ground truth per run");
  }
  EverydayDrivingMetrics out;
  out.runs = static_cast<int>(runs.size());
  out.per_run_cf.resize(runs.size());
  out.per_run_ate_m.resize(runs.size());
  // Each run's sum of windows per length.
  std::vector<std::vector<RelativePoseErrorSum>> per_run_drift(
      runs.size(), std::vector<RelativePoseErrorSum>(lengths_m.size()));
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    std::optional<EverydayDrivingTruth> own;
    const EverydayDrivingTruth& truth =
        truths ? truths->Of(runs[i], *tracks[i]) : own.emplace(runs[i], *tracks[i]);
    const TrajectoryErrors e =
        EvaluateTrajectory(model, runs[i], *tracks[i], truth.time_line, p, effects);
    out.per_run_cf[i] = e.cf;
    out.per_run_ate_m[i] = e.rms_distance_m;
    const RelativePoseErrorRun drift_run(truth.drift, e.odometry);
    for (std::size_t k = 0; k < lengths_m.size(); ++k) {
      drift_run.Add(lengths_m[k], &per_run_drift[i][k]);
    }
  });
  for (std::size_t i = 0; i < runs.size(); ++i) {
    out.cf += out.per_run_cf[i];
    out.mean_ate_rmse_m += out.per_run_ate_m[i];
  }
  if (out.runs > 0) {
    out.cf /= out.runs;
    out.mean_ate_rmse_m /= out.runs;
  }
  out.drift.reserve(lengths_m.size());
  for (std::size_t k = 0; k < lengths_m.size(); ++k) {
    RelativePoseErrorSum sum;
    DriftAtLength drift;
    drift.per_run_translation_percent.reserve(runs.size());
    drift.per_run_windows.reserve(runs.size());
    for (const std::vector<RelativePoseErrorSum>& run_drift : per_run_drift) {
      const RelativePoseErrorSum& run = run_drift[k];
      drift.AddRun(run.MeanTranslationPercent(), run.windows);
      sum.windows += run.windows;
      sum.translation_ratio_sum += run.translation_ratio_sum;
      sum.rotation_rad_per_m_sum += run.rotation_rad_per_m_sum;
    }
    drift.length_m = lengths_m[k];
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
