#pragma once
// The Ceres types the model seam (models/model_interface.h) names, declared without their
// definitions, so that the ~90 files including the seam do not parse jet.h and Eigen for them.
// A file that builds or evaluates a Jet or a cost function includes the real headers
// (<ceres/jet.h>, <ceres/cost_function.h>, <ceres/autodiff_cost_function.h>).
//
// Ceres' own forward header (since 2.1; Debian 12 ships 2.1.0) declares
//   namespace ceres { template <typename T, int N> struct Jet; }
// CostFunction has none: declared here as /usr/include/ceres/cost_function.h defines it
// (`class CERES_EXPORT CostFunction`; the macro is empty in Debian's
// /usr/include/ceres/internal/export.h, and a declaration without it names the same class).

#include <ceres/jet_fwd.h>

namespace ceres {
class CostFunction;
}  // namespace ceres
