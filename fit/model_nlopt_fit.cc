#include "fit/model_nlopt_fit.h"

#include <ceres/cost_function.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "models/pose_errors.h"
#include "odometry/linear_final_pose_kernel.h"

namespace fitcal {

namespace {

// The model's residuals through the seam: the value by its double replay - or, when its body step
// is linear in the channels (RobotModelInterface::StepMatrix), by the final-pose kernel on data
// prepared once per run (odometry/linear_final_pose_kernel.h, equal to the replay to rounding and
// ~3.5x faster on omni3), with M(p) computed once per evaluation in Prepare - and the Jacobian by
// its cost function (one per run, made only for the methods that use the gradient).
class ModelRunResiduals : public RunResiduals {
 public:
  ModelRunResiduals(const std::vector<AlignedRun>& runs, const RobotModelInterface& model,
                    const ResidualWeights& weights, bool needs_gradient)
      : runs_(runs), model_(model), weights_(weights) {
    const Robot& robot = model_.robot();
    step_matrix_.resize(3 * static_cast<std::size_t>(robot.NumChannels()));
    if (model_.StepMatrix(robot.nominal.data(), step_matrix_.data())) {
      for (const AlignedRun& run : runs_) {
        if (run.samples.num_channels() != robot.NumChannels()) {
          throw std::invalid_argument("run " + run.id + " has " +
                                      std::to_string(run.samples.num_channels()) +
                                      " channels, the " + robot.model + " robot " +
                                      std::to_string(robot.NumChannels()));
        }
        kernels_.emplace_back(run.samples);
      }
    }
    if (!needs_gradient) return;
    for (const AlignedRun& run : runs_) {
      cost_functions_.emplace_back(model_.FinalPoseCost(run, weights_));
    }
  }

  std::size_t NumRuns() const override { return runs_.size(); }
  void Prepare(const double* p) override {
    if (!kernels_.empty()) model_.StepMatrix(p, step_matrix_.data());
  }
  void Residual(std::size_t i, const double* p, double* r) const override {
    const Pose2d final_pose =
        kernels_.empty() ? model_.ReplayFinalPose(p, runs_[i].samples, runs_[i].start)
                         : kernels_[i].FinalPose(step_matrix_.data(), runs_[i].start);
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
  std::vector<LinearFinalPoseKernel> kernels_;  // empty: the replay
  std::vector<double> step_matrix_;             // M(p) of the last Prepare, 3 x channels
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
  return RunNloptSearch(residuals, robot.nominal, robot.bounds, robot.HeldFlags(), options);
}

}  // namespace fitcal
