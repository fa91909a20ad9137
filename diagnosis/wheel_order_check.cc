#include "diagnosis/wheel_order_check.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "diagnosis/statistics.h"
#include "fit/model_fit.h"
#include "models/omni3/omni3_robot_model.h"
#include "fit/segment_cost.h"
#include "odometry/omni3_replay.h"
#include "odometry/parallel_for.h"

namespace fitcal {

namespace {

const char* kColumnNames[3] = {"w_a", "w_b", "w_c"};

// Final-pose SSR of the runs replayed with the inverse kinematic matrix m_inv (the fit's
// objective times 2 when m_inv is Eq. 6 at some parameters).
double SumOfSquares(const Eigen::Matrix3d& m_inv, const std::vector<AlignedRun>& runs,
                    const ResidualWeights& weights, int num_threads) {
  return SumOverRuns(runs.size(), num_threads, [&](std::size_t i) {
    const AlignedRun& run = runs[i];
    double r[3];
    Omni3FinalPoseResidual(run, weights)
        .ResidualOfFinalPose(
            omni3::ReplayWithMatrix(m_inv, run.samples, 0, run.samples.size(), run.start), r);
    return r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  });
}

// Segment SSR (segment_residual.h) of `runs` replayed with m_inv.
double SegmentSumOfSquares(const Eigen::Matrix3d& m_inv, const std::vector<SegmentedRun>& runs,
                           const ResidualWeights& weights, int num_threads) {
  return SumOverRuns(runs.size(), num_threads, [&](std::size_t i) {
    const Omni3SegmentResidual residual(runs[i], weights);
    std::vector<double> r(static_cast<std::size_t>(residual.NumResiduals()));
    residual.ResidualsWithMatrix(m_inv, r.data());
    double ssr = 0.0;
    for (double v : r) ssr += v * v;
    return ssr;
  });
}

// The signed permutation A with (mapped rates) = A (recorded rates). Replaying mapped samples
// with M^-1 is replaying the recorded ones with M^-1 A, so no run needs to be copied to score a
// mapping.
Eigen::Matrix3d MappingMatrix(const WheelMapping& m) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) a(i, m.column[i]) = m.sign[i];
  return a;
}

double FittedSumOfSquares(const std::vector<AlignedRun>& runs, const Omni3Robot& robot,
                          const WheelOrderOptions& options) {
  ModelFitOptions fit;
  fit.ceres.weights = options.weights;
  fit.ceres.num_threads = options.num_threads;
  fit.ceres.compute_covariance = false;
  fit.ceres.max_num_iterations = 50;
  const ModelFitResult result = FitModel(runs, *Omni3ModelOf(robot), fit);
  return 2.0 * result.final_cost;
}

}  // namespace

double FDistributionQuantile(double p, double d1, double d2) {
  // Bisection on log x: the CDF is monotone; 200 halvings of [1e-12, 1e12] are ample.
  double lo = std::log(1e-12), hi = std::log(1e12);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (stats::FUpperTail(std::exp(mid), d1, d2) > 1.0 - p ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

void DecideMiswiring(const MiswiringTest& test, MiswiringScores* scores) {
  MiswiringScores& s = *scores;
  const int n = test.num_residuals;
  s.fitted = n - test.num_free_parameters >= 3;
  s.degrees_of_freedom = s.fitted ? n - test.num_free_parameters : n;
  const double alpha = test.false_alarm_probability /
                       static_cast<double>(std::max<std::size_t>(1, test.num_alternatives));
  s.threshold = FDistributionQuantile(1.0 - alpha, s.degrees_of_freedom, s.degrees_of_freedom);
  s.recorded_ssr = s.recorded_nominal_ssr;
  s.best_ssr = s.best_nominal_ssr;
  // The recorded order is already at least as good at the nominal: nothing to fit.
  if (!(s.best_nominal_ssr < s.recorded_nominal_ssr)) {
    s.fitted = false;
    return;
  }
  if (s.fitted) {
    s.recorded_ssr = test.fitted_ssr(false);
    s.best_ssr = test.fitted_ssr(true);
  }
  // A perfect fit of the other order (ssr 0) is "far better" as long as the recorded one is not
  // perfect too.
  const double ratio = s.best_ssr > 0.0       ? s.recorded_ssr / s.best_ssr
                       : s.recorded_ssr > 0.0 ? std::numeric_limits<double>::infinity()
                                              : 1.0;
  if (!(ratio > s.threshold)) return;
  s.likely_miswired = true;
  std::ostringstream msg;
  msg.precision(3);
  msg << "the encoder columns look miswired: with " << test.describe_best()
      << " the runs are explained " << ratio << "x better (" << test.evidence << " " << s.best_ssr
      << " vs " << s.recorded_ssr << " as recorded; threshold " << s.threshold << " for "
      << test.sample << "); fix the log or the robot YAML's " << test.order;
  s.message = msg.str();
}

std::vector<WheelMapping> AllWheelMappings() {
  std::vector<WheelMapping> out;
  std::array<int, 3> perm{0, 1, 2};
  do {
    for (int s = 0; s < 8; ++s) {
      WheelMapping m;
      m.column = perm;
      for (int i = 0; i < 3; ++i) m.sign[i] = (s >> i) & 1 ? -1 : 1;
      out.push_back(m);
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  return out;  // next_permutation from sorted order starts with the identity, sign pattern 0
}

std::vector<AlignedRun> ApplyWheelMapping(const std::vector<AlignedRun>& runs,
                                          const WheelMapping& mapping) {
  std::vector<AlignedRun> out = runs;
  for (AlignedRun& run : out) {
    for (auto&& s : run.samples) {
      const double w[3] = {s.value[0], s.value[1], s.value[2]};
      for (int i = 0; i < 3; ++i) s.value[i] = mapping.sign[i] * w[mapping.column[i]];
    }
  }
  return out;
}

std::string DescribeWheelMapping(const WheelMapping& m) {
  const bool all_positive = m.sign == std::array<int, 3>{1, 1, 1};
  std::vector<int> moved;
  for (int i = 0; i < 3; ++i) {
    if (m.column[i] != i) moved.push_back(i);
  }
  if (all_positive && moved.size() == 2) {
    return std::string("columns ") + kColumnNames[moved[0]] + " and " + kColumnNames[moved[1]] +
           " swapped";
  }
  std::string out;
  for (int i = 0; i < 3; ++i) {
    if (m.column[i] == i && m.sign[i] > 0) continue;
    if (!out.empty()) out += ", ";
    out += std::string("wheel ") + static_cast<char>('a' + i) + " = " + (m.sign[i] < 0 ? "-" : "") +
           kColumnNames[m.column[i]];
    if (m.column[i] == i) out += " (sign flipped)";
  }
  return out.empty() ? "recorded order" : out;
}

bool IsValidMiswiringOptions(double false_alarm_probability, const ResidualWeights& weights,
                             std::string* error) {
  if (!(false_alarm_probability > 0.0 && false_alarm_probability < 1.0)) {
    *error = "false_alarm_probability must be in (0, 1)";
    return false;
  }
  if (!(weights.position_sigma_m > 0.0) || !(weights.heading_sigma_rad > 0.0)) {
    *error = "weights must be positive";
    return false;
  }
  return true;
}

bool WheelOrderOptions::IsValid(std::string* error) const {
  if (!IsValidMiswiringOptions(false_alarm_probability, weights, error)) return false;
  if (!(segment_length_m > 0.0)) {
    *error = "segment_length_m must be positive";
    return false;
  }
  return true;
}

namespace {

// What differs between the final-pose and the segment test: how a mapping is scored at the
// nominal and after a fit, and how many residuals the scores sum.
struct MappingScorer {
  std::function<double(const WheelMapping&)> nominal_ssr;
  std::function<double(const WheelMapping&)> fitted_ssr;
  int num_residuals = 0;
  std::string evidence;  // e.g. "final-pose SSR"
  std::string sample;    // e.g. "36 runs"
};

// The best other mapping at the nominal, then the decision of the header (DecideMiswiring).
WheelOrderReport Decide(const MappingScorer& scorer, const WheelOrderOptions& options) {
  const std::vector<WheelMapping> mappings = AllWheelMappings();
  WheelOrderReport report;
  report.recorded_nominal_ssr = scorer.nominal_ssr(mappings[0]);
  report.best_nominal_ssr = std::numeric_limits<double>::infinity();
  WheelMapping best_other;
  for (std::size_t k = 1; k < mappings.size(); ++k) {
    const double ssr = scorer.nominal_ssr(mappings[k]);
    if (ssr < report.best_nominal_ssr) {
      report.best_nominal_ssr = ssr;
      best_other = mappings[k];
    }
  }
  MiswiringTest test;
  test.num_residuals = scorer.num_residuals;
  test.num_free_parameters = omni3::kNumParameters;
  test.num_alternatives = mappings.size() - 1;
  test.false_alarm_probability = options.false_alarm_probability;
  test.fitted_ssr = [&](bool other) { return scorer.fitted_ssr(other ? best_other : mappings[0]); };
  test.describe_best = [&] { return DescribeWheelMapping(best_other); };
  test.evidence = scorer.evidence;
  test.sample = scorer.sample;
  test.order = "wheel order";
  DecideMiswiring(test, &report);
  if (report.likely_miswired) report.best = best_other;
  return report;
}

}  // namespace

WheelOrderReport CheckWheelOrder(const std::vector<AlignedRun>& runs, const Omni3Robot& robot,
                                 const WheelOrderOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("WheelOrderOptions: " + error);
  if (runs.empty()) throw std::invalid_argument("CheckWheelOrder: no runs");
  const Omni3ParameterArray nominal = robot.nominal.ToArray();
  const Eigen::Matrix3d m_inv = omni3::InverseKinematicMatrix(nominal.data());
  MappingScorer scorer;
  scorer.nominal_ssr = [&](const WheelMapping& mapping) {
    return SumOfSquares(m_inv * MappingMatrix(mapping), runs, options.weights, options.num_threads);
  };
  scorer.fitted_ssr = [&](const WheelMapping& mapping) {
    return FittedSumOfSquares(mapping.IsIdentity() ? runs : ApplyWheelMapping(runs, mapping), robot,
                              options);
  };
  scorer.num_residuals = 3 * static_cast<int>(runs.size());
  scorer.evidence = "final-pose SSR";
  scorer.sample = std::to_string(runs.size()) + " runs";
  return Decide(scorer, options);
}

WheelOrderReport CheckWheelOrderOnSegments(const std::vector<AlignedRun>& runs,
                                           const std::vector<const GroundTruthTrack*>& tracks,
                                           const Omni3Robot& robot,
                                           const WheelOrderOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("WheelOrderOptions: " + error);
  if (runs.empty() || tracks.size() != runs.size()) {
    throw std::invalid_argument("CheckWheelOrderOnSegments: no runs, or not one track per run");
  }
  // Windows depend on the ground truth only, so every mapping is scored on the same ones.
  SegmentOptions windows;
  windows.length_m = options.segment_length_m;
  windows.stride_fraction = 1.0;  // disjoint: independent residuals for the F test
  std::vector<std::vector<Segment>> segments(runs.size());
  int num_windows = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    segments[i] = MakeSegments(runs[i], *tracks[i], windows);
    num_windows += static_cast<int>(segments[i].size());
  }
  WheelOrderReport report;
  if (num_windows < 4) return report;  // nothing to decide on
  std::vector<SegmentedRun> segmented(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) segmented[i] = {&runs[i], segments[i]};
  const Eigen::Matrix3d m_inv = omni3::InverseKinematicMatrix(robot.nominal.ToArray().data());
  MappingScorer scorer;
  scorer.nominal_ssr = [&](const WheelMapping& mapping) {
    return SegmentSumOfSquares(m_inv * MappingMatrix(mapping), segmented, options.weights,
                               options.num_threads);
  };
  scorer.fitted_ssr = [&](const WheelMapping& mapping) {
    const std::vector<AlignedRun> mapped = ApplyWheelMapping(runs, mapping);
    std::vector<SegmentedRun> mapped_segmented(mapped.size());
    for (std::size_t i = 0; i < mapped.size(); ++i) mapped_segmented[i] = {&mapped[i], segments[i]};
    FitOptions fit;
    fit.cost = CostKind::kSegment;
    fit.weights = options.weights;
    fit.num_threads = options.num_threads;
    fit.max_num_iterations = 50;
    const FitResult result = FitOmni3(mapped, mapped_segmented, robot, fit);
    return SegmentSumOfSquares(omni3::InverseKinematicMatrix(result.parameters.data()),
                               mapped_segmented, options.weights, options.num_threads);
  };
  scorer.num_residuals = 3 * num_windows;
  scorer.evidence = "segment SSR";
  std::ostringstream sample;
  sample << num_windows << " windows of " << options.segment_length_m << " m";
  scorer.sample = sample.str();
  return Decide(scorer, options);
}

RateUnitsReport CheckRateUnits(const std::vector<RunLog>& runs, const Omni3Robot& robot) {
  RateUnitsReport report;
  const Omni3ParameterArray p = robot.nominal.ToArray();
  const double mean_distance_m =
      (robot.nominal.distance_m[0] + robot.nominal.distance_m[1] + robot.nominal.distance_m[2]) /
      3.0;
  double odo_length = 0.0, gt_length = 0.0;
  for (const RunLog& log : runs) {
    const AlignedRun run = AlignRun(log);
    Pose2d previous = run.start;
    omni3::ReplayWithMatrix(omni3::InverseKinematicMatrix(p.data()), run.samples, 0,
                            run.samples.size(), run.start, [&](std::size_t, const Pose2d& pose) {
                              odo_length += std::hypot(pose.x - previous.x, pose.y - previous.y) +
                                            mean_distance_m * std::abs(pose.theta - previous.theta);
                              previous = pose;
                            });
    const GroundTruthTrack& gt = log.ground_truth;
    for (std::size_t k = 1; k < gt.t_s.size(); ++k) {
      if (gt.t_s[k - 1] < run.t_start_s || gt.t_s[k] > run.t_final_s) continue;
      const Pose2d& a = gt.world_T_robot[k - 1];
      const Pose2d& b = gt.world_T_robot[k];
      gt_length += std::hypot(b.x - a.x, b.y - a.y) +
                   mean_distance_m * std::abs(WrapAngle(b.theta - a.theta));
    }
  }
  if (!(gt_length > 0.0) || !(odo_length > 0.0)) return report;  // nothing moved: no evidence
  report.scale = odo_length / gt_length;
  // What the bounds allow: odometry distance scales with the wheel radius.
  double lo = 1.0, hi = 1.0;
  for (int i = 0; i < 3; ++i) {
    lo = std::min(lo, robot.bounds.radius_m.lo / robot.nominal.radius_m[i]);
    hi = std::max(hi, robot.bounds.radius_m.hi / robot.nominal.radius_m[i]);
  }
  if (report.scale >= lo / 2.0 && report.scale <= hi * 2.0) return report;
  report.suspicious = true;
  struct Unit {
    const char* name;
    double factor;  // recorded value / rad/s
  };
  static const Unit kUnits[] = {
      {"deg/s", 180.0 / M_PI}, {"rev/s", 0.5 / M_PI}, {"rpm", 30.0 / M_PI}};
  double best = std::numeric_limits<double>::infinity();
  for (const Unit& u : kUnits) {
    const double distance = std::abs(std::log(report.scale / u.factor));
    if (distance < std::log(1.5) && distance < best) {
      best = distance;
      report.likely_unit = u.name;
    }
  }
  std::ostringstream msg;
  msg.precision(3);
  msg << "the encoder rates move the robot " << report.scale
      << "x as far as the ground truth shows (the radius bounds allow " << lo << ".." << hi
      << "x): likely units: "
      << (report.likely_unit.empty() ? "not rad/s" : report.likely_unit + " instead of rad/s");
  report.message = msg.str();
  return report;
}

}  // namespace fitcal
