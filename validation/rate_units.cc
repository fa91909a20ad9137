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
// A ground truth sampled fast measures its own noise as path (5 mm of noise at 100 Hz on a robot
// at 0.1 m/s lengthens it ~7x); samples at least this far apart step 2 cm there, ~6 % longer.
constexpr double kMinMeasuredIntervalS = 0.2;
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
// start, every sample inside it kMinMeasuredIntervalS after the last, its end), and only over
// those short enough that the ground truth measures the path there (kMaxMeasuredIntervalS, or
// kChunk encoder samples at most): a ground truth of start and end poses only
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
    PathLengths odometry_path;
    Pose2d odometry;
    const std::size_t interval_begin = k;
    while (k < run.samples.size() && t_s < instant_s) {
      const std::size_t first = k;
      while (k < run.samples.size() && t_s < instant_s && k - first < kChunk) {
        t_s += run.samples[k++].dt_s;
      }
      const Pose2d next = model.Replay(p.data(), run.samples, first, k, odometry);
      odometry_path.Add(odometry, next, true);
      odometry = next;
    }
    // Or kChunk encoder samples at most, whatever the clock says (both logs' times in ms: every
    // interval 1000x long, and the path was not measured at all).
    const bool measured =
        instant_s - t_last_s <= kMaxMeasuredIntervalS || k - interval_begin <= kChunk;
    if (measured) {
      lengths->odometry_m += odometry_path.odometry_m;
      lengths->odometry_translation_m += odometry_path.odometry_translation_m;
      lengths->Add(truth, truth_there, false);
    }
    truth = truth_there;
    t_last_s = instant_s;
  };
  for (std::size_t g = 0; g < gt.t_s.size(); ++g) {
    if (gt.t_s[g] > run.t_start_s && gt.t_s[g] < run.t_final_s &&
        gt.t_s[g] - t_last_s >= kMinMeasuredIntervalS) {
      interval_to(gt.t_s[g], gt.world_T_robot[g]);
    }
  }
  interval_to(run.t_final_s, run.final_ground_truth);
}

// The largest factor the bounds let a wheel radius move from its nominal, either way (infinite
// without wheel radii).
double WheelRadiusBoundsScale(const Robot& robot) {
  double scale = 0.0;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const double r = robot.nominal[k];
    if (!robot.parameters[k].IsWheelRadius() || !(r > 0.0)) continue;
    scale = std::max({scale, robot.bounds[k].hi / r, r / robot.bounds[k].lo});
  }
  return scale > 0.0 ? scale : std::numeric_limits<double>::infinity();
}

}  // namespace

RateUnitsFinding CheckModelRateUnits(const RobotModelInterface& model,
                                     const std::vector<RunLog>& runs) {
  RateUnitsFinding finding;
  // Times in ms or us where s are meant: every encoder interval 1e3 (1e6) times as long, and the
  // rates integrate over it to as much more travel - where the ground truth, as slow in count,
  // measures no path at all (rates and ground truth in ms were blamed on the wiring).
  if (const double interval_s = TypicalEncoderInterval(runs); interval_s > 1.0) {
    finding.suspicious = true;
    finding.likely_unit = interval_s > 1e3 ? "us" : "ms";
    finding.message = StrFormat(
        "the encoder samples lie %.3g s apart, where a calibration log records every 0.001-0.1 s: "
        "times in %s, not s?; nothing fitted",
        interval_s, finding.likely_unit.c_str());
    return finding;
  }
  PathLengths lengths;
  for (const RunLog& log : runs) AddPathLengths(model, log, &lengths);
  if (!(lengths.truth_m > kMinEvidenceM) || !std::isfinite(lengths.odometry_m)) return finding;
  finding.scale = lengths.odometry_m / lengths.truth_m;
  // The wheels' travel scales with their radii, which the fit keeps inside their bounds: a scale
  // half again beyond what the bounds allow no fit can undo (encoder.ticks_per_rev declared 2x
  // off, x2 against x4 quadrature decoding, was blamed on the wiring). Robots without wheel radii
  // in their bounds keep kMaxPlausibleScale.
  const double bounds_scale = WheelRadiusBoundsScale(model.robot());
  const double most = std::min(kMaxPlausibleScale, 1.5 * bounds_scale);
  const auto plausible = [most](double scale) { return scale >= 1.0 / most && scale <= most; };
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
  if (finding.likely_unit.empty() && finding.scale >= 1.0 / kMaxPlausibleScale &&
      finding.scale <= kMaxPlausibleScale) {
    finding.message = StrFormat(
        "the nominal robot's odometry travels %.3g times the ground truth's path, where the "
        "bounds let a wheel radius change %.3gx at most: encoder.ticks_per_rev (x2 against x4 "
        "quadrature?) or the wheel sizes are off by that factor, or the rates are not in rad/s; "
        "nothing fitted",
        finding.scale, bounds_scale);
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
