#include "diagnosis/channel_order_check.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "diagnosis/wheel_order_check.h"
#include "fit/model_fit.h"
#include "fit/pose_errors.h"
#include "odometry/parallel_for.h"

namespace fitcal {

namespace {

// sum_i ssr(i): each run's term computed in parallel, the sum taken in run order (the same bits
// on any number of threads).
template <typename Fn>
double SumOverRuns(std::size_t n, int num_threads, Fn&& ssr) {
  std::vector<double> per_run(n, 0.0);
  ParallelFor(n, num_threads, [&](std::size_t i) { per_run[i] = ssr(i); });
  double sum = 0.0;
  for (double v : per_run) sum += v;
  return sum;
}

// SSR of the runs replayed with p: final poses, or the segments when given.
double SumOfSquares(const RobotModelInterface& model, const std::vector<double>& p,
                    const std::vector<AlignedRun>& runs,
                    const std::vector<std::vector<Segment>>& segments,
                    const ChannelOrderOptions& options) {
  return SumOverRuns(runs.size(), options.num_threads, [&](std::size_t i) {
    const AlignedRun& run = runs[i];
    double ssr = 0.0;
    if (segments.empty()) {
      double r[3];
      FinalPoseError(model.ReplayFinalPose(p.data(), run.samples, run.start),
                     run.final_ground_truth, options.weights, r);
      return r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    }
    // Replay once from the identity, keeping the pose after every sample count.
    std::vector<Pose2d> after(run.samples.size() + 1);
    model.Replay(p.data(), run.samples, 0, run.samples.size(), Pose2d{},
                 [&after](std::size_t k, const Pose2d& pose) { after[k + 1] = pose; });
    for (const Segment& s : segments[i]) {
      double r[3];
      SegmentError(after[s.begin], after[s.end], s.ground_truth_start_T_end, options.weights, r);
      ssr += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    }
    return ssr;
  });
}

double FittedSumOfSquares(const RobotModelInterface& model, const std::vector<AlignedRun>& runs,
                          const std::vector<std::vector<Segment>>& segments,
                          const ChannelOrderOptions& options) {
  ModelFitOptions fit;
  fit.ceres.weights = options.weights;
  fit.ceres.num_threads = options.num_threads;
  fit.ceres.compute_covariance = false;
  fit.ceres.max_num_iterations = 50;
  // The F test counts every free parameter as fitted: no direction is held.
  fit.hold_undetermined = false;
  if (!segments.empty()) fit.segments = &segments;
  const ModelFitResult result = FitModel(runs, model, fit);
  return SumOfSquares(model, result.parameters, runs, segments, options);
}

std::string ColumnName(const ChannelInfo& c) { return c.rate_column; }

}  // namespace

std::vector<AlignedRun> ApplyChannelMapping(const std::vector<AlignedRun>& runs,
                                            const ChannelMapping& mapping) {
  std::vector<AlignedRun> out = runs;
  for (AlignedRun& run : out) {
    const int n = run.samples.num_channels();
    double recorded[kMaxChannels];
    for (auto&& s : run.samples) {
      for (int i = 0; i < n; ++i) recorded[i] = s.value[i];
      for (int i = 0; i < n; ++i) s.value[i] = mapping.sign[i] * recorded[mapping.column[i]];
    }
  }
  return out;
}

std::string DescribeChannelMapping(const Robot& robot, const ChannelMapping& m) {
  std::vector<int> moved;
  bool all_positive = true;
  for (int i = 0; i < robot.NumChannels(); ++i) {
    if (m.column[i] != i) moved.push_back(i);
    all_positive = all_positive && m.sign[i] > 0;
  }
  if (all_positive && moved.size() == 2) {
    return "columns " + ColumnName(robot.channels[moved[0]]) + " and " +
           ColumnName(robot.channels[moved[1]]) + " swapped";
  }
  std::string out;
  for (int i = 0; i < robot.NumChannels(); ++i) {
    if (m.column[i] == i && m.sign[i] > 0) continue;
    if (!out.empty()) out += ", ";
    out += robot.channels[i].name + " = " + (m.sign[i] < 0 ? "-" : "") +
           ColumnName(robot.channels[m.column[i]]);
    if (m.column[i] == i) out += " (sign flipped)";
  }
  return out.empty() ? "recorded order" : out;
}

bool ChannelOrderOptions::IsValid(std::string* error) const {
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

ChannelOrderReport CheckChannelOrder(const std::vector<AlignedRun>& runs,
                                     const std::vector<std::vector<Segment>>& segments,
                                     const RobotModelInterface& model,
                                     const ChannelOrderOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("ChannelOrderOptions: " + error);
  if (runs.empty()) throw std::invalid_argument("CheckChannelOrder: no runs");
  const Robot& robot = model.robot();
  const std::vector<ChannelMapping> mappings = model.CandidateMiswirings();
  ChannelOrderReport report;
  int num_residuals = 3 * static_cast<int>(runs.size());
  if (!segments.empty()) {
    num_residuals = 0;
    for (const auto& w : segments) num_residuals += 3 * static_cast<int>(w.size());
    if (num_residuals < 12) return report;  // fewer than 4 windows: nothing to decide on
  }
  report.recorded_nominal_ssr = SumOfSquares(model, robot.nominal, runs, segments, options);
  report.best_nominal_ssr = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k < mappings.size(); ++k) {
    const double ssr = SumOfSquares(model, robot.nominal, ApplyChannelMapping(runs, mappings[k]),
                                    segments, options);
    if (ssr < report.best_nominal_ssr) {
      report.best_nominal_ssr = ssr;
      report.best = mappings[k];
    }
  }
  const int free = robot.NumFree();
  report.fitted = num_residuals - free >= 3;
  report.degrees_of_freedom = report.fitted ? num_residuals - free : num_residuals;
  const double alpha = options.false_alarm_probability /
                       static_cast<double>(std::max<std::size_t>(1, mappings.size() - 1));
  report.threshold =
      FDistributionQuantile(1.0 - alpha, report.degrees_of_freedom, report.degrees_of_freedom);
  report.recorded_ssr = report.recorded_nominal_ssr;
  report.best_ssr = report.best_nominal_ssr;
  if (!(report.best_nominal_ssr < report.recorded_nominal_ssr)) {
    report.fitted = false;
    return report;
  }
  if (report.fitted) {
    report.recorded_ssr = FittedSumOfSquares(model, runs, segments, options);
    report.best_ssr =
        FittedSumOfSquares(model, ApplyChannelMapping(runs, report.best), segments, options);
  }
  const double ratio = report.best_ssr > 0.0       ? report.recorded_ssr / report.best_ssr
                       : report.recorded_ssr > 0.0 ? std::numeric_limits<double>::infinity()
                                                   : 1.0;
  if (!(ratio > report.threshold)) return report;
  report.likely_miswired = true;
  std::ostringstream msg;
  msg.precision(3);
  msg << "the encoder columns look miswired: with " << DescribeChannelMapping(robot, report.best)
      << " the runs are explained " << ratio << "x better ("
      << (segments.empty() ? "final-pose" : "segment") << " SSR " << report.best_ssr << " vs "
      << report.recorded_ssr << " as recorded; threshold " << report.threshold << " for "
      << runs.size() << " runs); fix the log or the robot YAML's channel order";
  report.message = msg.str();
  return report;
}

}  // namespace fitcal
