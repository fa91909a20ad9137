#include "validation/residual_dof.h"

namespace fitcal {

std::string ResidualDofRefusal(std::size_t num_residuals, std::size_t num_parameters,
                               std::size_t num_training_runs, const std::string& residual_kind,
                               std::size_t residuals_per_run) {
  if (num_residuals > num_parameters) return "";
  const std::size_t per_run = residuals_per_run > 0 ? residuals_per_run : 1;
  // The fewest runs whose residuals outnumber the parameters.
  const std::size_t runs_needed = num_parameters / per_run + 1;
  auto count = [](std::size_t n, const char* noun) {
    return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
  };
  return count(num_training_runs, "training run") + " give" +
         (num_training_runs == 1 ? "s " : " ") + std::to_string(num_residuals) + " " +
         residual_kind + " residuals for " + count(num_parameters, "free parameter") +
         ": no residual degrees of freedom, so the fit reproduces any data exactly and nothing "
         "judges it (no calibration, no uncertainty); nothing written. Record at least " +
         count(runs_needed, "training run") +
         " (repeat the trajectory or drive another) and keep further repetitions held out";
}

std::string FinalPoseDofRefusal(std::size_t num_training_runs, std::size_t num_parameters) {
  constexpr std::size_t kFinalPoseResiduals = 3;  // x, y, heading (Palacin Eq. 14)
  return ResidualDofRefusal(kFinalPoseResiduals * num_training_runs, num_parameters,
                            num_training_runs, "final-pose", kFinalPoseResiduals);
}

}  // namespace fitcal
