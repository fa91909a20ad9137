#pragma once
// The NLopt search behind every model's NLopt methods (`--method crs2lm`, ...,
// fit/model_nlopt_fit.h): global methods (the analogues
// of the genetic algorithm of Palacin Sec. 2.6 / Table 4), local derivative-free methods, and
// bounded gradient methods (the analogue of MATLAB's fmincon), over per-run final-pose residuals
// (models/pose_errors.h) that a RunResiduals supplies - in doubles for the value, with the autodiff
// Jacobian of the same residual for the gradient. Runs are evaluated in parallel on a pool of
// threads that lives for the whole search.
//
// The search runs in the box of the parameters' bounds (Palacin Eq. 16 for omni3), normalised to
// [0, 1]^n so that every method sees parameters of one scale (metres of wheel distance and radians
// of wheel angle would otherwise differ in step size), over the free parameters only: held
// (gauge) parameters stay at their start values. It starts from the start point (the nominal
// parameters, Palacin Eq. 15).
//
// Objective over the N training runs with residuals r_i:
//   kSumOfNorms   (1/N) sum_i |r_i|   = Palacin Eq. 14's CF (default: it is what the paper's GA
//                                      and fmincon minimised, and these methods do not need a
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

#include "fit/solver_options.h"
#include "odometry/robot.h"

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
const NloptMethodInfo& Info(NloptMethod method);

// One point of a convergence trace, or of the progress reported while the search runs: the best
// CF (Eq. 14, on the training runs) after `evaluations` objective evaluations.
struct ConvergencePoint {
  int evaluations = 0;
  double best_cf = 0.0;
  double elapsed_s = 0.0;
};
using NloptProgress = ConvergencePoint;

// No time limit (it would make results timing-dependent) and NLopt's default population for
// each method: neither is an option. How often `progress` is called, at most:
inline constexpr double kNloptProgressIntervalS = 0.5;

struct NloptFitOptions {
  NloptMethod method = NloptMethod::kCrs2Lm;
  FinalPoseObjective objective = FinalPoseObjective::kSumOfNorms;
  ResidualWeights weights;
  std::uint64_t seed = 1;
  int max_evaluations = 20000;  // the whole fit, polish included
  // Relative tolerances in the normalised box / on the objective; 0 disables a test. Global
  // methods stop on them too (CRS2, ISRES and MLSL check them), so set both to 0 to spend the
  // whole budget.
  double ftol_rel = 1e-10;
  double xtol_rel = 1e-8;
  // Global methods only: the search gets max_evaluations - local_polish_evaluations, then SLSQP
  // with the autodiff gradient polishes its best point with the rest.
  bool local_polish = false;
  int local_polish_evaluations = 2000;
  int num_threads = 0;  // 0 = all cores
  bool record_trace = true;
  // Called on the fitting thread at most every kNloptProgressIntervalS with the search's state.
  std::function<void(const NloptProgress&)> progress;

  bool IsValid(std::string* error) const;
};

// The per-run final-pose residuals a search minimises (3 per run, already weighted). Residual
// and ResidualAndJacobian are called concurrently for distinct runs, after Prepare.
class RunResiduals {
 public:
  virtual ~RunResiduals() = default;
  virtual std::size_t NumRuns() const = 0;
  // Once per evaluation of the value, on the searching thread, before any Residual: whatever
  // depends on p only (e.g. omni3's M^-1).
  virtual void Prepare(const double* /*p*/) {}
  // The 3 residuals of run i at p (all parameters).
  virtual void Residual(std::size_t i, const double* p, double* r) const = 0;
  // The residuals and their Jacobian (3 x n, row-major) by autodiff.
  virtual void ResidualAndJacobian(std::size_t i, const double* p, double* r,
                                   double* jacobian) const = 0;
};

// How a search went, and the parameters it found.
struct NloptSearchResult {
  bool usable = false;      // finite parameters and NLopt stopped on a success code
  std::string termination;  // NLopt's result, e.g. "NLOPT_MAXEVAL_REACHED"
  std::string message;      // the method, polish and stop reason in words
  int evaluations = 0;      // objective evaluations (each one replays every training run)
  double solve_time_s = 0.0;
  double initial_objective = 0.0;
  double final_objective = 0.0;
  double initial_cf = 0.0;  // Eq. 14 (weighted as the residuals) at the start
  double final_cf = 0.0;
  std::vector<ConvergencePoint> trace;  // one point per improvement of the best CF
  std::vector<double> parameters;       // all of them, held ones at their start value
  std::vector<bool> at_bound;           // within 1e-6 of the box width of a bound
};

// Searches the box `bounds` (one interval per parameter, start inside it) from `start`; held[k]
// keeps parameter k at start[k]. Throws std::invalid_argument for invalid options, no runs or
// inconsistent sizes.
NloptSearchResult RunNloptSearch(RunResiduals& residuals, const std::vector<double>& start,
                                 const std::vector<Interval>& bounds, const std::vector<bool>& held,
                                 const NloptFitOptions& options);

}  // namespace fitcal
