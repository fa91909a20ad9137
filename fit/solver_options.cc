#include "fit/solver_options.h"

#include <cmath>

#include "odometry/invalid.h"

namespace fitcal {

namespace {

// Palacin Eq. 14 as a loss on the squared norm s = |r|^2: Ceres minimises 0.5 rho(s), so
// rho(s) = 2 sqrt(s) makes a run's cost |r|. Smoothed as 2 (sqrt(s + eps^2) - eps) so that the
// derivative stays finite for a run that fits exactly; eps = 1e-9 residual units (1 nm) is far
// below any CF a real data set reaches.
class SumOfNormsLoss : public ceres::LossFunction {
 public:
  void Evaluate(double s, double rho[3]) const override {
    constexpr double kEps = 1e-9;
    const double a = std::sqrt(s + kEps * kEps);
    rho[0] = 2.0 * (a - kEps);
    rho[1] = 1.0 / a;
    rho[2] = -0.5 / (a * a * a);
  }
};

}  // namespace

ceres::LossFunction* MakeLoss(const CeresFitOptions& options) {
  if (options.objective == FinalPoseObjective::kSumOfNorms) return new SumOfNormsLoss;
  switch (options.loss) {
    case CeresRobustLoss::kHuber:
      return new ceres::HuberLoss(options.loss_scale);
    case CeresRobustLoss::kCauchy:
      return new ceres::CauchyLoss(options.loss_scale);
    case CeresRobustLoss::kNone:
      break;
  }
  return nullptr;
}

namespace {

template <typename E>
struct NamedValue {
  const char* name;
  E value;
};
constexpr NamedValue<CeresTrustRegion> kTrustRegionNames[] = {
    {"lm", CeresTrustRegion::kLevenbergMarquardt}, {"dogleg", CeresTrustRegion::kDogleg}};
constexpr NamedValue<CeresRobustLoss> kLossNames[] = {{"none", CeresRobustLoss::kNone},
                                                      {"huber", CeresRobustLoss::kHuber},
                                                      {"cauchy", CeresRobustLoss::kCauchy}};
constexpr NamedValue<FinalPoseObjective> kObjectiveNames[] = {
    {"squares", FinalPoseObjective::kSumOfSquares}, {"eq14", FinalPoseObjective::kSumOfNorms}};

template <typename E, std::size_t N>
const char* NameOf(const NamedValue<E> (&table)[N], E value) {
  for (const auto& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}
template <typename E, std::size_t N>
bool ValueOf(const NamedValue<E> (&table)[N], const std::string& text, E* out) {
  for (const auto& entry : table) {
    if (text == entry.name) {
      *out = entry.value;
      return true;
    }
  }
  return false;
}

}  // namespace

const char* ToString(CeresTrustRegion v) { return NameOf(kTrustRegionNames, v); }
const char* ToString(CeresRobustLoss v) { return NameOf(kLossNames, v); }
const char* ToString(FinalPoseObjective v) { return NameOf(kObjectiveNames, v); }
bool ParseCeresRobustLoss(const std::string& text, CeresRobustLoss* out) {
  return ValueOf(kLossNames, text, out);
}
bool ParseFinalPoseObjective(const std::string& text, FinalPoseObjective* out) {
  return ValueOf(kObjectiveNames, text, out);
}

bool CeresFitOptions::IsValid(std::string* error) const {
  if (!(weights.position_sigma_m > 0.0) || !(weights.heading_sigma_rad > 0.0))
    return Invalid(error, "residual sigmas must be positive");
  if (max_num_iterations < 1) return Invalid(error, "max_num_iterations must be at least 1");
  if (num_threads < 0) return Invalid(error, "num_threads must be >= 0");
  if (loss != CeresRobustLoss::kNone && !(loss_scale > 0.0))
    return Invalid(error, "loss_scale must be positive");
  if (loss != CeresRobustLoss::kNone && objective == FinalPoseObjective::kSumOfNorms)
    return Invalid(error,
                   "a robust loss applies to the sum-of-squares objective; the Eq. 14 sum of "
                   "norms already weighs each run linearly");
  return true;
}

}  // namespace fitcal
