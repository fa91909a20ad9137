#include "fit/omni3_nlopt_fit.h"

#include <ceres/cost_function.h>

#include <memory>
#include <stdexcept>

#include "odometry/omni3_final_pose_kernel.h"

namespace fitcal {

namespace {

// Per-run residuals from Omni3FinalPoseResidual: its residual formula applied to the final pose
// of omni3::FinalPoseKernel for the value (Eq. 4 to rounding), its Ceres autodiff cost function
// for the gradient. M^-1 (Eq. 6) is computed once per evaluation in Prepare.
class Omni3KernelResiduals : public RunResiduals {
 public:
  Omni3KernelResiduals(const std::vector<AlignedRun>& runs, const NloptFitOptions& options,
                       bool needs_gradient)
      : runs_(runs) {
    functors_.reserve(runs_.size());
    kernels_.reserve(runs_.size());
    for (const AlignedRun& run : runs_) {
      functors_.emplace_back(run, options.weights);
      kernels_.emplace_back(run.samples);
      if (needs_gradient) {
        cost_functions_.emplace_back(Omni3FinalPoseResidual::Create(run, options.weights));
      }
    }
  }

  std::size_t NumRuns() const override { return runs_.size(); }
  void Prepare(const double* p) override { m_inv_ = omni3::InverseKinematicMatrix(p); }
  void Residual(std::size_t i, const double* /*p*/, double* r) const override {
    functors_[i].ResidualOfFinalPose(kernels_[i].FinalPose(m_inv_, runs_[i].start), r);
  }
  void ResidualAndJacobian(std::size_t i, const double* p, double* r,
                           double* jacobian) const override {
    const double* parameters[] = {p};
    double* jacobians[] = {jacobian};
    cost_functions_.at(i)->Evaluate(parameters, r, jacobians);
  }

 private:
  const std::vector<AlignedRun>& runs_;  // the caller's; AlignRun merged their rests already
  std::vector<Omni3FinalPoseResidual> functors_;
  std::vector<omni3::FinalPoseKernel> kernels_;  // the value's replay (the gradient's: functors_)
  std::vector<std::unique_ptr<ceres::CostFunction>> cost_functions_;
  Eigen::Matrix3d m_inv_ = Eigen::Matrix3d::Zero();
};

}  // namespace

NloptFitResult FitOmni3Nlopt(const std::vector<AlignedRun>& training, const Omni3Robot& robot,
                             const NloptFitOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("NloptFitOptions: " + error);
  if (training.empty()) throw std::invalid_argument("FitOmni3Nlopt: no training runs");
  const NloptMethodInfo& info = Info(options.method);
  const bool needs_gradient = info.gradient || (options.local_polish && info.global);
  Omni3KernelResiduals residuals(training, options, needs_gradient);

  const auto nominal = robot.nominal.ToArray();
  const auto box = robot.ParameterBounds();
  std::vector<Interval> bounds;
  for (const auto& b : box) bounds.push_back({b.lo, b.hi});
  const NloptSearchResult r =
      RunNloptSearch(residuals, std::vector<double>(nominal.begin(), nominal.end()), bounds,
                     std::vector<bool>(omni3::kNumParameters, false), options);

  NloptFitResult result;
  static_cast<NloptSearchSummary&>(result) = r;
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    result.parameters[k] = r.parameters[k];
    result.at_bound[k] = r.at_bound[k];
  }
  return result;
}

}  // namespace fitcal
