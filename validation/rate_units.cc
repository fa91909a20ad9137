#include "validation/rate_units.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "odometry/aligned_run.h"

namespace fitcal {
namespace {

// Rotation counted as travel at this radius, so that turning in place counts too.
constexpr double kTurnLengthM = 0.2;
// Below this much ground-truth travel there is no evidence either way.
constexpr double kMinEvidenceM = 0.5;
constexpr std::size_t kChunk = 10;  // samples per replayed step of the path

double StepLength(const Pose2d& a, const Pose2d& b) {
  return std::hypot(b.x - a.x, b.y - a.y) +
         kTurnLengthM * std::abs(std::remainder(b.theta - a.theta, 2.0 * M_PI));
}

}  // namespace

RateUnitsFinding CheckModelRateUnits(const RobotModelInterface& model,
                                     const std::vector<RunLog>& runs) {
  RateUnitsFinding finding;
  const std::vector<double>& p = model.robot().nominal;
  double odometry_m = 0.0, truth_m = 0.0;
  for (const RunLog& log : runs) {
    const AlignedRun run = AlignRun(log);
    Pose2d pose = run.start;
    for (std::size_t k = 0; k < run.samples.size(); k += kChunk) {
      const std::size_t end = std::min(run.samples.size(), k + kChunk);
      const Pose2d next = model.Replay(p.data(), run.samples, k, end, pose);
      odometry_m += StepLength(pose, next);
      pose = next;
    }
    const GroundTruthTrack& gt = log.ground_truth;
    for (std::size_t k = 1; k < gt.t_s.size(); ++k) {
      if (gt.t_s[k - 1] < run.t_start_s || gt.t_s[k] > run.t_final_s) continue;
      truth_m += StepLength(gt.world_T_robot[k - 1], gt.world_T_robot[k]);
    }
  }
  if (!(truth_m > kMinEvidenceM) || !std::isfinite(odometry_m)) return finding;
  finding.scale = odometry_m / truth_m;
  if (finding.scale >= 1.0 / kMaxPlausibleScale && finding.scale <= kMaxPlausibleScale) {
    return finding;
  }
  finding.suspicious = true;
  struct Unit {
    const char* name;
    double factor;  // logged value / rad/s
  };
  static const Unit kUnits[] = {
      {"deg/s", 180.0 / M_PI}, {"rpm", 30.0 / M_PI}, {"rev/s", 0.5 / M_PI}};
  double best = std::numeric_limits<double>::infinity();
  for (const Unit& u : kUnits) {
    const double misfit = std::abs(std::log(finding.scale / u.factor));
    if (misfit < best && misfit < std::log(1.5)) {
      best = misfit;
      finding.likely_unit = u.name;
    }
  }
  char line[400];
  // Ground-truth positions in millimetres scale the other way, by 1/1000 (turns count less there,
  // so the pooled ratio lies a little above it).
  if (std::abs(std::log(finding.scale / 1e-3)) < std::log(3.0)) {
    finding.likely_unit = "ground truth in mm";
    std::snprintf(
        line, sizeof line,
        "the ground truth's path is %.3g times the nominal robot's odometry: ground-truth "
        "positions in millimetres, not metres?; nothing fitted",
        1.0 / finding.scale);
    finding.message = line;
    return finding;
  }
  std::snprintf(line, sizeof line,
                "the nominal robot's odometry travels %.3g times the ground truth's path: the "
                "encoder rates are not in rad/s%s%s%s (or the robot file's wheel sizes or "
                "encoder.ticks_per_rev are off by that factor); nothing fitted",
                finding.scale, finding.likely_unit.empty() ? "" : " (they look like ",
                finding.likely_unit.c_str(), finding.likely_unit.empty() ? "" : ")");
  finding.message = line;
  return finding;
}

}  // namespace fitcal
