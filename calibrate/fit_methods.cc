#include "calibrate/fit_methods.h"

#include <Eigen/Dense>
#include <ceres/cost_function.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <tuple>

#include "fit/final_pose_errors.h"
#include "fit/model_nlopt_fit.h"
#include "fit/residual_choice.h"
#include "io/text_file.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

std::string ObjectiveText(FinalPoseObjective objective, CeresRobustLoss loss, double scale) {
  std::string text = objective == FinalPoseObjective::kSumOfNorms
                         ? "Eq. 14: sum of per-run final-pose error norms"
                         : "sum of squared final-pose residuals";
  if (loss != CeresRobustLoss::kNone) {
    text += std::string(", ") + ToString(loss) + " loss (scale " + std::to_string(scale) + ")";
  }
  return text;
}

CeresFitOptions CeresOptionsFor(CeresTrustRegion trust_region, const FitMethodSettings& settings) {
  CeresFitOptions options;
  options.num_threads = settings.threads;
  options.max_num_iterations = settings.max_iterations;
  options.weights = settings.weights;
  options.trust_region = trust_region;
  if (settings.objective_set) options.objective = settings.objective;
  options.loss = settings.loss;
  options.loss_scale = settings.loss_scale;
  return options;
}

// The NLopt options of a method for these settings.
NloptFitOptions NloptOptionsFor(NloptMethod method, const FitMethodSettings& settings) {
  NloptFitOptions options;
  options.method = method;
  options.num_threads = settings.threads;
  options.weights = settings.weights;
  if (settings.objective_set) options.objective = settings.objective;
  options.seed = settings.seed;
  options.max_evaluations = settings.max_evaluations;
  options.local_polish = settings.local_polish;
  options.progress = settings.progress;
  if (options.local_polish) {
    options.local_polish_evaluations = std::min(2000, std::max(1, options.max_evaluations / 5));
  }
  return options;
}

// What the residuals compare, in words, before the final poses' objective ("" for final poses
// alone, whose text is unchanged).
std::string ResidualsText(const FitMethodSettings& settings) {
  if (settings.residuals == ResidualKind::kFinalPose || settings.track == nullptr) return "";
  const TrackResidualOptions& t = settings.track->options;
  return StrFormat(
      "track residuals (pose from the run's start every %.2g m of ground-truth path and at the "
      "end, heading %s, Huber %.2g, runs weighed alike; clock offsets: %s)%s",
      t.checkpoint_spacing_m, ToString(t.heading), t.huber_scale,
      settings.clock_grouping == ClockGrouping::kNone
          ? "none"
          : (std::string("one per ") + ToString(settings.clock_grouping)).c_str(),
      settings.residuals == ResidualKind::kBoth ? " and final poses: " : "");
}

ModelFitMethodOutcome RunModelCeres(CeresTrustRegion trust_region,
                                    const std::vector<AlignedRun>& training,
                                    const RobotModelInterface& model,
                                    const FitMethodSettings& settings) {
  ModelFitOptions options;
  options.ceres = CeresOptionsFor(trust_region, settings);
  options.residuals = settings.residuals;
  options.track = settings.track;
  options.estimate_weights = settings.estimate_weights;
  options.track_weights = settings.track_weights;
  options.tying = &settings.tying;
  options.ceres.compute_covariance = !settings.judgement_fit;
  options.held_fit_from_projection = settings.judgement_fit;
  ModelFitMethodOutcome out;
  // From the guess (the nominal), with FitModel's global start; a fit warm-started from a fitted
  // point (a fold's, from the fit of all the training runs) starts from no guess and keeps it.
  out.fit = settings.start.empty() ? FitModel(training, model, options)
                                   : FitModelFrom(training, model, settings.start, options);
  out.evaluations = out.fit.evaluations;
  out.objective = ResidualsText(settings);
  if (options.residuals != ResidualKind::kTrack) {
    out.objective +=
        ObjectiveText(options.ceres.objective, options.ceres.loss, options.ceres.loss_scale);
  }
  if (settings.judgement_fit) return out;
  // Ceres reports no per-evaluation CF: the trace holds the start and the end.
  out.trace.push_back(
      {1, EvaluateFinalPoseErrors(model, model.robot().nominal, training, settings.threads).cf,
       0.0});
  out.trace.push_back(
      {out.evaluations,
       EvaluateFinalPoseErrors(model, out.fit.parameters, training, settings.threads).cf,
       out.fit.solve_time_s});
  return out;
}

// Whether a global search's end point is a minimum of its objective, by the decrease of the
// objective's quadratic model one Gauss-Newton step away, over the parameters free and off their
// bounds: sum_i w_i |r_i + J_i d|^2 / 2 with r_i, J_i run i's weighted final-pose residual and
// Jacobian and w_i = 1 (sum of squares) or 1 / |r_i| (Eq. 14's sum of norms, whose majoriser it is:
// |a| <= (|a|^2 / |r| + |r|) / 2). At a minimum the gradient, and so the decrease, is 0.
// DIRECT-L on the OptiOdom tricycle stopped on its function tolerance at a point of its box's grid,
// held-out CF 0.69 against 0.09 for Ceres and CRS2-LM, and was written with exit 0 (stop 72's
// D-F11). "" at a minimum, else why not.
std::string NotAtAMinimum(const std::vector<AlignedRun>& training,
                          const RobotModelInterface& model, const NloptFitOptions& options,
                          const ModelFitResult& fit) {
  constexpr double kMinimumLeft = 0.1;  // a tenth of the objective: a search short of its end
  const int n = model.robot().NumParameters();
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  double objective = 0.0;
  for (const AlignedRun& run : training) {
    std::unique_ptr<ceres::CostFunction> cost(model.FinalPoseCost(run, options.weights));
    Eigen::Vector3d r;
    Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> j(3, n);
    const double* parameters[] = {fit.parameters.data()};
    double* jacobians[] = {j.data()};
    if (cost->num_residuals() != 3 || !cost->Evaluate(parameters, r.data(), jacobians)) return "";
    const double w = options.objective == FinalPoseObjective::kSumOfNorms
                         ? 1.0 / std::max(r.norm(), 1e-12)
                         : 1.0;
    h += w * j.transpose() * j;
    g += w * j.transpose() * r;
    objective += 0.5 * w * r.squaredNorm();
  }
  std::vector<int> moving;
  for (int k = 0; k < n; ++k) {
    if (!fit.held[k] && !fit.at_bound[k]) moving.push_back(k);
  }
  if (moving.empty() || !(objective > 0.0)) return "";
  const Eigen::MatrixXd h_moving = h(moving, moving);
  const Eigen::VectorXd g_moving = g(moving);
  const double decrease = 0.5 * g_moving.dot(h_moving.ldlt().solve(g_moving));
  if (!(decrease > kMinimumLeft * objective)) return "";
  return StrFormat("its end point is not a minimum: one Gauss-Newton step from it lowers its "
                   "objective's local model by %.0f %%",
                   100.0 * std::min(decrease / objective, 1.0));
}

ModelFitMethodOutcome RunModelNlopt(NloptMethod method, const std::vector<AlignedRun>& training,
                                    const RobotModelInterface& model,
                                    const FitMethodSettings& settings) {
  if (!settings.tying.empty()) {
    // The NLopt search of the tied model (fit/parameter_tying.h), mapped back to the parameters.
    const TiedModel tied(model, settings.tying);
    FitMethodSettings untied = settings;
    untied.tying = {};
    ModelFitMethodOutcome out = RunModelNlopt(method, training, tied, untied);
    out.fit = ExpandTiedResult(tied, out.fit);
    return out;
  }
  const NloptFitOptions options = NloptOptionsFor(method, settings);
  const NloptSearchResult r = FitModelNlopt(training, model, options);
  const Robot& robot = model.robot();
  ModelFitMethodOutcome out;
  ModelFitResult& fit = out.fit;
  fit.usable = r.usable;
  // A local method out of its evaluation budget stopped short of converging, as Ceres at its
  // iteration limit: flagged when written (exit 6; SBPLX on the example differential drive spent
  // its 20000 and wrote, exit 0). A global method always ends on its budget: its way to stop.
  fit.stopped_early = r.usable && !Info(method).global &&
                      r.termination.find("MAXEVAL_REACHED") != std::string::npos;
  fit.termination = r.termination;
  fit.message = r.message;
  fit.iterations = r.evaluations;
  fit.solve_time_s = r.solve_time_s;
  fit.parameters = r.parameters;
  fit.at_bound = r.at_bound;
  fit.held = robot.HeldFlags();
  fit.sigma.assign(robot.NumParameters(), 0.0);
  fit.covariance_message = "no covariance from NLopt methods (the ceres method computes one)";
  if (r.usable && Info(method).global && !options.local_polish) {
    fit.not_at_a_minimum = NotAtAMinimum(training, model, options, fit);
  }
  out.evaluations = r.evaluations;
  out.objective = ObjectiveText(options.objective, CeresRobustLoss::kNone, 0.0) + ", seed " +
                  std::to_string(options.seed);
  out.trace = r.trace;
  return out;
}

std::vector<FitMethod> MakeMethods() {
  std::vector<FitMethod> methods;
  for (const auto& [name, description, region] :
       {std::tuple{"ceres", "Ceres Levenberg-Marquardt", CeresTrustRegion::kLevenbergMarquardt},
        std::tuple{"ceres-dogleg", "Ceres dogleg", CeresTrustRegion::kDogleg}}) {
    const CeresTrustRegion trust_region = region;
    methods.push_back({name, description,
                       [trust_region](const auto& t, const auto& m, const auto& s) {
                         return RunModelCeres(trust_region, t, m, s);
                       }});
  }
  for (const NloptMethodInfo& info : NloptMethods()) {
    const NloptMethod method = info.method;
    methods.push_back({info.name, info.description,
                       [method](const auto& t, const auto& m, const auto& s) {
                         return RunModelNlopt(method, t, m, s);
                       }});
  }
  return methods;
}

}  // namespace

const std::vector<FitMethod>& FitMethods() {
  static const std::vector<FitMethod> kMethods = MakeMethods();
  return kMethods;
}

const FitMethod* FindFitMethod(const std::string& name) {
  for (const FitMethod& method : FitMethods()) {
    if (method.name == name) return &method;
  }
  return nullptr;
}

std::string FitMethodNames() {
  return io::Joined(FitMethods(), ", ", [](const FitMethod& method) { return method.name; });
}

bool IsCeresMethod(const std::string& name) { return name == "ceres" || name == "ceres-dogleg"; }

void ResolveAutoResiduals(const std::vector<AlignedRun>& training,
                          const std::vector<const GroundTruthTrack*>& tracks,
                          const std::string& method, FitMethodSettings* settings) {
  if (!settings->residuals_auto) return;
  settings->residuals = IsCeresMethod(method) && MeasureTrackDensity(training, tracks).dense
                            ? ResidualKind::kTrack
                            : ResidualKind::kFinalPose;
}

}  // namespace fitcal
