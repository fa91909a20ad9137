#include "fit/segment_cost.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fit/dense_solver_options.h"
#include "odometry/parallel_for.h"

namespace fitcal {

bool SegmentOptions::IsValid(std::string* error) const {
  if (!(length_m > 0.0)) {
    *error = "segment length must be positive";
    return false;
  }
  if (!(stride_fraction > 0.0 && stride_fraction <= 1.0)) {
    *error = "segment stride fraction must be in (0, 1]";
    return false;
  }
  return true;
}

bool ClockMapOptions::IsValid(std::string* error) const {
  if (!(max_offset_s >= 0.0) || !(offset_step_s > 0.0) || !(max_rate >= 0.0 && max_rate < 0.5) ||
      !(rate_step > 0.0)) {
    *error = "clock map search: ranges must be >= 0 (rate < 0.5) and steps positive";
    return false;
  }
  return true;
}

namespace {

// Sample boundary times of an aligned run: boundary b lies after b samples.
std::vector<double> BoundaryTimes(const AlignedRun& run) {
  std::vector<double> t(run.samples.size() + 1);
  t[0] = run.t_start_s;
  for (std::size_t k = 0; k < run.samples.size(); ++k) t[k + 1] = t[k] + run.samples[k].dt_s;
  return t;
}

Pose2d Between(const Pose2d& a, const Pose2d& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const double dx = b.x - a.x, dy = b.y - a.y;
  return Pose2d{c * dx + s * dy, -s * dx + c * dy, b.theta - a.theta};
}

}  // namespace

std::vector<Segment> MakeSegments(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                                  const SegmentOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("SegmentOptions: " + error);
  const std::vector<double> t = BoundaryTimes(run);
  std::vector<Pose2d> q(t.size());
  std::vector<double> s(t.size(), 0.0);
  for (std::size_t b = 0; b < t.size(); ++b) {
    q[b] = InterpolateGroundTruth(ground_truth, t[b]);
    if (b > 0) s[b] = s[b - 1] + std::hypot(q[b].x - q[b - 1].x, q[b].y - q[b - 1].y);
  }
  std::vector<Segment> out;
  const double stride = options.stride_fraction * options.length_m;
  double next_start = 0.0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (s[i] < next_start) continue;
    j = std::max(j, i + 1);
    while (j < t.size() && s[j] - s[i] < options.length_m) ++j;
    if (j >= t.size()) break;
    Segment seg;
    seg.begin = i;
    seg.end = j;
    seg.ground_truth_start_T_end = Between(q[i], q[j]);
    seg.path_length_m = s[j] - s[i];
    out.push_back(seg);
    next_start = s[i] + stride;
  }
  return out;
}

std::vector<Segment> MakeCheckpointsFromStart(const AlignedRun& run,
                                              const GroundTruthTrack& ground_truth,
                                              double spacing_m) {
  if (!(spacing_m > 0.0)) throw std::invalid_argument("checkpoint spacing must be positive");
  const std::vector<double> t = BoundaryTimes(run);
  std::vector<Segment> out;
  if (t.size() < 2) return out;
  const Pose2d start = InterpolateGroundTruth(ground_truth, t[0]);
  Pose2d previous = start;
  double path_m = 0.0, next_checkpoint_m = spacing_m;
  for (std::size_t j = 1; j < t.size(); ++j) {
    const Pose2d q = InterpolateGroundTruth(ground_truth, t[j]);
    path_m += std::hypot(q.x - previous.x, q.y - previous.y);
    previous = q;
    const bool last = j + 1 == t.size();
    if (path_m < next_checkpoint_m && !last) continue;
    Segment seg;
    seg.begin = 0;
    seg.end = j;
    seg.ground_truth_start_T_end = Between(start, q);
    seg.path_length_m = path_m;
    out.push_back(seg);
    next_checkpoint_m = path_m + spacing_m;  // the count restarts at each, as the authors'
  }
  return out;
}

SegmentErrors EvaluateSegmentErrors(const Omni3ParameterArray& p,
                                    const std::vector<SegmentedRun>& runs, int num_threads) {
  std::vector<SegmentErrors> per_run(runs.size());
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    const Omni3SegmentResidual residual(runs[i], ResidualWeights{});
    std::vector<double> r(static_cast<std::size_t>(residual.NumResiduals()));
    residual(p.data(), r.data());
    SegmentErrors& e = per_run[i];
    for (std::size_t k = 0; k < runs[i].segments.size(); ++k) {
      const double* rk = &r[3 * k];
      e.cf += std::sqrt(rk[0] * rk[0] + rk[1] * rk[1] + rk[2] * rk[2]);
      e.mean_translation_error_m += std::hypot(rk[0], rk[1]);
      e.mean_abs_heading_error_rad += std::abs(rk[2]);
      ++e.num_segments;
    }
  });
  SegmentErrors out;
  for (const SegmentErrors& e : per_run) {
    out.cf += e.cf;
    out.mean_translation_error_m += e.mean_translation_error_m;
    out.mean_abs_heading_error_rad += e.mean_abs_heading_error_rad;
    out.num_segments += e.num_segments;
  }
  if (out.num_segments > 0) {
    const double n = out.num_segments;
    out.cf /= n;
    out.mean_translation_error_m /= n;
    out.mean_abs_heading_error_rad /= n;
  }
  return out;
}

ClockMap EstimateClockMap(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                          const Omni3ParameterArray& p, const ClockMapOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("ClockMapOptions: " + error);
  const std::vector<double> t = BoundaryTimes(run);
  const omni3::Matrix3<double> m_inv = omni3::InverseKinematicMatrix(p.data());
  const double lever_m = (p[0] + p[1] + p[2]) / 3.0;  // weighs omega like a wheel's speed
  const std::size_t n = run.samples.size();
  std::vector<double> speed(n), omega(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d w(run.samples[k].value[0], run.samples[k].value[1],
                            run.samples[k].value[2]);
    const Eigen::Vector3d v = m_inv * w;
    speed[k] = std::hypot(v[0], v[1]);
    omega[k] = v[2];
  }
  ClockMap best;
  best.t_mid_s = 0.5 * (t.front() + t.back());
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<Pose2d> q(t.size());
  const int num_rates = static_cast<int>(std::floor(options.max_rate / options.rate_step + 1e-9));
  const int num_offsets =
      static_cast<int>(std::floor(options.max_offset_s / options.offset_step_s + 1e-9));
  for (int ir = -num_rates; ir <= num_rates; ++ir) {
    for (int io = -num_offsets; io <= num_offsets; ++io) {
      ClockMap map = best;
      map.rate = ir * options.rate_step;
      map.offset_s = io * options.offset_step_s;
      for (std::size_t b = 0; b < t.size(); ++b)
        q[b] = InterpolateGroundTruth(ground_truth, map.Map(t[b]));
      double cost = 0.0;
      for (std::size_t k = 0; k < n; ++k) {
        const double dt = run.samples[k].dt_s;
        const double gt_speed = std::hypot(q[k + 1].x - q[k].x, q[k + 1].y - q[k].y) / dt;
        const double gt_omega = (q[k + 1].theta - q[k].theta) / dt;
        const double ds = speed[k] - gt_speed;
        const double dw = lever_m * (omega[k] - gt_omega);
        cost += dt * (ds * ds + dw * dw);
      }
      // Prefer the smaller correction on ties (flat cost when the robot stands still).
      if (cost < best_cost * (1.0 - 1e-12)) {
        best_cost = cost;
        best.rate = map.rate;
        best.offset_s = map.offset_s;
      }
    }
  }
  return best;
}

GroundTruthTrack ApplyClockMap(const GroundTruthTrack& ground_truth, const ClockMap& map) {
  GroundTruthTrack out = ground_truth;
  for (double& t : out.t_s) t = (t - map.offset_s + map.rate * map.t_mid_s) / (1.0 + map.rate);
  return out;
}

int ParameterTying::NumFree() const { return 1 + *std::max_element(group.begin(), group.end()); }

ParameterTying ParameterTying::Nine() { return ParameterTying{}; }

ParameterTying ParameterTying::CommonDistanceThreeRadii() {
  ParameterTying t;
  t.name = "reduced (common R, r_a..r_c)";
  t.group = {0, 0, 0, 1, 2, 3, -1, -1, -1};
  return t;
}

bool FitOptions::IsValid(std::string* error) const {
  if (!(weights.position_sigma_m > 0.0) || !(weights.heading_sigma_rad > 0.0)) {
    *error = "residual sigmas must be positive";
    return false;
  }
  if (max_num_iterations < 1 || num_threads < 0) {
    *error = "max_num_iterations must be >= 1 and num_threads >= 0";
    return false;
  }
  if (tying.NumFree() < 1) {
    *error = "the parameter tying leaves nothing free";
    return false;
  }
  for (int j = 0; j < tying.NumFree(); ++j) {
    if (std::find(tying.group.begin(), tying.group.end(), j) == tying.group.end()) {
      *error = "free parameter " + std::to_string(j) + " is tied to nothing";
      return false;
    }
  }
  return true;
}

int FitResult::NumAtBound() const {
  return static_cast<int>(std::count(at_bound.begin(), at_bound.end(), true));
}

namespace {

// p = nominal with p_k replaced by q_{group[k]}: the tied/fixed model seen by a residual on the
// nine parameters.
template <typename Inner>
class TiedResidual {
 public:
  TiedResidual(Inner* inner, const ParameterTying& tying, const Omni3ParameterArray& nominal)
      : inner_(inner), tying_(tying), nominal_(nominal) {}
  template <typename T>
  bool operator()(T const* const* q, T* residual) const {
    T p[omni3::kNumParameters];
    for (int k = 0; k < omni3::kNumParameters; ++k) {
      p[k] = tying_.group[k] >= 0 ? q[0][tying_.group[k]] : T(nominal_[k]);
    }
    return (*inner_)(p, residual);
  }

 private:
  std::unique_ptr<Inner> inner_;
  ParameterTying tying_;
  Omni3ParameterArray nominal_;
};

template <typename Inner>
ceres::CostFunction* MakeTied(Inner* inner, int num_residuals, const ParameterTying& tying,
                              const Omni3ParameterArray& nominal) {
  auto* cost = new ceres::DynamicAutoDiffCostFunction<TiedResidual<Inner>, 9>(
      new TiedResidual<Inner>(inner, tying, nominal));
  cost->AddParameterBlock(tying.NumFree());
  cost->SetNumResiduals(num_residuals);
  return cost;
}

}  // namespace

FitResult FitOmni3(const std::vector<AlignedRun>& final_runs,
                   const std::vector<SegmentedRun>& segmented, const Omni3Robot& robot,
                   const FitOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("FitOptions: " + error);
  const Omni3ParameterArray nominal = robot.nominal.ToArray();
  const auto box = robot.ParameterBounds();
  const int num_free = options.tying.NumFree();
  // Start at the mean nominal of each group; bounds = the intersection of its members' boxes.
  std::vector<double> q(num_free, 0.0), lo(num_free, -1e300), hi(num_free, 1e300);
  std::vector<int> count(num_free, 0);
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    const int j = options.tying.group[k];
    if (j < 0) continue;
    q[j] += nominal[k];
    ++count[j];
    lo[j] = std::max(lo[j], box[k].lo);
    hi[j] = std::min(hi[j], box[k].hi);
  }
  for (int j = 0; j < num_free; ++j) {
    q[j] /= count[j];
    if (!(lo[j] <= q[j] && q[j] <= hi[j])) {
      throw std::invalid_argument("FitOmni3: tied parameters have disjoint bounds");
    }
  }

  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  int num_blocks = 0;
  if (options.cost == CostKind::kFinalPose) {
    for (const AlignedRun& run : final_runs) {
      problem.AddResidualBlock(
          MakeTied(new Omni3FinalPoseResidual(run, options.weights), 3, options.tying, nominal),
          nullptr, q.data());
      ++num_blocks;
    }
  } else {
    for (const SegmentedRun& run : segmented) {
      if (run.segments.empty()) continue;
      auto* inner = new Omni3SegmentResidual(run, options.weights);
      const int m = inner->NumResiduals();
      problem.AddResidualBlock(MakeTied(inner, m, options.tying, nominal), nullptr, q.data());
      ++num_blocks;
    }
  }
  if (num_blocks == 0) throw std::invalid_argument("FitOmni3: no training runs (or no segments)");
  for (int j = 0; j < num_free; ++j) {
    problem.SetParameterLowerBound(q.data(), j, lo[j]);
    problem.SetParameterUpperBound(q.data(), j, hi[j]);
  }
  const ceres::Solver::Options solver_options =
      DenseSolverOptions(options.max_num_iterations, options.num_threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  FitResult result;
  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  result.message = summary.message;
  result.iterations = static_cast<int>(summary.iterations.size());
  bool finite = true;
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    const int j = options.tying.group[k];
    result.parameters[k] = j >= 0 ? q[j] : nominal[k];
    finite = finite && std::isfinite(result.parameters[k]);
    if (j >= 0) {
      const double tol = 1e-6 * (hi[j] - lo[j]);
      result.at_bound[k] = q[j] <= lo[j] + tol || q[j] >= hi[j] - tol;
    }
  }
  result.usable = finite && summary.termination_type == ceres::CONVERGENCE;
  return result;
}

}  // namespace fitcal
