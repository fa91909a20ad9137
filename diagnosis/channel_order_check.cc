#include "diagnosis/channel_order_check.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "fit/model_fit.h"
#include "fit/residual_choice.h"
#include "fit/segment_cost.h"
#include "fit/statistics.h"
#include "fit/track_residual.h"
#include "models/mounted_model.h"
#include "models/pose_errors.h"
#include "odometry/invalid.h"
#include "odometry/parallel_for.h"

namespace fitcal {

namespace {

// Buffers one worker reuses for every run and mapping: a run's samples with a mapping applied,
// and the pose after every sample count. A run's are ~0.5 MB: made per run and mapping they were
// allocated and freed (mmap, page faults) hundreds of times per run.
struct RunScratch {
  explicit RunScratch(int num_channels) : mapped(num_channels) {}
  EncoderSamples mapped;
  std::vector<Pose2d> after;
};

// The run's samples with channel i = sign_i * recorded column_i, written into scratch->mapped
// (the same numbers ApplyChannelMapping gives).
const EncoderSamples& MapInto(const EncoderSamples& samples, const ChannelMapping& mapping,
                              RunScratch* scratch) {
  EncoderSamples& out = scratch->mapped;
  out.resize(samples.size());
  const int n = samples.num_channels();
  const int stride = samples.stride();
  const double* in = samples.data();
  double* o = out.data();
  for (std::size_t k = 0; k < samples.size(); ++k, in += stride, o += stride) {
    o[0] = in[0];
    for (int i = 0; i < n; ++i) o[1 + i] = mapping.sign[i] * in[1 + mapping.column[i]];
  }
  return out;
}

// SSR of one run replayed from `samples` with p: its final pose, or its segments when given.
double RunSumOfSquares(const RobotModelInterface& model, const std::vector<double>& p,
                       const AlignedRun& run, const EncoderSamples& samples,
                       const std::vector<Segment>* segments, const ChannelOrderOptions& options,
                       std::vector<Pose2d>* after) {
  if (segments == nullptr) {
    double r[3];
    FinalPoseError(model.ReplayFinalPose(p.data(), samples, run.start), run.final_ground_truth,
                   options.weights, r);
    return r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  }
  // Replay once from the identity, keeping the pose after every sample count.
  after->resize(samples.size() + 1);
  (*after)[0] = Pose2d{};
  Pose2d* poses = after->data();
  model.Replay(p.data(), samples, 0, samples.size(), Pose2d{},
               [poses](std::size_t k, const Pose2d& pose) { poses[k + 1] = pose; });
  double ssr = 0.0;
  for (const Segment& s : *segments) {
    double r[3];
    SegmentError(poses[s.begin], poses[s.end], s.ground_truth_start_T_end, options.weights, r);
    ssr += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  }
  return ssr;
}

// SSR of the runs replayed with p: final poses, or the segments when given.
double SumOfSquares(const RobotModelInterface& model, const std::vector<double>& p,
                    const std::vector<AlignedRun>& runs,
                    const std::vector<std::vector<Segment>>& segments,
                    const ChannelOrderOptions& options) {
  return SumOverRuns(runs.size(), options.num_threads, [&](std::size_t i) {
    std::vector<Pose2d> after;
    return RunSumOfSquares(model, p, runs[i], runs[i].samples,
                           segments.empty() ? nullptr : &segments[i], options, &after);
  });
}

// The nominal SSR of every mapping k >= 1 (ssr[0] is left at infinity), or infinity for a mapping
// that cannot be the smallest: each mapping's runs are summed in run order (the bits of
// SumOfSquares on the mapped runs), and a sum stops as soon as it exceeds a complete sum of
// another mapping - the terms are non-negative, so it can only grow. The smallest value and the
// first mapping that has it are the same as with every sum complete, on any number of threads.
// A sum also stops above `stop_above`: the recorded order's SSR, where only a mapping that beats
// it matters (ChannelOrderOptions::score_every_mapping).
std::vector<double> OtherMappingsNominalSsr(const RobotModelInterface& model,
                                            const std::vector<AlignedRun>& runs,
                                            const std::vector<std::vector<Segment>>& segments,
                                            const std::vector<ChannelMapping>& mappings,
                                            const ChannelOrderOptions& options,
                                            double stop_above) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> ssr(mappings.size(), inf);
  if (mappings.size() < 2) return ssr;
  std::atomic<double> smallest{stop_above};
  std::atomic<std::size_t> next{1};
  const std::size_t workers = std::min<std::size_t>(
      mappings.size() - 1, static_cast<std::size_t>(ResolveThreadCount(options.num_threads)));
  ParallelFor(workers, static_cast<int>(workers), [&](std::size_t) {
    RunScratch scratch(runs.front().samples.num_channels());
    for (std::size_t k = next++; k < mappings.size(); k = next++) {
      double sum = 0.0;
      for (std::size_t i = 0; i < runs.size() && sum <= smallest.load(); ++i) {
        const EncoderSamples& mapped = MapInto(runs[i].samples, mappings[k], &scratch);
        sum += RunSumOfSquares(model, model.robot().nominal, runs[i], mapped,
                               segments.empty() ? nullptr : &segments[i], options, &scratch.after);
      }
      if (!(sum <= smallest.load())) continue;  // stopped early, or above a complete sum
      ssr[k] = sum;
      double seen = smallest.load();
      while (sum < seen && !smallest.compare_exchange_weak(seen, sum)) {
      }
    }
  });
  return ssr;
}

// The SSR after a bounded fit of `runs` (final poses, or `segments`). With `start_windows` (final
// poses with a dense ground truth) the final-pose fit starts from the fit of those windows: final
// poses from a guess far off have local minima the well-posed windows do not (a tricycle's
// steering gain 2.5x off: the recorded order stuck at SSR 177 from the nominal and the box's
// centre and quarters, the sign-flipped one at 69.3, and `fit` refused a correctly wired robot;
// from the windows' fit 0.0056 and 69.3). Without windows, or when their fit is unusable, from the
// nominal with FitModel's global start. Each order alike. The global start from the nominal is not
// added to the windows' start: on every case measured it found no lower SSR (the real tricycle's
// two orders: 0.214 and 14.36 either way; the 2.5x gain's: 177 and 69.3 against 0.0056 and 69.3)
// and cost most of the check (17.6 of 23 s on the 2.5x gain, 1.0 of 2.0 s on the real tricycle).
// `windows_global_start`: whether a fit of windows (segments, or the start from start_windows)
// tries FitModel's global start; a fit of final poses from the nominal always does.
double FittedSumOfSquares(const RobotModelInterface& model, const std::vector<AlignedRun>& runs,
                          const std::vector<std::vector<Segment>>& segments,
                          const std::vector<std::vector<Segment>>* start_windows,
                          const ChannelOrderOptions& options, bool windows_global_start) {
  ModelFitOptions fit;
  fit.global_start = windows_global_start || segments.empty();
  fit.ceres.weights = options.weights;
  fit.ceres.num_threads = options.num_threads;
  fit.ceres.compute_covariance = false;
  fit.ceres.max_num_iterations = 50;
  // The F test counts every free parameter as fitted: no direction is held.
  fit.hold_undetermined = false;
  if (!segments.empty()) fit.segments = &segments;
  if (start_windows != nullptr) {
    ModelFitOptions on_windows = fit;
    on_windows.segments = start_windows;
    on_windows.global_start = windows_global_start;
    const ModelFitResult windows = FitModel(runs, model, on_windows);
    if (windows.HasFinitePoint()) {
      const ModelFitResult from_windows = FitModelFrom(runs, model, windows.parameters, fit);
      return SumOfSquares(model, from_windows.parameters, runs, segments, options);
    }
  }
  const ModelFitResult result = FitModel(runs, model, fit);
  return SumOfSquares(model, result.parameters, runs, segments, options);
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
      << test.sample << "); fix the log or the robot YAML's channel order";
  s.message = msg.str();
}

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
    return "columns " + robot.channels[moved[0]].rate_column + " and " +
           robot.channels[moved[1]].rate_column + " swapped";
  }
  std::string out;
  for (int i = 0; i < robot.NumChannels(); ++i) {
    if (m.column[i] == i && m.sign[i] > 0) continue;
    if (!out.empty()) out += ", ";
    out += robot.channels[i].name + " = " + (m.sign[i] < 0 ? "-" : "") +
           robot.channels[m.column[i]].rate_column;
    if (m.column[i] == i) out += " (sign flipped)";
  }
  return out.empty() ? "recorded order" : out;
}

bool ChannelOrderOptions::IsValid(std::string* error) const {
  if (!(false_alarm_probability > 0.0 && false_alarm_probability < 1.0))
    return Invalid(error, "false_alarm_probability must be in (0, 1)");
  if (!(weights.position_sigma_m > 0.0) || !(weights.heading_sigma_rad > 0.0))
    return Invalid(error, "weights must be positive");
  return true;
}

namespace {

// CheckChannelOrder, its final-pose fits started from the fit of `start_windows` when given.
ChannelOrderReport CheckOrder(const std::vector<AlignedRun>& runs,
                              const std::vector<std::vector<Segment>>& segments,
                              const std::vector<std::vector<Segment>>* start_windows,
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
  const std::vector<double> other_ssr = OtherMappingsNominalSsr(
      model, runs, segments, mappings, options,
      options.score_every_mapping ? std::numeric_limits<double>::infinity()
                                  : report.recorded_nominal_ssr);
  for (std::size_t k = 1; k < mappings.size(); ++k) {
    if (other_ssr[k] < report.best_nominal_ssr) {
      report.best_nominal_ssr = other_ssr[k];
      report.best = mappings[k];
    }
  }
  MiswiringTest test;
  test.num_residuals = num_residuals;
  test.num_free_parameters = robot.NumFree();
  test.num_alternatives = mappings.size() - 1;
  test.false_alarm_probability = options.false_alarm_probability;
  // The other mapping's fit of windows goes without the global start. In the common case it is
  // the wrong mapping: its fit stays far above the noise, so the global start always tried three
  // more starts (`fit` of a simulated tricycle guessed with half its steering gain: 7.1 -> 4.8 s
  // of CPU without them). Its windows' SSR can then only be higher (least squares: FitModel keeps
  // the lowest cost), which makes the check less ready to call a robot miswired, not more; and
  // windows have none of the far-guess minima of final poses (FittedSumOfSquares). The recorded
  // order keeps its global start: a correctly wired robot is not called miswired for a fit that
  // stopped short.
  test.fitted_ssr = [&](bool other) {
    if (!other) return FittedSumOfSquares(model, runs, segments, start_windows, options, true);
    return FittedSumOfSquares(model, ApplyChannelMapping(runs, report.best), segments,
                              start_windows, options, false);
  };
  test.describe_best = [&] { return DescribeChannelMapping(robot, report.best); };
  test.evidence = segments.empty() ? "final-pose SSR" : "segment SSR";
  test.sample = std::to_string(runs.size()) + " runs";
  DecideMiswiring(test, &report);
  return report;
}

}  // namespace

ChannelOrderReport CheckChannelOrder(const std::vector<AlignedRun>& runs,
                                     const std::vector<std::vector<Segment>>& segments,
                                     const RobotModelInterface& model,
                                     const ChannelOrderOptions& options) {
  return CheckOrder(runs, segments, nullptr, model, options);
}

namespace {

// Disjoint windows of 0.5 m of ground-truth path, *total of them (independent residuals for the
// F test), or none (*total 0) where the ground truth does not sample the path.
std::vector<std::vector<Segment>> WindowsToCheckOn(
    const std::vector<AlignedRun>& runs, const std::vector<const GroundTruthTrack*>& tracks,
    std::size_t* total) {
  std::vector<std::vector<Segment>> segments = MakeDisjointWindows(runs, tracks, total);
  // A window's ground truth is interpolated between samples: where they lie farther apart than a
  // window (start and end poses only, a pose every half loop) the window compares the odometry
  // with the straight line between two samples, not with a measured motion, and a sign flip can
  // fit that fiction better than the true wiring (a simulated differential drive's loops with
  // three poses each were refused as miswired, 3.4x). Such runs are judged on final poses only.
  if (!MeasureTrackDensity(runs, tracks).SamplesThePath()) {
    segments.assign(runs.size(), {});
    *total = 0;
  }
  return segments;
}

// On final poses, then on the `total` windows `segments` (WindowsToCheckOn) when there are 4.
ChannelOrderReport CheckPooledChannelOrder(const std::vector<AlignedRun>& runs,
                                           const std::vector<std::vector<Segment>>& segments,
                                           std::size_t total, const RobotModelInterface& model,
                                           const ChannelOrderOptions& options) {
  ChannelOrderReport final_poses =
      CheckOrder(runs, {}, total < 4 ? nullptr : &segments, model, options);
  if (total < 4) return final_poses;
  ChannelOrderReport on_windows = CheckChannelOrder(runs, segments, model, options);
  on_windows.on_windows = true;
  // Closed loops close as well with a mirrored wiring (a diff drive's right wheel negated: left
  // negated instead explains the final poses as well, 0.0311 each, and was named); the windows
  // follow the path and tell the two apart, so they name the mapping when both find one.
  if (final_poses.likely_miswired && !on_windows.likely_miswired) return final_poses;
  return on_windows;
}

// The check of each session (runs of one trajectory label; `import optiodom` labels a session so)
// when there are several, each at alpha / sessions: a driver rewired between two recordings
// leaves the other sessions' runs to outvote the rewired one's in the pool (OptiOdom's diff drive,
// the right wheel negated in one of two sessions, passed the pool and was fitted: held-out error
// 0.22 -> 0.26 m). On windows where the ground truth samples the path, else on final poses: a
// session's few closed loops close nearly as well mirrored, so at the nominal a mirrored wiring
// beat the recorded one on final poses in 7 of the real diff drive's 21 sessions, and their fits
// cost its 97-run fit 0.19 s of CPU (+18 %). The first miswired session, named; else the pool's.
// A session is checked alone only with 10 residuals per free parameter or more. With fewer the
// fit of the recorded order can stop short of the noise (a far guess, a bound) while a wrong
// mapping's fit bends into the few windows: a simulated four-wheel omni robot with its sensor's
// mount guessed 0.3 m off, one run (session) of 38 checked alone, was called miswired, 330x
// against a threshold of 136. The pool decides for such sessions.
constexpr std::size_t kMinSessionResidualsPerFreeParameter = 10;

ChannelOrderReport CheckEachSession(const std::vector<AlignedRun>& runs,
                                    const std::vector<std::vector<Segment>>& segments,
                                    const RobotModelInterface& model,
                                    const ChannelOrderOptions& options,
                                    ChannelOrderReport pooled) {
  // The sessions as `--clock-offsets session` and the per-session noise levels group them.
  const RunGroups sessions = GroupRuns(runs, ClockGrouping::kPerSession);
  if (sessions.names.size() < 2) return pooled;
  ChannelOrderOptions each = options;
  each.false_alarm_probability /= static_cast<double>(sessions.names.size());
  each.score_every_mapping = false;  // the pool's scores are the ones printed
  for (std::size_t g = 0; g < sessions.names.size(); ++g) {
    const std::string& session = sessions.names[g];
    std::vector<AlignedRun> session_runs;
    std::vector<std::vector<Segment>> session_windows;
    std::size_t total = 0;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (sessions.of_run[i] != static_cast<int>(g)) continue;
      session_runs.push_back(runs[i]);
      session_windows.push_back(segments[i]);
      total += segments[i].size();
    }
    const bool on_windows = total >= 4;
    const std::size_t residuals = 3 * (on_windows ? total : session_runs.size());
    if (residuals < kMinSessionResidualsPerFreeParameter * model.robot().NumFree()) continue;
    if (!on_windows) session_windows.clear();  // the final-pose test
    ChannelOrderReport report = CheckChannelOrder(session_runs, session_windows, model, each);
    report.on_windows = on_windows;
    if (!report.likely_miswired) continue;
    report.message = "session '" + session + "' (" + std::to_string(session_runs.size()) +
                     " of " + std::to_string(runs.size()) + " runs): " + report.message;
    return report;
  }
  return pooled;
}

}  // namespace

bool TurnsTheBodyHalfway(const RobotModelInterface& model, const ChannelMapping& mapping,
                         const std::vector<AlignedRun>& runs) {
  const RobotModelInterface& body = BaseModel(model);
  const std::unique_ptr<const PreparedKinematics<double>> kinematics =
      body.PrepareKinematics(body.robot().nominal.data());
  const std::vector<AlignedRun> mapped = ApplyChannelMapping(runs, mapping);
  double mismatch = 0.0, size = 0.0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    for (std::size_t k = 0; k < runs[r].samples.size(); ++k) {
      const auto s = runs[r].samples[k], m = mapped[r].samples[k];
      double x, y, theta, xm, ym, thetam;
      kinematics->Step(s.value, s.dt_s, &x, &y, &theta);
      kinematics->Step(m.value, m.dt_s, &xm, &ym, &thetam);
      mismatch += (xm + x) * (xm + x) + (ym + y) * (ym + y) + (thetam - theta) * (thetam - theta);
      size += x * x + y * y + theta * theta;
    }
  }
  // A relative 1e-3 in the steps: the same motion but for rounding and nominal wheels that differ
  // a little from side to side; any other miswiring differs by the steps' own size.
  return size > 0.0 && mismatch <= 1e-6 * size;
}

ChannelOrderReport CheckRecordedChannelOrder(const std::vector<AlignedRun>& runs,
                                             const std::vector<const GroundTruthTrack*>& tracks,
                                             const RobotModelInterface& model,
                                             const ChannelOrderOptions& options) {
  if (tracks.size() != runs.size()) {
    throw std::invalid_argument("CheckRecordedChannelOrder: not one ground truth per run");
  }
  std::size_t total = 0;
  const std::vector<std::vector<Segment>> segments = WindowsToCheckOn(runs, tracks, &total);
  ChannelOrderReport report = CheckPooledChannelOrder(runs, segments, total, model, options);
  if (!report.likely_miswired) {
    report = CheckEachSession(runs, segments, model, options, std::move(report));
  }
  // The data cannot tell such a mapping from a ground truth whose frame faces backwards (a pose
  // sensor mounted turned around, its yaw guessed 180 deg off): the message names both.
  if (report.likely_miswired && TurnsTheBodyHalfway(model, report.best, runs)) {
    report.message +=
        "; or the ground truth's frame faces backwards, which no run tells from this wiring (a "
        "sensor turned around: declare its ground_truth_frame yaw_deg)";
  }
  return report;
}

}  // namespace fitcal
