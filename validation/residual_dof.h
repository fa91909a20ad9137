#pragma once
// A fit with no residual degrees of freedom is not a calibration. With as many parameters as
// residuals (one run: three final-pose residuals, Palacin Eq. 14, against three or more
// parameters) the solver reproduces the data exactly - CF 0 on the training runs, whatever the
// robot - and neither the residual nor a covariance (which divides by the degrees of freedom) can
// say anything about it. Every command that writes a calibration asks here first and refuses with
// the returned line; an objective with more residuals per run (a track objective) passes its own
// residual count and is refused only when that, too, does not exceed the parameters.

#include <cstddef>
#include <string>

namespace fitcal {

// Empty when `num_residuals` > `num_parameters`; otherwise one line (without the "fitcal:"
// prefix) naming the counts, why that is no calibration, and what to record. `residual_kind`
// names the residuals ("final-pose"), `residuals_per_run` how many a run adds (for the advice).
std::string ResidualDofRefusal(std::size_t num_residuals, std::size_t num_parameters,
                               std::size_t num_training_runs, const std::string& residual_kind,
                               std::size_t residuals_per_run);

// The final-pose objective's case: three residuals per training run (x, y, heading).
std::string FinalPoseDofRefusal(std::size_t num_training_runs, std::size_t num_parameters);

}  // namespace fitcal
