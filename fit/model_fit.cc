#include "fit/model_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "fit/ceres_problem.h"
#include "fit/correlation.h"
#include "fit/determined_directions.h"
#include "fit/last_evaluation_memo.h"
#include "fit/segment_cost.h"
#include "fit/serial_covariance.h"
#include "io/text_file.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

// The covariance's message when J^T J of the free parameters is singular at the fit (also a
// reason for the global start: ReasonToStartAcrossTheBox).
constexpr char kRankDeficient[] =
    "covariance is rank deficient: the runs cannot determine all free parameters";

// Whether the problem has track residuals (and so clock offsets).
bool UsesTracks(const ModelFitOptions& options) {
  return options.segments == nullptr && options.residuals != ResidualKind::kFinalPose;
}

// Run i's track and final-pose weights: its session's (weights_per_run) or the data set's (for
// the tracks ModelFitOptions::track_weights, else the final poses').
ResidualWeights TrackWeightsOf(const ModelFitOptions& options, std::size_t i) {
  if (i < options.weights_per_run.size()) return options.weights_per_run[i].track;
  return options.track_weights.value_or(options.ceres.weights);
}
ResidualWeights FinalPoseWeightsOf(const ModelFitOptions& options, std::size_t i) {
  if (i < options.weights_per_run.size()) return options.weights_per_run[i].final_pose;
  return options.ceres.weights;
}

// Each run's weights as the fit weighs its residuals (tracks or final poses).
std::vector<ResidualWeights> WeightsOfRuns(const ModelFitOptions& options, std::size_t num_runs) {
  std::vector<ResidualWeights> out;
  for (std::size_t i = 0; i < num_runs; ++i) {
    out.push_back(UsesTracks(options) ? TrackWeightsOf(options, i)
                                      : FinalPoseWeightsOf(options, i));
  }
  return out;
}

// Rounds of the active set: one per parameter that comes to rest on a bound, and releases.
constexpr int kMaxActiveSetRounds = 16;

// Directions held at the nominal and the hold's weight (residual units per prior sigma).
struct HeldDirections {
  std::vector<UndeterminedDirection> directions;
  double weight = 1.0;
};

// Holds directions at the nominal: r_j = w u_j . ((p - p_nominal) / prior_sigma), one row per
// held direction u_j (fit/determined_directions.h). Linear, so its Jacobian is the constant
// matrix. w makes a held direction stiffer than any the data determine by kHoldStiffness.
class HoldDirectionsCost : public ceres::CostFunction {
 public:
  HoldDirectionsCost(const std::vector<UndeterminedDirection>& held, const Robot& robot,
                     double weight)
      : nominal_(robot.nominal), rows_(held.size(), robot.NumParameters()) {
    for (std::size_t j = 0; j < held.size(); ++j) {
      for (int k = 0; k < robot.NumParameters(); ++k) {
        const double prior_sigma = robot.bounds[k].Width() / std::sqrt(12.0);
        rows_(j, k) = robot.IsHeld(k) ? 0.0 : weight * held[j].prior_units[k] / prior_sigma;
      }
    }
    set_num_residuals(static_cast<int>(held.size()));
    mutable_parameter_block_sizes()->push_back(robot.NumParameters());
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = static_cast<int>(nominal_.size());
    for (int j = 0; j < rows_.rows(); ++j) {
      residuals[j] = 0.0;
      for (int k = 0; k < n; ++k) residuals[j] += rows_(j, k) * (parameters[0][k] - nominal_[k]);
    }
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      for (int j = 0; j < rows_.rows(); ++j) {
        for (int k = 0; k < n; ++k) jacobians[0][j * n + k] = rows_(j, k);
      }
    }
    return true;
  }

 private:
  std::vector<double> nominal_;
  Eigen::MatrixXd rows_;
};

// A run's residual block, its repeated evaluations at one point answered from a memo
// (fit/last_evaluation_memo.h: Ceres' bounded line search evaluates the step's end twice).
ceres::CostFunction* Memo(ceres::CostFunction* cost) { return new LastEvaluationMemo(cost); }

// One Ceres problem over the training runs with the parameters in `fixed` held constant.
class FitProblem {
 public:
  FitProblem(const std::vector<AlignedRun>& training, const RobotModelInterface& model,
             const ModelFitOptions& fit_options, const std::vector<bool>& fixed, double* p,
             double* clock_offsets, const HeldDirections& holds = {},
             std::vector<OdometryMemo>* memos = nullptr) {
    const CeresFitOptions& options = fit_options.ceres;
    ceres::Problem::Options problem_options = ProblemOptionsOnSharedContext();
    problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(problem_options);
    const bool final_poses = fit_options.residuals != ResidualKind::kTrack;
    const bool tracks = fit_options.residuals != ResidualKind::kFinalPose;
    for (std::size_t i = 0; i < training.size(); ++i) {
      const AlignedRun& run = training[i];
      if (fit_options.segments != nullptr) {
        if ((*fit_options.segments)[i].empty()) continue;
        data_blocks_.push_back(problem_->AddResidualBlock(
            Memo(model.SegmentCost(run, (*fit_options.segments)[i], options.weights)), nullptr,
            p));
        continue;
      }
      if (final_poses) {
        data_blocks_.push_back(problem_->AddResidualBlock(
            Memo(model.FinalPoseCost(run, FinalPoseWeightsOf(fit_options, i))), MakeLoss(options),
            p));
      }
      if (!tracks) continue;
      const TrackCheckpoints& track = fit_options.track->runs[i];
      if (!track.segments.empty()) {
        data_blocks_.push_back(problem_->AddResidualBlock(
            Memo(TrackResidual::Create(track, model, TrackWeightsOf(fit_options, i),
                                       fit_options.track->options,
                                       memos != nullptr ? &(*memos)[i] : nullptr)),
            nullptr, p, clock_offsets + track.clock_group));
      }
    }
    if (tracks && fit_options.segments == nullptr) BoundClockOffsets(fit_options, clock_offsets);
    if (!holds.directions.empty()) {
      problem_->AddResidualBlock(
          new HoldDirectionsCost(holds.directions, model.robot(), holds.weight), nullptr, p);
    }
    BoundModelBlock(model.robot(), fixed, p, problem_.get());
    p_ = p;
  }

  // Each clock offset in [-max, max], or held at its value when not estimated.
  void BoundClockOffsets(const ModelFitOptions& fit_options, double* clock_offsets) {
    const TrackFitData& track = *fit_options.track;
    for (std::size_t g = 0; g < track.clock_groups.size(); ++g) {
      double* offset = clock_offsets + g;
      if (!problem_->HasParameterBlock(offset)) continue;
      if (!track.estimate_clock_offsets) {
        problem_->SetParameterBlockConstant(offset);
        continue;
      }
      problem_->SetParameterLowerBound(offset, 0, -kMaxClockOffsetS);
      problem_->SetParameterUpperBound(offset, 0, kMaxClockOffsetS);
    }
  }

  ceres::Problem& problem() { return *problem_; }
  // The runs' residual blocks (not the hold), for the residual variance.
  const std::vector<ceres::ResidualBlockId>& data_blocks() const { return data_blocks_; }

  // Gradient of the (loss-shaped) cost in the model's parameters (robot().parameters order) - in
  // all of them only when none is fixed: Ceres gives a block with fixed entries (SubsetManifold)
  // the gradient of its free ones alone.
  std::vector<double> ModelGradient() {
    ceres::Problem::EvaluateOptions options;
    options.parameter_blocks = {p_};
    double cost = 0.0;
    std::vector<double> gradient;
    problem_->Evaluate(options, &cost, nullptr, &gradient, nullptr);
    return gradient;
  }

 private:
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<ceres::ResidualBlockId> data_blocks_;
  double* p_ = nullptr;  // the model's parameter block
};

// Ends a bounded solve once a free parameter has rested on its bound (AtBound) for
// kBoundContactSteps successful steps in a row: from there Ceres' projected steps only crawl
// (header comment), so the active set takes over at once instead of after the iteration limit.
constexpr int kBoundContactSteps = 3;

class BoundContactStop : public ceres::IterationCallback {
 public:
  BoundContactStop(const Robot& robot, const double* p, const std::vector<bool>& fixed)
      : robot_(robot), p_(p), fixed_(fixed) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration == 0 || !summary.step_is_successful) return ceres::SOLVER_CONTINUE;
    bool resting = false;
    for (int k = 0; k < robot_.NumParameters(); ++k) {
      resting = resting || (!fixed_[k] && AtBound(p_[k], robot_.bounds[k]));
    }
    contact_steps_ = resting ? contact_steps_ + 1 : 0;
    if (contact_steps_ < kBoundContactSteps) return ceres::SOLVER_CONTINUE;
    fired_ = true;
    return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }
  bool fired() const { return fired_; }

 private:
  const Robot& robot_;
  const double* p_;  // the parameter block, updated every iteration
  const std::vector<bool>& fixed_;
  int contact_steps_ = 0;
  bool fired_ = false;
};

void Accumulate(const ceres::Solver::Summary& summary, ModelFitResult* result) {
  result->termination = ceres::TerminationTypeToString(summary.termination_type);
  result->message = summary.message;
  result->iterations += static_cast<int>(summary.iterations.size());
  result->evaluations += summary.num_residual_evaluations + summary.num_jacobian_evaluations;
  result->final_cost = summary.final_cost;
}

// One Ceres solve of `fit` whose parameters are `p` with `fixed` held. With the active set on, a
// BoundContactStop ends it early; it then reports NO_CONVERGENCE, which hands the point to the
// active set, and the function returns true.
bool SolveUntilBoundContact(const Robot& robot, const ModelFitOptions& options,
                            const std::vector<bool>& fixed, double* p, ceres::Problem* problem,
                            ceres::Solver::Summary* summary) {
  ceres::Solver::Options solver_options = SolverOptionsFor(options.ceres);
  BoundContactStop stop(robot, p, fixed);
  if (options.active_set_bounds) {
    solver_options.update_state_every_iteration = true;
    solver_options.callbacks.push_back(&stop);
  }
  ceres::Solve(solver_options, problem, summary);
  if (!stop.fired() || summary->termination_type != ceres::USER_SUCCESS) return false;
  summary->termination_type = ceres::NO_CONVERGENCE;
  summary->message = "a parameter rests on its bound: the active set takes over";
  return true;
}

// Fixes every parameter that rests on a bound (AtBound) exactly on it.
void FixParametersAtBound(const Robot& robot, std::vector<double>* p, std::vector<bool>* fixed) {
  const std::vector<bool> on_bound = ParametersAtBound(robot, *p);
  for (std::size_t k = 0; k < p->size(); ++k) {
    if (!on_bound[k]) continue;
    (*fixed)[k] = true;
    const Interval& box = robot.bounds[k];
    (*p)[k] = (*p)[k] - box.lo < box.hi - (*p)[k] ? box.lo : box.hi;
  }
}

// The cost's gradient in every model parameter at p (FitCostGradient): measured on a problem with
// nothing fixed. With the held parameters fixed it had fewer entries, g[k] was another
// parameter's entry or lay past the end, and fits with a held parameter on a bound released
// parameters by chance (valgrind; a simulated ASOC's fits differed from run to run, stop 66).
std::vector<double> GradientInEveryParameter(const std::vector<AlignedRun>& training,
                                             const RobotModelInterface& model,
                                             const ModelFitOptions& options, double* p,
                                             double* clock_offsets, const HeldDirections& holds,
                                             std::vector<OdometryMemo>* memos) {
  FitProblem all_free(training, model, options,
                      std::vector<bool>(model.robot().NumParameters(), false), p, clock_offsets,
                      holds, memos);
  return all_free.ModelGradient();
}

// Active-set rounds after a bounded solve that did not converge (header comment). Returns the
// last solve's summary.
ceres::Solver::Summary RefineWithActiveSet(const std::vector<AlignedRun>& training,
                                           const RobotModelInterface& model,
                                           const ModelFitOptions& options,
                                           const HeldDirections& holds,
                                           ceres::Solver::Summary summary, ModelFitResult* result,
                                           std::vector<OdometryMemo>* memos) {
  const Robot& robot = model.robot();
  const int n = robot.NumParameters();
  std::vector<double>& p = result->parameters;
  std::vector<bool> fixed = result->held;
  FixParametersAtBound(robot, &p, &fixed);
  for (int round = 0; round < kMaxActiveSetRounds; ++round) {
    ++result->active_set_rounds;
    FitProblem fit(training, model, options, fixed, p.data(), result->clock_offsets_s.data(),
                   holds, memos);
    const bool contact =
        SolveUntilBoundContact(robot, options, fixed, p.data(), &fit.problem(), &summary);
    Accumulate(summary, result);
    if (contact) {  // another parameter came to rest on its bound: fix it too
      FixParametersAtBound(robot, &p, &fixed);
      continue;
    }
    if (summary.termination_type != ceres::CONVERGENCE) break;
    // Release a bound parameter whose descent direction points into the box.
    const std::vector<double> g = GradientInEveryParameter(
        training, model, options, p.data(), result->clock_offsets_s.data(), holds, memos);
    bool released = false;
    for (int k = 0; k < n; ++k) {
      if (!fixed[k] || result->held[k]) continue;
      const bool at_lo = p[k] <= robot.bounds[k].lo;
      if ((at_lo && g[k] < 0.0) || (!at_lo && g[k] > 0.0)) {
        fixed[k] = false;
        released = true;
      }
    }
    if (!released) break;
  }
  return summary;
}

// The residuals the runs contribute (not the holds): 3 per final pose, 3 per checkpoint or window.
int NumDataResiduals(const std::vector<AlignedRun>& training, const ModelFitOptions& options) {
  int num_residuals = 0;
  if (options.segments != nullptr) {
    for (const auto& windows : *options.segments)
      num_residuals += 3 * static_cast<int>(windows.size());
    return num_residuals;
  }
  if (options.residuals != ResidualKind::kTrack)
    num_residuals += 3 * static_cast<int>(training.size());
  if (UsesTracks(options)) {
    for (const TrackCheckpoints& t : options.track->runs)
      num_residuals += 3 * static_cast<int>(t.segments.size());
  }
  return num_residuals;
}

// A cost's residuals and its Jacobian in every estimated unknown (the model's parameters, then
// the clock offsets; m columns), evaluated at `parameters` (Jacobians of blocks in order).
struct EvaluatedBlock {
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;
};
EvaluatedBlock EvaluateBlock(const ceres::CostFunction& cost,
                             const std::vector<const double*>& parameters,
                             const std::vector<int>& first_column, int m) {
  const int rows = cost.num_residuals();
  EvaluatedBlock out{Eigen::VectorXd::Zero(rows), Eigen::MatrixXd::Zero(rows, m)};
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> j;
  std::vector<double*> jacobians;
  for (int size : cost.parameter_block_sizes()) {
    j.emplace_back(rows, size);
    jacobians.push_back(j.back().data());
  }
  if (!cost.Evaluate(parameters.data(), out.residuals.data(), jacobians.data())) {
    out.jacobian.resize(0, 0);
    return out;
  }
  for (std::size_t b = 0; b < j.size(); ++b) {
    if (first_column[b] >= 0) out.jacobian.middleCols(first_column[b], j[b].cols()) += j[b];
  }
  return out;
}

// What a held direction leaves uncertain (header, "Uncertainty"). The held fit sits at the
// nominal along each held direction, so its error there is the nominal's, u = nominal - truth, of
// which nothing is known but the bounds (read as a uniform prior over the box, variance
// width^2 / 12, as fit/determined_directions.h reads them). The hold is stiff, so the fit's own
// covariance is near zero along it and excluded the truth (a mecanum robot's R_fl -6 sigma,
// tests/recorded_robot_cli_test.cc). To first order the held fit's error moves with u as B u,
// B = H^-1 J_h^T J_h (H the information with the hold, J_h the hold's Jacobian): the directions
// themselves, and whatever the fit moved with them (the information's cross terms). Adds
// B Cov(u) B^T to the covariance and keeps it apart in held_directions_covariance.
void AddHeldDirectionsCovariance(const Robot& robot, const HeldDirections& holds,
                                 const Eigen::MatrixXd& inverse_information,
                                 ModelFitResult* result) {
  const int n = robot.NumParameters();
  const HoldDirectionsCost hold(holds.directions, robot, holds.weight);
  const Eigen::MatrixXd j = EvaluateBlock(hold, {result->parameters.data()}, {0}, n).jacobian;
  Eigen::VectorXd prior_variance = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    const double width = robot.bounds[k].Width();
    if (!result->held[k]) prior_variance(k) = width * width / 12.0;
  }
  const Eigen::MatrixXd b = inverse_information * j.transpose() * j;
  result->held_directions_covariance = b * prior_variance.asDiagonal() * b.transpose();
  result->covariance += result->held_directions_covariance;
}

// One run's track errors at the solution for the random-walk covariance (fit/serial_covariance.h),
// weighed as the fit weighed them (`weights`: TrackWeightsOf), so that the sandwich's bread and
// meat are those of the objective that was minimised.
TrackErrorChain TrackChainOf(const TrackCheckpoints& track, const RobotModelInterface& model,
                             const ModelFitOptions& options, const ResidualWeights& weights,
                             const std::vector<double>& p, double offset_s, int offset_column,
                             int m) {
  const std::unique_ptr<TrackResidual> cost(static_cast<TrackResidual*>(
      TrackResidual::Create(track, model, weights, options.track->options)));
  const EvaluatedBlock block =
      EvaluateBlock(*cost, {p.data(), &offset_s}, {0, offset_column}, m);
  TrackErrorChain chain;
  if (block.jacobian.size() == 0) return chain;
  const std::vector<double> pose = cost->OdometryFromStart(p.data());
  const Eigen::Vector3d w(1.0 / weights.position_sigma_m, 1.0 / weights.position_sigma_m,
                          1.0 / weights.heading_sigma_rad);
  for (std::size_t k = 0; k < track.segments.size(); ++k) {
    const Pose2d q = GroundTruthFromStart(track, k, offset_s);
    const double c = std::cos(q.theta), s = std::sin(q.theta);
    const double ex = pose[3 * k] - q.x, ey = pose[3 * k + 1] - q.y;
    const Eigen::Vector3d e(c * ex + s * ey, -s * ex + c * ey,
                            WrapAngle(pose[3 * k + 2] - q.theta));
    // r_k = factor W e_k: the factor (run weight, loss) from the residual itself.
    const Eigen::Vector3d r = block.residuals.segment<3>(3 * static_cast<Eigen::Index>(k));
    const double weighted = w.cwiseProduct(e).norm();
    const double factor = weighted > 0.0 ? r.norm() / weighted : 0.0;
    chain.jacobian.push_back(block.jacobian.middleRows(3 * static_cast<Eigen::Index>(k), 3));
    chain.residual_per_error.push_back(factor * w.asDiagonal().toDenseMatrix());
    chain.error.push_back(e);
    chain.ground_truth_from_start.push_back(q);
  }
  return chain;
}

// The covariance of a fit with track residuals: the sandwich of fit/serial_covariance.h over
// the free parameters and the estimated clock offsets. With final poses as well (kBoth), a run's
// final pose and its track share one random walk; their scores are added with the bound
// Var(a + b) <= 2 Var(a) + 2 Var(b) (final poses: s^2 J^T J, independent across runs), which errs
// on the wide side by at most sqrt(2) in sigma.
void TrackSandwichCovariance(const std::vector<AlignedRun>& training,
                             const RobotModelInterface& model, const ModelFitOptions& options,
                             const HeldDirections& holds, int num_offsets,
                             ModelFitResult* result) {
  const int n = model.robot().NumParameters();
  const int m = n + num_offsets;
  const std::vector<double>& p = result->parameters;
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(m, m);
  std::vector<TrackErrorChain> chains;
  Eigen::MatrixXd final_pose_information = Eigen::MatrixXd::Zero(m, m);
  double final_pose_squares = 0.0;
  int final_pose_residuals = 0;
  for (std::size_t i = 0; i < training.size(); ++i) {
    const TrackCheckpoints& track = options.track->runs[i];
    if (options.residuals == ResidualKind::kBoth) {
      const std::unique_ptr<ceres::CostFunction> cost(
          model.FinalPoseCost(training[i], FinalPoseWeightsOf(options, i)));
      const EvaluatedBlock block = EvaluateBlock(*cost, {p.data()}, {0}, m);
      if (block.jacobian.size() > 0) {
        final_pose_information += block.jacobian.transpose() * block.jacobian;
        final_pose_squares += block.residuals.squaredNorm();
        final_pose_residuals += static_cast<int>(block.residuals.size());
      }
    }
    if (track.segments.empty()) continue;
    const int column = num_offsets > 0 ? n + track.clock_group : -1;
    chains.push_back(TrackChainOf(track, model, options, TrackWeightsOf(options, i), p,
                                  result->clock_offsets_s[track.clock_group], column, m));
    for (const Eigen::MatrixXd& j : chains.back().jacobian) information += j.transpose() * j;
  }
  information += final_pose_information;
  Eigen::MatrixXd meat = RandomWalkScoreCovariance(chains, m);
  if (final_pose_residuals > 0) {
    const double s2 = final_pose_squares / std::max(1, final_pose_residuals - n);
    meat = 2.0 * meat + 2.0 * s2 * final_pose_information;
  }
  if (!holds.directions.empty()) {
    const HoldDirectionsCost hold(holds.directions, model.robot(), holds.weight);
    const Eigen::MatrixXd j = EvaluateBlock(hold, {p.data()}, {0}, m).jacobian;
    information += j.transpose() * j;
  }
  // Only the free unknowns: held parameters (and offsets of groups without a track) keep zero
  // rows and columns.
  std::vector<int> free;
  for (int k = 0; k < m; ++k) {
    if (k < n ? !result->held[k] : information(k, k) > 0.0) free.push_back(k);
  }
  // H^-1 once: the sandwich's two factors, and what the held directions move with (B = H^-1 ...).
  const Eigen::MatrixXd inverse = InverseInformation(information(free, free));
  if (inverse.size() == 0) {
    result->covariance_message = kRankDeficient;
    return;
  }
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(m, m);
  full(free, free) = inverse * meat(free, free) * inverse.transpose();
  result->covariance = full.topLeftCorner(n, n);
  if (!holds.directions.empty()) {
    Eigen::MatrixXd full_inverse = Eigen::MatrixXd::Zero(m, m);
    full_inverse(free, free) = inverse;
    AddHeldDirectionsCovariance(model.robot(), holds, full_inverse.topLeftCorner(n, n), result);
  }
  result->sigma = SigmasOf(result->covariance);
  result->correlation = CorrelationOf(result->covariance);
  result->has_covariance = true;
  result->clock_offset_sigma_s.assign(result->clock_offsets_s.size(), 0.0);
  for (int g = 0; g < num_offsets; ++g) {
    result->clock_offset_sigma_s[g] = std::sqrt(std::max(0.0, full(n + g, n + g)));
  }
}

void ComputeCovariance(const std::vector<AlignedRun>& training, const RobotModelInterface& model,
                       const ModelFitOptions& options, const HeldDirections& holds,
                       ModelFitResult* result) {
  const int n = model.robot().NumParameters();
  const int num_free =
      n - static_cast<int>(std::count(result->held.begin(), result->held.end(), true)) -
      static_cast<int>(holds.directions.size());
  const int num_offsets = UsesTracks(options) && options.track->estimate_clock_offsets
                              ? static_cast<int>(options.track->clock_groups.size())
                              : 0;
  const int dof = NumDataResiduals(training, options) - num_free - num_offsets;
  if (!result->usable || dof <= 0) {
    result->covariance_message = dof <= 0 ? "too few runs for a covariance (need more than " +
                                                std::to_string(num_free / 3) + ")"
                                          : "no covariance: the fit is not usable";
    return;
  }
  std::vector<double> p = result->parameters;
  std::vector<double> offsets = result->clock_offsets_s;
  FitProblem fit(training, model, options, result->held, p.data(), offsets.data(), holds);
  // s^2 from the plain sum of squares of the runs, whatever loss shaped the objective.
  result->residual_sigma = std::sqrt(SumOfSquares(&fit.problem(), fit.data_blocks()) / dof);
  const double s2 = result->residual_sigma * result->residual_sigma;
  if (UsesTracks(options)) {
    TrackSandwichCovariance(training, model, options, holds, num_offsets, result);
    return;
  }
  std::vector<const double*> blocks = {p.data()};
  for (int g = 0; g < num_offsets; ++g) {
    if (fit.problem().HasParameterBlock(&offsets[g])) blocks.push_back(&offsets[g]);
  }
  const std::vector<Eigen::MatrixXd> covariance = ScaledCovariance(
      &fit.problem(), blocks, s2, /*pseudo_inverse=*/false, options.ceres.num_threads);
  if (covariance.empty()) {
    result->covariance_message = kRankDeficient;
    return;
  }
  result->covariance = covariance[0];
  if (!holds.directions.empty() && s2 > 0.0) {
    AddHeldDirectionsCovariance(model.robot(), holds, covariance[0] / s2, result);
  }
  result->sigma = SigmasOf(result->covariance);
  result->correlation = CorrelationOf(result->covariance);
  result->has_covariance = true;
  result->clock_offset_sigma_s.assign(result->clock_offsets_s.size(), 0.0);
  for (std::size_t b = 1; b < blocks.size(); ++b) {
    result->clock_offset_sigma_s[blocks[b] - offsets.data()] = SigmasOf(covariance[b])[0];
  }
}

}  // namespace

const char* ToString(ResidualKind kind) {
  switch (kind) {
    case ResidualKind::kFinalPose:
      return "final-pose";
    case ResidualKind::kTrack:
      return "track";
    case ResidualKind::kBoth:
      return "both";
  }
  return "?";
}

bool ParseResidualKind(const std::string& text, ResidualKind* out) {
  for (ResidualKind kind : {ResidualKind::kFinalPose, ResidualKind::kTrack, ResidualKind::kBoth}) {
    if (text == ToString(kind)) {
      *out = kind;
      return true;
    }
  }
  return false;
}

bool AtBound(double value, const Interval& box) {
  const double tolerance = 1e-6 * box.Width();
  return value <= box.lo + tolerance || value >= box.hi - tolerance;
}

std::vector<bool> ParametersAtBound(const Robot& robot, const std::vector<double>& p) {
  std::vector<bool> out(p.size(), false);
  for (std::size_t k = 0; k < p.size(); ++k) out[k] = AtBound(p[k], robot.bounds[k]);
  return out;
}

namespace {

// The clock offsets of every group with the parameters `p` held, each the minimum of its group's
// exact track cost (the ground truth interpolated linearly at t + dt, TrackResidual): a scan of the
// bounded interval every kOffsetScanStepS, then a golden-section search of the best step's
// neighbourhood to kOffsetSearchToleranceS (without `scan`, the scan covers kLocalScanSteps steps
// either side of the current offset: after the first round the parameters move little). Why a
// search and not Gauss-Newton: the cost is piecewise smooth with kinks at sample crossings
// (fit/track_residual.h), and on circles an offset is seen mostly through the start and stop
// transients, where the cost's curvature in dt is up to 10 times Gauss-Newton's model of it (the
// OptiOdom diff circles): the joint Levenberg-Marquardt solve zigzagged for 46-118 iterations. The
// scan also keeps a weakly determined offset from a local minimum. The group's runs are replayed
// once per call (the odometry does not depend on dt); an evaluation only interpolates the ground
// truth.
constexpr double kOffsetScanStepS = 0.025;
constexpr double kOffsetSearchToleranceS = 1e-5;
constexpr int kLocalScanSteps = 3;

void SolveClockOffsetsAt(const RobotModelInterface& model, const ModelFitOptions& options,
                         const std::vector<double>& p, std::vector<double>* offsets_s,
                         ModelFitResult* result, bool scan = true,
                         std::vector<OdometryMemo>* memos = nullptr) {
  const TrackFitData& track = *options.track;
  const double bound = kMaxClockOffsetS;
  for (std::size_t g = 0; g < track.clock_groups.size(); ++g) {
    // Each run's odometry from its start, replayed once: it does not depend on dt.
    std::vector<std::pair<std::unique_ptr<TrackResidual>, std::vector<double>>> runs;
    for (std::size_t i = 0; i < track.runs.size(); ++i) {
      const TrackCheckpoints& run = track.runs[i];
      if (run.clock_group != static_cast<int>(g) || run.segments.empty()) continue;
      std::unique_ptr<TrackResidual> cost(static_cast<TrackResidual*>(
          TrackResidual::Create(run, model, TrackWeightsOf(options, i), track.options,
                                memos != nullptr ? &(*memos)[i] : nullptr)));
      std::vector<double> poses = cost->OdometryFromStart(p.data());
      runs.emplace_back(std::move(cost), std::move(poses));
    }
    if (runs.empty()) continue;
    const auto cost_at = [&](double dt) {
      ++result->clock_offset_iterations;
      double sum = 0.0;
      for (const auto& [cost, poses] : runs) sum += cost->SquaredNormAt(poses, dt);
      return sum;
    };
    // The whole interval, or kLocalScanSteps either side of the current offset.
    const int steps =
        scan ? static_cast<int>(std::ceil(bound / kOffsetScanStepS)) : kLocalScanSteps;
    const double centre = scan ? 0.0 : (*offsets_s)[g];
    double best = centre, best_cost = HUGE_VAL;
    for (int i = -steps; i <= steps; ++i) {
      const double dt = std::clamp(centre + i * kOffsetScanStepS, -bound, bound);
      const double c = cost_at(dt);
      if (c < best_cost) {
        best = dt;
        best_cost = c;
      }
    }
    // Golden section on [best - step, best + step] within the bounds.
    double lo = std::max(-bound, best - kOffsetScanStepS);
    double hi = std::min(bound, best + kOffsetScanStepS);
    const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
    double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
    double c1 = cost_at(x1), c2 = cost_at(x2);
    while (hi - lo > kOffsetSearchToleranceS) {
      if (c1 < c2) {
        hi = x2;
        x2 = x1;
        c2 = c1;
        x1 = hi - ratio * (hi - lo);
        c1 = cost_at(x1);
      } else {
        lo = x1;
        x1 = x2;
        c1 = c2;
        x2 = lo + ratio * (hi - lo);
        c2 = cost_at(x2);
      }
    }
    const double found = 0.5 * (lo + hi);
    (*offsets_s)[g] = cost_at(found) <= best_cost ? found : best;
  }
}

// The largest change of any offset between `before` and `after`.
double LargestChange(const std::vector<double>& before, const std::vector<double>& after) {
  double moved = 0.0;
  for (std::size_t g = 0; g < before.size(); ++g)
    moved = std::max(moved, std::abs(after[g] - before[g]));
  return moved;
}

// Clock offsets are estimated by turns (block coordinate descent): the offsets with the
// parameters held (SolveClockOffsetsAt: a search on the exact cost), then the parameters with
// the offsets held, until the offsets move by less than kClockOffsetToleranceS. A joint
// Levenberg-Marquardt solve took 46-118 iterations on the OptiOdom diff circles + squares
// (1.2-2.9 s on one thread, against 5 iterations and 0.13 s without offsets; reasons above); an
// offset's search replays only its group's runs, without derivatives, and the parameters'
// problem with the offsets held converges as fast as without offsets. At the end the offsets are
// the minimum for the parameters and the parameters for the offsets (the covariance is then the
// joint one, ComputeCovariance, with the interpolant's piecewise derivative in dt).
constexpr int kMaxClockOffsetRounds = 12;
constexpr double kClockOffsetToleranceS = 1e-4;  // 0.1 ms: 20 um at 0.2 m/s, << every sigma
// The parameters' steps between offset solves: one. The offsets then follow every parameter step
// (closer to a joint step, without its zigzag): on the OptiOdom diff loops with `--clock-offsets
// session` the written fit took 12 iterations against 17 with two, the whole 97-run command ~10 %
// less CPU; four took 22 (docs/clock_offsets.md).
constexpr int kParameterStepsPerRound = 1;

// Turns of offsets and a few parameter steps, from result's parameters, until the offsets settle.
void AlternateWithClockOffsets(const std::vector<AlignedRun>& training,
                               const RobotModelInterface& model, const ModelFitOptions& options,
                               const ModelFitOptions& offsets_held, const HeldDirections& holds,
                               ModelFitResult* result, std::vector<OdometryMemo>* memos) {
  ModelFitOptions few_steps = offsets_held;
  few_steps.ceres.max_num_iterations = kParameterStepsPerRound;
  for (int round = 0; round < kMaxClockOffsetRounds; ++round) {
    const std::vector<double> before = result->clock_offsets_s;
    SolveClockOffsetsAt(model, options, result->parameters, &result->clock_offsets_s, result,
                        /*scan=*/round == 0, memos);
    if (round > 0 && LargestChange(before, result->clock_offsets_s) < kClockOffsetToleranceS) {
      return;
    }
    FitProblem fit(training, model, few_steps, result->held, result->parameters.data(),
                   result->clock_offsets_s.data(), holds, memos);
    ceres::Solver::Summary summary;
    ceres::Solve(SolverOptionsFor(few_steps.ceres), &fit.problem(), &summary);
    result->iterations += static_cast<int>(summary.iterations.size());
    result->evaluations += summary.num_residual_evaluations + summary.num_jacobian_evaluations;
  }
}

// The clock offsets a problem points into: one per clock group, and one slot even without tracks
// (the problem takes a pointer it never uses then).
std::size_t ClockOffsetSlots(const ModelFitOptions& options) {
  return UsesTracks(options) ? std::max<std::size_t>(1, options.track->clock_groups.size()) : 1;
}

// One bounded solve from `start` with `holds`, refined by the active set when it did not converge.
ModelFitResult SolveFrom(const std::vector<AlignedRun>& training, const RobotModelInterface& model,
                         const std::vector<double>& start, const ModelFitOptions& options,
                         const HeldDirections& holds) {
  const Robot& robot = model.robot();
  ModelFitResult result;
  result.parameters = start;
  result.held = HoldAtNominal(robot, result.parameters.data());
  result.clock_offsets_s.assign(ClockOffsetSlots(options), 0.0);
  const auto t0 = std::chrono::steady_clock::now();
  // With estimated offsets, the parameters' solves below hold them (AlternateWithClockOffsets).
  const bool offsets = UsesTracks(options) && options.track->estimate_clock_offsets;
  TrackFitData track_offsets_held;
  ModelFitOptions solve_options = options;
  // The runs' odometry at the last parameters, kept across this fit's problems (OdometryMemo).
  std::vector<OdometryMemo> memos(UsesTracks(options) ? options.track->runs.size() : 0);
  if (offsets) {
    track_offsets_held = *options.track;
    track_offsets_held.estimate_clock_offsets = false;
    solve_options.track = &track_offsets_held;
    AlternateWithClockOffsets(training, model, options, solve_options, holds, &result, &memos);
  }
  ceres::Solver::Summary summary;
  for (int round = 0; round < kMaxClockOffsetRounds; ++round) {
    {
      FitProblem fit(training, model, solve_options, result.held, result.parameters.data(),
                     result.clock_offsets_s.data(), holds, &memos);
      SolveUntilBoundContact(robot, solve_options, result.held, result.parameters.data(),
                             &fit.problem(), &summary);
    }
    Accumulate(summary, &result);
    const bool converged = summary.termination_type == ceres::CONVERGENCE;
    if (!converged && options.active_set_bounds) {
      summary =
          RefineWithActiveSet(training, model, solve_options, holds, summary, &result, &memos);
    }
    if (!offsets) break;
    // The offsets for the parameters found; done when they stay (the joint minimum).
    const std::vector<double> before = result.clock_offsets_s;
    SolveClockOffsetsAt(model, options, result.parameters, &result.clock_offsets_s, &result,
                        /*scan=*/false, &memos);
    result.clock_offsets_settled =
        LargestChange(before, result.clock_offsets_s) < kClockOffsetToleranceS;
    if (result.clock_offsets_settled) break;
  }
  result.solve_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bool finite = true;
  for (double v : result.parameters) finite = finite && std::isfinite(v);
  result.at_bound = ParametersAtBound(robot, result.parameters);
  const bool settled = !offsets || result.clock_offsets_settled;
  result.usable = finite && summary.termination_type == ceres::CONVERGENCE && settled;
  result.stopped_early =
      finite && (summary.termination_type == ceres::NO_CONVERGENCE || !settled);
  return result;
}

// The hold's weight: kHoldStiffness times the stiffest direction the data determine, in the
// same residual units, so a held direction moves by a part in kHoldStiffness^2 of what the data
// would move it.
double HoldWeight(const DirectionAnalysis& analysis) {
  constexpr double kHoldStiffness = 1e4;
  const double smallest_fraction = analysis.posterior_fractions.empty()
                                       ? 1.0
                                       : *std::min_element(analysis.posterior_fractions.begin(),
                                                           analysis.posterior_fractions.end());
  const double w = kHoldStiffness * analysis.residual_sigma / std::max(smallest_fraction, 1e-12);
  return w > 0.0 && std::isfinite(w) ? w : 1.0;
}

// ModelFitOptions::held_fit_from_projection: `p` with its components along the held directions
// set to the nominal's, where HoldDirectionsCost is zero. The directions are orthonormal in the
// prior's units (fit/determined_directions.h), so q - sum_j u_j (u_j . q) with
// q = (p - nominal) / prior sigma; clamped to the box, which the projection may leave.
std::vector<double> ProjectOntoHold(const Robot& robot,
                                    const std::vector<UndeterminedDirection>& held,
                                    const std::vector<double>& p) {
  const Eigen::VectorXd prior_sigma = PriorSigma(robot);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(robot.NumParameters());
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (prior_sigma[k] > 0.0) q[k] = (p[k] - robot.nominal[k]) / prior_sigma[k];
  }
  for (const UndeterminedDirection& d : held) q -= d.prior_units * d.prior_units.dot(q);
  std::vector<double> out = p;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (prior_sigma[k] > 0.0) {
      out[k] = std::clamp(robot.nominal[k] + q[k] * prior_sigma[k], robot.bounds[k].lo,
                          robot.bounds[k].hi);
    }
  }
  return out;
}

// The fit from `start` with the directions the runs do not determine held
// (ModelFitOptions::hold_undetermined; *holds says which), without its covariance.
ModelFitResult SolveHoldingUndetermined(const std::vector<AlignedRun>& training,
                                        const RobotModelInterface& model,
                                        const std::vector<double>& start,
                                        const ModelFitOptions& options, HeldDirections* holds) {
  // What the direction analysis sees: with tracks, their checkpoints at the start's clock offsets
  // (the last checkpoint is the final pose relative to the start, so "both" adds nothing to it).
  std::vector<std::vector<Segment>> checkpoints;
  if (UsesTracks(options)) {
    for (const TrackCheckpoints& t : options.track->runs) checkpoints.push_back(t.segments);
  }
  const std::vector<std::vector<Segment>>* analysed =
      UsesTracks(options) ? &checkpoints : options.segments;

  ModelFitResult result = SolveFrom(training, model, start, options, {});
  if (options.hold_undetermined) {
    bool finite = true;
    for (double v : result.parameters) finite = finite && std::isfinite(v);
    const DirectionAnalysis analysis =
        AnalyseDeterminedDirections(training, model, finite ? result.parameters : start,
                                    WeightsOfRuns(options, training.size()), analysed,
                                    options.ceres.num_threads);
    if (analysis.ok && !analysis.undetermined.empty()) {
      holds->directions = analysis.undetermined;
      holds->weight = HoldWeight(analysis);
      const bool project = options.held_fit_from_projection && result.usable;
      ModelFitResult held = SolveFrom(
          training, model,
          project ? ProjectOntoHold(model.robot(), holds->directions, result.parameters) : start,
          options, *holds);
      held.held_directions = analysis.undetermined;
      held.unconstrained_parameters = result.parameters;
      held.unconstrained_usable = result.usable;
      held.iterations += result.iterations;
      held.evaluations += result.evaluations;
      held.solve_time_s += result.solve_time_s;
      result = std::move(held);
    }
  }
  return result;
}

// ModelFitOptions::estimate_weights (fit/noise_levels.h): fit, estimate the noise levels at the
// solution, reweight, refit from there, until two estimates agree. The fit returned is the last
// one, made with weights that agree with the estimate at its solution; its covariance is the only
// one computed (the rounds before are discarded).
ModelFitResult FitWithNoiseLevels(const std::vector<AlignedRun>& training,
                                  const RobotModelInterface& model,
                                  const std::vector<double>& start,
                                  const ModelFitOptions& options) {
  ModelFitOptions weighted = options;
  weighted.estimate_weights = false;
  std::vector<double> from = start;
  NoiseLevels levels;
  ModelFitResult fit;
  ModelFitOptions fitted_with;  // the returned fit's options and holds
  HeldDirections holds;
  int iterations = 0;  // summed over the rounds, as the evaluations and the solve time
  int evaluations = 0;
  double solve_time_s = 0.0;
  for (int round = 1; round <= kMaxNoiseLevelIterations; ++round) {
    holds = {};
    fit = SolveHoldingUndetermined(training, model, from, weighted, &holds);
    fitted_with = weighted;
    iterations += fit.iterations;
    evaluations += fit.evaluations;
    solve_time_s += fit.solve_time_s;
    if (!fit.HasFinitePoint()) break;
    const int held = static_cast<int>(std::count(fit.held.begin(), fit.held.end(), true));
    const int offsets = options.track->estimate_clock_offsets
                            ? static_cast<int>(options.track->clock_groups.size())
                            : 0;
    const int estimated = model.robot().NumParameters() - held -
                          static_cast<int>(fit.held_directions.size()) + offsets;
    NoiseLevels next = EstimateNoiseLevels(training, model, fit.parameters, fit.clock_offsets_s,
                                           *options.track, options.residuals == ResidualKind::kBoth,
                                           estimated, options.noise_levels_per_session);
    if (!next.estimated) break;
    next.iterations = round;
    next.settled = NoiseLevelsAgree(levels, next);
    levels = next;
    if (levels.settled) break;
    const FitWeights w = WeightsFromNoiseLevels(levels);
    weighted.track_weights = w.track;
    if (levels.with_final_poses) weighted.ceres.weights = w.final_pose;
    weighted.weights_per_run = WeightsPerRun(levels);
    from = fit.parameters;
  }
  if (options.ceres.compute_covariance) {
    ComputeCovariance(training, model, fitted_with, holds, &fit);
  }
  fit.noise_levels = levels;
  fit.iterations = iterations;
  fit.evaluations = evaluations;
  fit.solve_time_s = solve_time_s;
  return fit;
}

}  // namespace

ModelFitResult FitModelFrom(const std::vector<AlignedRun>& training,
                            const RobotModelInterface& model, const std::vector<double>& start,
                            const ModelFitOptions& options) {
  std::string error;
  if (!options.ceres.IsValid(&error)) throw std::invalid_argument("CeresFitOptions: " + error);
  if (training.empty()) throw std::invalid_argument("FitModel: no training runs");
  if (options.segments != nullptr && options.segments->size() != training.size()) {
    throw std::invalid_argument("FitModel: not one window list per training run");
  }
  const int n = model.robot().NumParameters();
  if (static_cast<int>(start.size()) != n) throw std::invalid_argument("FitModel: bad start");
  if (options.tying != nullptr && !options.tying->empty()) {
    const TiedModel tied(model, *options.tying);
    ModelFitOptions untied = options;
    untied.tying = nullptr;
    return ExpandTiedResult(tied, FitModelFrom(training, tied, tied.Reduce(start), untied));
  }
  if (UsesTracks(options)) {
    if (options.track == nullptr || options.track->runs.size() != training.size()) {
      throw std::invalid_argument("FitModel: track residuals need one track per training run");
    }
    if (!options.track->options.IsValid(&error)) throw std::invalid_argument(error);
    for (const TrackCheckpoints& t : options.track->runs) {
      if (t.clock_group < 0 ||
          t.clock_group >= static_cast<int>(options.track->clock_groups.size()))
        throw std::invalid_argument("FitModel: a track's clock group is out of range");
    }
  }
  if (options.estimate_weights && UsesTracks(options)) {
    return FitWithNoiseLevels(training, model, start, options);
  }
  HeldDirections holds;
  ModelFitResult result = SolveHoldingUndetermined(training, model, start, options, &holds);
  if (options.ceres.compute_covariance) ComputeCovariance(training, model, options, holds, &result);
  return result;
}

std::vector<bool> NotDeterminedParameters(const ModelFitResult& fit) {
  const Eigen::Index n = static_cast<Eigen::Index>(fit.parameters.size());
  std::vector<bool> out(fit.parameters.size(), false);
  const Eigen::MatrixXd& held = fit.held_directions_covariance;
  if (!fit.has_covariance || held.rows() != n || fit.covariance.rows() != n) return out;
  for (Eigen::Index k = 0; k < n; ++k) out[k] = held(k, k) > 0.5 * fit.covariance(k, k);
  return out;
}

ModelFitResult ExpandTiedResult(const TiedModel& tied, const ModelFitResult& fit) {
  const int n = tied.inner().robot().NumParameters();
  const auto per_member = [&](const auto& of_q) {
    std::remove_const_t<std::remove_reference_t<decltype(of_q)>> out(n);
    for (int k = 0; k < n; ++k) out[k] = of_q[tied.GroupOf(k)];
    return out;
  };
  ModelFitResult out = fit;
  out.parameters = tied.Expand(fit.parameters.data());
  out.at_bound = per_member(fit.at_bound);
  out.held = per_member(fit.held);
  if (!fit.unconstrained_parameters.empty())
    out.unconstrained_parameters = tied.Expand(fit.unconstrained_parameters.data());
  for (UndeterminedDirection& d : out.held_directions) {
    d.prior_units = per_member(d.prior_units);
    d.one_sigma_step = per_member(d.one_sigma_step);
  }
  if (fit.sigma.size() == fit.parameters.size()) out.sigma = per_member(fit.sigma);
  if (fit.has_covariance) {
    const Eigen::MatrixXd a = tied.Basis();
    out.covariance = a * fit.covariance * a.transpose();
    if (fit.held_directions_covariance.size() > 0)
      out.held_directions_covariance = a * fit.held_directions_covariance * a.transpose();
    out.correlation = CorrelationOf(out.covariance);
  }
  return out;
}

std::vector<double> EstimateClockOffsets(const RobotModelInterface& model,
                                         const std::vector<double>& p,
                                         const ModelFitOptions& options) {
  if (options.track == nullptr) throw std::invalid_argument("EstimateClockOffsets: no tracks");
  std::vector<double> offsets_s(options.track->clock_groups.size(), 0.0);
  ModelFitResult counts;
  SolveClockOffsetsAt(model, options, p, &offsets_s, &counts);
  return offsets_s;
}

namespace {

// Held by the model (gauge) or by --hold (the tying's held names).
bool HeldInFit(const Robot& robot, int k, const ModelFitOptions& options) {
  if (robot.IsHeld(k)) return true;
  if (options.tying == nullptr) return false;
  const std::vector<std::string>& held = options.tying->held;
  return std::find(held.begin(), held.end(), robot.parameters[k].name) != held.end();
}

// The free parameters a fit left on a bound.
std::vector<std::string> FreeParametersOnABound(const Robot& robot, const ModelFitResult& fit,
                                                const ModelFitOptions& options) {
  std::vector<std::string> out;
  for (int k = 0; k < robot.NumParameters() && k < static_cast<int>(fit.at_bound.size()); ++k) {
    if (!HeldInFit(robot, k, options) && fit.at_bound[k]) out.push_back(robot.parameters[k].name);
  }
  return out;
}

// A free parameter whose sigma, from the fit's own covariance (scaled by the residuals it left),
// exceeds its box's: the largest such ratio and the parameter (-1 when none does or there is no
// covariance). The box is read as fit/determined_directions.h reads it, a uniform prior of
// standard deviation width / sqrt(12).
struct WiderThanItsBox {
  int parameter = -1;
  double ratio = 0.0;  // sigma / (width / sqrt(12))
};
WiderThanItsBox SigmaWiderThanItsBox(const Robot& robot, const ModelFitResult& fit,
                                     const ModelFitOptions& options) {
  WiderThanItsBox out;
  if (!fit.has_covariance || fit.sigma.size() != fit.parameters.size()) return out;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const double box_sigma = robot.bounds[k].Width() / std::sqrt(12.0);
    if (HeldInFit(robot, k, options) || !(box_sigma > 0.0)) continue;
    // The runs' own sigma: a held direction's part is the box's by construction.
    const double held_part = fit.held_directions_covariance.size() > 0
                                 ? fit.held_directions_covariance(k, k)
                                 : 0.0;
    const double own = std::sqrt(std::max(0.0, fit.sigma[k] * fit.sigma[k] - held_part));
    const double ratio = own / box_sigma;
    if (ratio > kGlobalStartSigmaRatio && ratio > out.ratio) out = {k, ratio};
  }
  return out;
}

// Why the fit from the guess should be tried again from across the box, in words ("" when it
// should not): a free parameter on a bound (a guess several times off pulls the others there), a
// rank-deficient covariance, a fit of tracks that held a direction as undetermined, or
// residuals so far above the noise that the fit's own sigma of a free parameter is wider than its
// box - a fit that explained the runs would pin every parameter well inside the box (measured:
// a diff drive guessed with its separation 20 % off stops with sigmas 2.7-3.9x the box's and
// 59 deg of final heading error; the clean and the real fits of this project stay below 0.25x).
std::string ReasonToStartAcrossTheBox(const Robot& robot, const ModelFitResult& fit,
                                      const ModelFitOptions& options) {
  const std::vector<std::string> on_bound = FreeParametersOnABound(robot, fit, options);
  if (!on_bound.empty()) return "ended on a bound (" + io::Joined(on_bound, ", ") + ")";
  // No covariance although the runs are enough for one: the fit stopped where the runs, at its
  // residual level, leave a direction flat (measured: the diff drive 20 % off fitted on final poses
  // stopped at a separation of 0.166 for 0.24 with a rank-deficient covariance, docs/fit.md).
  if (fit.usable && options.ceres.compute_covariance && fit.covariance_message == kRankDeficient) {
    return "left a direction the runs do not determine (" + fit.covariance_message + ")";
  }
  // A fit of tracks that held a direction as undetermined: a local minimum can look flat where
  // the runs' tracks determine everything (a randomized sweep, stop 65: a diff drive guessed
  // 9-18 % off on two squares held the common scale of wheels and track and one more direction,
  // training CF 1.95 against 0.033 at the truth, and was written; its held part is left out of
  // the sigmas' test below, so that showed nothing).
  if (UsesTracks(options) && !fit.held_directions.empty()) {
    return "held a direction its tracks leave undetermined";
  }
  const WiderThanItsBox wide = SigmaWiderThanItsBox(robot, fit, options);
  if (wide.parameter < 0) return "";
  return StrFormat("left residuals far above the noise (%s's sigma %.3gx its box's)",
                   robot.parameters[wide.parameter].name.c_str(), wide.ratio);
}

// A point `fraction` of the way across a parameter's box. A ratio's box is a factor either way of
// its nominal (a steering gain's default [g / 10, 10 g]), so its fractions are taken on the log
// scale: the centre is the nominal, a quarter g / 3.2. On the linear scale every start of such a
// box lay at 2.5 g or more, and a gain 2.5x below its guess was never reached (a tricycle of gain
// 0.4 guessed 1: fit refused with the radius and the wheelbase on their bounds).
double AcrossTheBox(const ParameterInfo& info, const Interval& box, double fraction) {
  if (info.unit == ParameterUnit::kRatio && box.lo > 0.0) {
    return box.lo * std::pow(box.hi / box.lo, fraction);
  }
  return box.lo + fraction * box.Width();
}

// A start from the windows' fit (FitOfDisjointWindows) only for a fit of tracks, which see all the
// windows see: a final-pose fit holds what its runs leave undetermined at its start, and from the
// windows' fit that would be a value its own residuals never measured
// (GeneralisationOptiOdom.CheckpointsSeeWhatAClosedPathHidesFromItsFinalPose, generalisation_test).
std::optional<std::vector<double>> WindowsStart(const std::vector<AlignedRun>& training,
                                                const RobotModelInterface& model,
                                                const ModelFitOptions& options) {
  if (!UsesTracks(options)) return std::nullopt;
  return FitOfDisjointWindows(training, model, options);
}

// A point `fraction` of the way across every free parameter's box (AcrossTheBox).
std::vector<double> StartAcrossTheBox(const Robot& robot, const ModelFitOptions& options,
                                      double fraction) {
  std::vector<double> start = robot.nominal;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (!HeldInFit(robot, k, options)) {
      start[k] = AcrossTheBox(robot.parameters[k], robot.bounds[k], fraction);
    }
  }
  return start;
}

// A fit of tracks, on no bound, with a flat direction (held, or a rank-deficient covariance): the
// runs may truly leave that direction open, and then every start ends flat again. Such a fit
// tries the windows' fit first (WithGlobalStart): short windows reach the truth from guesses a
// whole run's fit does not (the tricycle below), so a fit from there that ends at the guess's
// cost says the guess's minimum is the runs' own, and the search ends. A start across the box
// that meets the guess's cost says less: letting it end the search failed three far-guess tests
// (FarFromTheGuessOnTracks, RecordedRobot, ResidualKindChoice), where the 50 % start fell into
// the guess's local minimum and a later start found the truth.
// Without this a robot whose runs leave directions open tried every start (a simulated ASOC robot
// with a mounted pose source, `fit --residuals track`: the probe with the mount freed,
// calibrate/calibrate.cc, held two directions with a rank-deficient covariance at cost
// 1.1193241e-06; the 25 % and 75 % starts ended on bounds at 0.0095 and 3.2 after 300-500
// iterations each, the windows' fit at 1.11932431e-06; 88-137 s of wall time).
bool FlatAtTheGuessesFit(const ModelFitResult& fit, const ModelFitOptions& options) {
  if (!UsesTracks(options) || !fit.usable) return false;
  if (std::find(fit.at_bound.begin(), fit.at_bound.end(), true) != fit.at_bound.end()) {
    return false;
  }
  return !fit.held_directions.empty() || fit.covariance_message == kRankDeficient;
}

// Whether a start's fit ended at the guess's fit's cost, to a part in 10^6 (the same minimum
// reached twice: the ASOC case above differs by 2e-7 of itself; a local minimum's cost is
// orders of magnitude above the truth's).
bool EndsWhereTheGuessEnded(double cost, double guess_cost) {
  constexpr double kSameMinimum = 1e-6;
  return std::isfinite(guess_cost) && std::abs(cost - guess_cost) <= kSameMinimum * guess_cost;
}

constexpr const char* kWindowsStart = "the windows' fit";

// ModelFitOptions::global_start: the starts spread across the box, then (a fit of tracks) the fit
// of 0.5 m windows, the lowest cost kept; the first start whose fit leaves no reason to go
// on ends the search. The windows come last, but where the guess's fit is flat
// (FlatAtTheGuessesFit): where a start across the box suffices, nothing changes (measured: a
// tricycle guessed with twice its steering gain on two 40 m free runs with a mounted pose source
// ended with its radius on a bound from the guess and from every start across the box; from the
// windows' fit, at the truth).
ModelFitResult WithGlobalStart(const std::vector<AlignedRun>& training,
                               const RobotModelInterface& model, const ModelFitOptions& options,
                               ModelFitResult local) {
  const Robot& robot = model.robot();
  const std::string reason = ReasonToStartAcrossTheBox(robot, local, options);
  if (reason.empty()) return local;
  const double local_cost = local.usable ? local.final_cost : HUGE_VAL;
  const bool windows_first = FlatAtTheGuessesFit(local, options);
  ModelFitResult best = std::move(local);
  double best_cost = local_cost;
  std::string best_start, fractions, met_again;
  bool windows_tried = false;
  const auto try_start = [&](const std::string& name, const std::vector<double>& start) {
    ModelFitResult fit = FitModelFrom(training, model, start, options);
    if (windows_first && name == kWindowsStart && fit.usable &&
        EndsWhereTheGuessEnded(fit.final_cost, local_cost)) {
      met_again = name;
      return true;
    }
    if (!fit.usable || !(fit.final_cost < best_cost)) return false;
    best_cost = fit.final_cost;
    best_start = name;
    best = std::move(fit);
    return ReasonToStartAcrossTheBox(robot, best, options).empty();
  };
  const auto try_windows = [&] {
    const std::optional<std::vector<double>> start = WindowsStart(training, model, options);
    windows_tried = start.has_value();
    return start && try_start(kWindowsStart, *start);
  };
  bool done = windows_first && try_windows();
  for (double fraction : {0.5, 0.25, 0.75}) {
    if (done) break;
    const std::string name = std::to_string(static_cast<int>(100.0 * fraction)) + " %";
    fractions += (fractions.empty() ? "" : ", ") + name;
    done = try_start(name, StartAcrossTheBox(robot, options, fraction));
  }
  if (!done && !windows_first) try_windows();
  const std::string across = fractions.empty() ? "" : fractions + " of the way across the box";
  const std::string windows = windows_tried ? "the fit of 0.5 m windows" : "";
  const std::string tried =
      windows_first ? windows + (windows_tried && !across.empty() ? ", then " : "") + across +
                          (met_again.empty() ? "" : " (it ended where the guess's did)")
                    : across + (windows_tried ? " and from " + windows : "");
  best.global_start =
      best_start.empty()
          ? StrFormat("the fit from the guess %s; fits from %s found no lower cost: kept",
                      reason.c_str(), tried.c_str())
          : StrFormat("the fit from the guess %s, %s; fits from %s: the one from %s found "
                      "cost %.6g, kept",
                      reason.c_str(),
                      std::isfinite(local_cost) ? StrFormat("cost %.6g", local_cost).c_str()
                                                : "no usable cost",
                      tried.c_str(), best_start.c_str(), best_cost);
  return best;
}

}  // namespace

ModelFitResult FitModel(const std::vector<AlignedRun>& training, const RobotModelInterface& model,
                        const ModelFitOptions& options) {
  ModelFitResult local = FitModelFrom(training, model, model.robot().nominal, options);
  if (!options.global_start) return local;
  return WithGlobalStart(training, model, options, std::move(local));
}

std::vector<double> FitCostGradient(const std::vector<AlignedRun>& training,
                                    const RobotModelInterface& model, std::vector<double> p,
                                    const ModelFitOptions& options) {
  std::vector<double> offsets(ClockOffsetSlots(options), 0.0);
  return GradientInEveryParameter(training, model, options, p.data(), offsets.data(), {},
                                  nullptr);
}

// A window's error does not accumulate along a run, so a guess far off meets none of the minima a
// whole run's final pose or track has (diagnosis/channel_order_check.h measured a tricycle's 2.5x
// gain: final poses fitted from the guess SSR 177, from the windows' fit 0.0056).
std::optional<std::vector<double>> FitOfDisjointWindows(const std::vector<AlignedRun>& training,
                                                        const RobotModelInterface& model,
                                                        const ModelFitOptions& options) {
  for (const AlignedRun& run : training) {
    if (run.track == nullptr) return std::nullopt;
  }
  std::size_t total = 0;
  const std::vector<std::vector<Segment>> segments =
      MakeDisjointWindows(training, TracksOf(training), &total);
  if (total < 4) return std::nullopt;
  ModelFitOptions on_windows = options;
  on_windows.segments = &segments;
  on_windows.global_start = false;
  const ModelFitResult fit = FitModelFrom(training, model, model.robot().nominal, on_windows);
  if (!fit.HasFinitePoint()) return std::nullopt;
  return fit.parameters;
}

}  // namespace fitcal
