#include "validation/rate_units.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "odometry/aligned_run.h"
#include "odometry/text_format.h"

namespace fitcal {
namespace {

// Rotation counted as travel at this radius, so that turning in place counts too.
constexpr double kTurnLengthM = 0.2;
// Ground-truth intervals longer than this are not a measured path (a robot drives far and turns
// much in a second); shorter ones are, at any speed a calibration drive has.
constexpr double kMaxMeasuredIntervalS = 1.0;
constexpr std::size_t kChunk = 10;  // samples per replayed step of the odometry's path
// Below this much ground-truth travel there is no evidence either way.
constexpr double kMinEvidenceM = 0.5;

double StepLength(const Pose2d& a, const Pose2d& b) {
  return std::hypot(b.x - a.x, b.y - a.y) +
         kTurnLengthM * std::abs(std::remainder(b.theta - a.theta, 2.0 * M_PI));
}

// Both paths (translation + kTurnLengthM x rotation) and their translations alone: when the
// translations agree and the sums do not, the ground truth's heading is the odd one out.
struct PathLengths {
  double odometry_m = 0.0, truth_m = 0.0;
  double odometry_translation_m = 0.0, truth_translation_m = 0.0;
  void Add(const Pose2d& a, const Pose2d& b, bool is_odometry) {
    (is_odometry ? odometry_m : truth_m) += StepLength(a, b);
    (is_odometry ? odometry_translation_m : truth_translation_m) +=
        std::hypot(b.x - a.x, b.y - a.y);
  }
};

// Both paths over the same intervals between consecutive ground-truth instants (the window's
// start, every sample inside it, its end), and only over those short enough that the ground truth
// measures the path there (kMaxMeasuredIntervalS): a ground truth of start and end poses only
// measures the straight line between them, not the path the wheels drove, so it is no evidence
// of a unit error. The odometry is replayed in steps of kChunk samples inside an interval, so that
// rates 57x too large (deg/s), which spin the odometry round many times, count in full.
void AddPathLengths(const RobotModelInterface& model, const RunLog& log, PathLengths* lengths) {
  const std::vector<double>& p = model.robot().nominal;
  const AlignedRun run = AlignRun(log);
  const GroundTruthTrack& gt = log.ground_truth;
  Pose2d truth = run.start;
  double t_s = run.t_start_s, t_last_s = run.t_start_s;
  std::size_t k = 0;
  const auto interval_to = [&](double instant_s, const Pose2d& truth_there) {
    const bool measured = instant_s - t_last_s <= kMaxMeasuredIntervalS;
    Pose2d odometry;
    while (k < run.samples.size() && t_s < instant_s) {
      const std::size_t first = k;
      while (k < run.samples.size() && t_s < instant_s && k - first < kChunk) {
        t_s += run.samples[k++].dt_s;
      }
      const Pose2d next = model.Replay(p.data(), run.samples, first, k, odometry);
      if (measured) lengths->Add(odometry, next, true);
      odometry = next;
    }
    if (measured) lengths->Add(truth, truth_there, false);
    truth = truth_there;
    t_last_s = instant_s;
  };
  for (std::size_t g = 0; g < gt.t_s.size(); ++g) {
    if (gt.t_s[g] > run.t_start_s && gt.t_s[g] < run.t_final_s) {
      interval_to(gt.t_s[g], gt.world_T_robot[g]);
    }
  }
  interval_to(run.t_final_s, run.final_ground_truth);
}

}  // namespace

RateUnitsFinding CheckModelRateUnits(const RobotModelInterface& model,
                                     const std::vector<RunLog>& runs) {
  RateUnitsFinding finding;
  PathLengths lengths;
  for (const RunLog& log : runs) AddPathLengths(model, log, &lengths);
  if (!(lengths.truth_m > kMinEvidenceM) || !std::isfinite(lengths.odometry_m)) return finding;
  finding.scale = lengths.odometry_m / lengths.truth_m;
  const auto plausible = [](double scale) {
    return scale >= 1.0 / kMaxPlausibleScale && scale <= kMaxPlausibleScale;
  };
  if (plausible(finding.scale)) return finding;
  finding.suspicious = true;
  // Positions that agree and turns that do not: the ground truth's heading column is in another
  // unit (degrees read as radians turn 57x as much; wrapped to +-pi between samples, less).
  const double translation_scale =
      lengths.odometry_translation_m / lengths.truth_translation_m;
  if (lengths.truth_translation_m > kMinEvidenceM && plausible(translation_scale)) {
    finding.likely_unit = "ground-truth heading";
    finding.message = StrFormat(
        "the ground truth's positions travel as the nominal robot's odometry does (%.3g times) "
        "but with its turns the path is %.3g times the odometry's: the ground truth's heading "
        "(theta) is not in radians (degrees?); nothing fitted",
        1.0 / translation_scale, 1.0 / finding.scale);
    return finding;
  }
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
  // Ground-truth positions in millimetres scale the other way, by 1/1000 (turns count less there,
  // so the pooled ratio lies a little above it).
  if (std::abs(std::log(finding.scale / 1e-3)) < std::log(3.0)) {
    finding.likely_unit = "ground truth in mm";
    finding.message = StrFormat(
        "the ground truth's path is %.3g times the nominal robot's odometry: ground-truth "
        "positions in millimetres, not metres?; nothing fitted",
        1.0 / finding.scale);
    return finding;
  }
  finding.message = StrFormat(
      "the nominal robot's odometry travels %.3g times the ground truth's path: the encoder "
      "rates are not in rad/s%s%s%s (or the robot file's wheel sizes or encoder.ticks_per_rev "
      "are off by that factor); nothing fitted",
      finding.scale, finding.likely_unit.empty() ? "" : " (they look like ",
      finding.likely_unit.c_str(), finding.likely_unit.empty() ? "" : ")");
  return finding;
}

}  // namespace fitcal
