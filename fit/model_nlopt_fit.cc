#include "fit/model_nlopt_fit.h"

#include <ceres/cost_function.h>

#include <memory>
#include <stdexcept>

#include "models/pose_errors.h"

namespace fitcal {

namespace {

// The model's residuals through the seam: value by its double replay, Jacobian by its autodiff
// cost function (one per run, made only for the methods that use the gradient).
class ModelRunResiduals : public RunResiduals {
 public:
  ModelRunResiduals(const std::vector<AlignedRun>& runs, const RobotModelInterface& model,
                    const ResidualWeights& weights, bool needs_gradient)
      : runs_(runs), model_(model), weights_(weights) {
    if (!needs_gradient) return;
    for (const AlignedRun& run : runs_) {
      cost_functions_.emplace_back(model_.FinalPoseCost(run, weights_));
    }
  }

  std::size_t NumRuns() const override { return runs_.size(); }
  void Residual(std::size_t i, const double* p, double* r) const override {
    const Pose2d final_pose = model_.ReplayFinalPose(p, runs_[i].samples, runs_[i].start);
    FinalPoseError(final_pose, runs_[i].final_ground_truth, weights_, r);
  }
  void ResidualAndJacobian(std::size_t i, const double* p, double* r,
                           double* jacobian) const override {
    const double* parameters[] = {p};
    double* jacobians[] = {jacobian};
    if (!cost_functions_.at(i)->Evaluate(parameters, r, jacobians)) {
      throw std::runtime_error("the final-pose cost of run " + runs_[i].id + " failed");
    }
  }

 private:
  const std::vector<AlignedRun>& runs_;
  const RobotModelInterface& model_;
  ResidualWeights weights_;
  std::vector<std::unique_ptr<ceres::CostFunction>> cost_functions_;
};

}  // namespace

NloptSearchResult FitModelNlopt(const std::vector<AlignedRun>& training,
                                const RobotModelInterface& model, const NloptFitOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("NloptFitOptions: " + error);
  if (training.empty()) throw std::invalid_argument("FitModelNlopt: no training runs");
  const NloptMethodInfo& info = Info(options.method);
  const bool needs_gradient = info.gradient || (options.local_polish && info.global);
  ModelRunResiduals residuals(training, model, options.weights, needs_gradient);
  const Robot& robot = model.robot();
  std::vector<bool> held(robot.NumParameters(), false);
  for (const HeldParameter& h : robot.held) held[h.index] = true;
  return RunNloptSearch(residuals, robot.nominal, robot.bounds, held, options);
}

}  // namespace fitcal
