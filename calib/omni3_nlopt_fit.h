#pragma once
// Fits the nine omni3 parameters with NLopt: global methods (the analogues of the genetic
// algorithm of Palacin Sec. 2.6 / Table 4), local derivative-free methods, and a bounded gradient
// method (the analogue of MATLAB's fmincon) - all over the SAME per-run residual as the Ceres fit
// (final_pose_residual.h): for the cost, its formula on the final pose of the precomputed Eq. 4
// kernel (odometry/omni3_final_pose_kernel.h); for the gradient, its Ceres autodiff. Runs are
// evaluated in parallel on a pool of threads that lives for the whole fit.
//
// The search runs in the box of Palacin Eq. 16, normalised to [0, 1]^9 so that every method sees
// parameters of one scale (metres of wheel distance and radians of wheel angle would otherwise
// differ in step size). It starts from the nominal parameters (Eq. 15).
//
// Objective over the N training runs with residuals r_i (weights as in ResidualWeights):
//   kSumOfNorms   (1/N) sum_i |r_i|   = Palacin Eq. 14's CF (default here: it is what the paper's
//                                      GA and fmincon minimised, and these methods do not need a
//                                      smooth sum of squares);
//   kSumOfSquares (1/N) sum_i |r_i|^2 (the Ceres default's objective, scaled by 2/N).
//
// Reproducibility: every random draw comes from NLopt's generator, seeded with `seed` before the
// search; per-run residuals are summed in run order whatever thread computed them. The same seed
// and data give the same parameters bit for bit, on any number of threads.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "calib/aligned_run.h"
#include "calib/final_pose_cost.h"
#include "calib/final_pose_residual.h"
#include "calib/omni3_ceres_fit.h"
#include "odometry/robot_description.h"

namespace fitcal {

enum class NloptMethod {
  kCrs2Lm,   // GN_CRS2_LM: controlled random search with local mutation (global)
  kIsres,    // GN_ISRES: improved stochastic ranking evolution strategy (global)
  kEsch,     // GN_ESCH: evolutionary algorithm, the closest to a GA (global)
  kMlslLds,  // G_MLSL_LDS: multi-level single linkage on a Sobol sequence, BOBYQA polish (global)
  kDirectL,  // GN_DIRECT_L: deterministic box division (global)
  kBobyqa,   // LN_BOBYQA: local, derivative-free, quadratic models
  kSbplx,    // LN_SBPLX: local, derivative-free, Nelder-Mead on subspaces
  kSlsqp,    // LD_SLSQP: local, bounded SQP with the autodiff gradient (fmincon analogue)
  kMma,      // LD_MMA: local, method of moving asymptotes with the autodiff gradient
};

struct NloptMethodInfo {
  NloptMethod method;
  const char* name;  // command-line name, e.g. "crs2lm"
  bool global;       // searches the whole box (stops on the evaluation budget)
  bool gradient;     // uses the autodiff gradient
  const char* description;
};

// Every method, in the order above.
const std::vector<NloptMethodInfo>& NloptMethods();
// nullptr when no method has that name.
const NloptMethodInfo* FindNloptMethod(const std::string& name);
const NloptMethodInfo& Info(NloptMethod method);

// One point of a convergence trace: the best CF (Eq. 14, on the training runs) after
// `evaluation` objective evaluations.
struct ConvergencePoint {
  int evaluation = 0;
  double best_cf = 0.0;
  double elapsed_s = 0.0;
};

struct NloptProgress {
  int evaluations = 0;
  double best_cf = 0.0;
  double elapsed_s = 0.0;
};

struct NloptFitOptions {
  NloptMethod method = NloptMethod::kCrs2Lm;
  FinalPoseObjective objective = FinalPoseObjective::kSumOfNorms;
  ResidualWeights weights;
  std::uint64_t seed = 1;
  int max_evaluations = 20000;  // the whole fit, polish included
  double max_time_s = 0.0;      // 0 = no limit (a time limit makes results timing-dependent)
  // Relative tolerances in the normalised box / on the objective; 0 disables a test. Global
  // methods stop on them too (CRS2, ISRES and MLSL check them), so set both to 0 to spend the
  // whole budget.
  double ftol_rel = 1e-10;
  double xtol_rel = 1e-8;
  int population = 0;  // 0 = NLopt's default for the method
  // Global methods only: the search gets max_evaluations - local_polish_evaluations, then SLSQP
  // with the autodiff gradient polishes its best point with the rest.
  bool local_polish = false;
  int local_polish_evaluations = 2000;
  int num_threads = 0;  // 0 = all cores
  bool record_trace = true;
  // Called on the fitting thread at most every progress_interval_s with the state of the search.
  std::function<void(const NloptProgress&)> progress;
  double progress_interval_s = 0.5;

  bool IsValid(std::string* error) const;
};

struct NloptFitResult {
  bool usable = false;           // finite parameters and NLopt stopped on a success code
  std::string termination;       // NLopt's result, e.g. "NLOPT_MAXEVAL_REACHED"
  std::string message;           // the method, polish and stop reason in words
  int evaluations = 0;           // objective evaluations (each one replays every training run)
  int gradient_evaluations = 0;  // of them, evaluations with the gradient
  double solve_time_s = 0.0;
  double initial_objective = 0.0;
  double final_objective = 0.0;
  double initial_cf = 0.0;  // Eq. 14 on the training runs at the nominal parameters
  double final_cf = 0.0;
  Omni3ParameterArray parameters{};
  std::array<bool, omni3::kNumParameters> at_bound{};
  std::vector<ConvergencePoint> trace;  // one point per improvement of the best CF
};

// Throws std::invalid_argument for invalid options or no runs.
NloptFitResult FitOmni3Nlopt(const std::vector<AlignedRun>& training, const Omni3Robot& robot,
                             const NloptFitOptions& options = {});

}  // namespace fitcal
