#include "tools/fit_methods.h"

#include "calib/final_pose_cost.h"

namespace fitcal::tools {

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

FitMethodOutcome RunCeres(CeresTrustRegion trust_region, const std::vector<AlignedRun>& training,
                          const Omni3Robot& robot, const FitMethodSettings& settings) {
  CeresFitOptions options;
  options.num_threads = settings.threads;
  options.max_num_iterations = settings.max_iterations;
  options.weights = settings.weights;
  options.trust_region = trust_region;
  if (settings.objective_set) options.objective = settings.objective;
  options.loss = settings.loss;
  options.loss_scale = settings.loss_scale;
  FitMethodOutcome out;
  out.fit = FitOmni3Ceres(training, robot, options);
  out.evaluations = out.fit.num_residual_evaluations + out.fit.num_jacobian_evaluations;
  out.objective = ObjectiveText(options.objective, options.loss, options.loss_scale);
  // Ceres reports no per-evaluation CF: the trace holds the start and the end.
  out.trace.push_back(
      {1, EvaluateFinalPoseErrors(robot.nominal.ToArray(), training, settings.threads).cf, 0.0});
  out.trace.push_back({out.evaluations,
                       EvaluateFinalPoseErrors(out.fit.parameters, training, settings.threads).cf,
                       out.fit.solve_time_s});
  return out;
}

FitMethodOutcome RunNlopt(NloptMethod method, const std::vector<AlignedRun>& training,
                          const Omni3Robot& robot, const FitMethodSettings& settings) {
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
  const NloptFitResult r = FitOmni3Nlopt(training, robot, options);
  FitMethodOutcome out;
  out.fit.usable = r.usable;
  out.fit.termination = r.termination;
  out.fit.message = r.message;
  out.fit.iterations = r.evaluations;
  out.fit.num_residual_evaluations = r.evaluations - r.gradient_evaluations;
  out.fit.num_jacobian_evaluations = r.gradient_evaluations;
  out.fit.solve_time_s = r.solve_time_s;
  out.fit.parameters = r.parameters;
  out.fit.at_bound = r.at_bound;
  out.fit.covariance_message = "no covariance from NLopt methods (the ceres method computes one)";
  out.evaluations = r.evaluations;
  out.objective = ObjectiveText(options.objective, CeresRobustLoss::kNone, 0.0) + ", seed " +
                  std::to_string(options.seed);
  out.trace = r.trace;
  return out;
}

std::vector<FitMethod> MakeMethods() {
  std::vector<FitMethod> methods = {
      {"ceres", "Ceres Levenberg-Marquardt",
       [](const auto& t, const auto& r, const auto& s) {
         return RunCeres(CeresTrustRegion::kLevenbergMarquardt, t, r, s);
       }},
      {"ceres-dogleg", "Ceres dogleg",
       [](const auto& t, const auto& r, const auto& s) {
         return RunCeres(CeresTrustRegion::kDogleg, t, r, s);
       }},
  };
  for (const NloptMethodInfo& info : NloptMethods()) {
    const NloptMethod method = info.method;
    methods.push_back(
        {info.name, info.description, [method](const auto& t, const auto& r, const auto& s) {
           return RunNlopt(method, t, r, s);
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
  std::string out;
  for (const FitMethod& method : FitMethods()) out += (out.empty() ? "" : ", ") + method.name;
  return out;
}

}  // namespace fitcal::tools
