#include "fit/nlopt_search.h"

#include <nlopt.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "odometry/invalid.h"
#include "odometry/parallel_for.h"

namespace fitcal {

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Threads that live for a whole fit: an objective evaluation hands every thread a share of the
// runs, so tens of thousands of evaluations do not pay for tens of thousands of thread starts.
// Each evaluation is a Batch; threads claim its items one at a time and the caller works too, so
// a worker that the OS has not scheduled yet never delays an evaluation (the caller simply does
// its share). Between evaluations the workers spin briefly (NLopt's own work between two
// evaluations takes microseconds), then sleep on a condition variable.
class WorkerPool {
 public:
  explicit WorkerPool(int num_threads) {
    for (int t = 1; t < num_threads; ++t) threads_.emplace_back([this] { WorkerLoop(); });
  }
  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stop_ = true;
      generation_.fetch_add(1);
    }
    cv_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Runs fn(i) for i in [0, n) on every thread; returns when all are done. fn must not throw.
  void Run(std::size_t n, const std::function<void(std::size_t)>& fn) {
    if (threads_.empty() || n <= 1) {
      for (std::size_t i = 0; i < n; ++i) fn(i);
      return;
    }
    auto batch = std::make_shared<Batch>(&fn, n);
    {
      std::lock_guard<std::mutex> lock(mu_);
      current_ = batch;
      generation_.fetch_add(1);
    }
    cv_.notify_all();
    Work(*batch);
    // Only items other threads have claimed and not finished remain.
    while (batch->done.load() < n) std::this_thread::yield();
  }

 private:
  struct Batch {
    Batch(const std::function<void(std::size_t)>* f, std::size_t count) : fn(f), n(count) {}
    const std::function<void(std::size_t)>* fn;
    std::size_t n;
    std::atomic<std::size_t> next{0};
    std::atomic<std::size_t> done{0};
  };

  static void Work(Batch& batch) {
    for (std::size_t i = batch.next++; i < batch.n; i = batch.next++) {
      (*batch.fn)(i);
      batch.done.fetch_add(1);
    }
  }

  void WorkerLoop() {
    constexpr double kSpinSeconds = 50e-6;
    std::uint64_t seen = 0;
    for (;;) {
      const Clock::time_point t0 = Clock::now();
      for (int k = 0; generation_.load() == seen; ++k) {
        if ((k & 63) == 63 && SecondsSince(t0) > kSpinSeconds) break;
      }
      std::shared_ptr<Batch> batch;
      {
        std::unique_lock<std::mutex> lock(mu_);
        cv_.wait(lock, [&] { return generation_.load() != seen; });
        seen = generation_.load();
        if (stop_) return;
        batch = current_;
      }
      Work(*batch);
    }
  }

  std::vector<std::thread> threads_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::shared_ptr<Batch> current_;  // guarded by mu_
  bool stop_ = false;               // guarded by mu_
  std::atomic<std::uint64_t> generation_{0};
};

// The gradient methods, and the polish of a global method, use the autodiff gradient.
bool NeedsGradient(const NloptFitOptions& options) {
  return Info(options.method).gradient || (options.local_polish && Info(options.method).global);
}

// The objective NLopt sees, over the normalised free coordinates u in [0, 1]^m:
// p_k = lo_k + u_j (hi_k - lo_k) for the j-th free parameter k, held ones at the start. Per-run
// residuals come from RunResiduals (value in doubles, autodiff Jacobian for the gradient) and
// are reduced in run order.
class Objective {
 public:
  Objective(RunResiduals& residuals, const std::vector<double>& start,
            const std::vector<Interval>& bounds, const std::vector<bool>& held,
            const NloptFitOptions& options)
      : residuals_(residuals),
        options_(options),
        pool_(ResolveThreadCount(options.num_threads)),
        t0_(Clock::now()),
        start_(start),
        n_(static_cast<int>(start.size())) {
    for (int k = 0; k < n_; ++k) {
      lo_.push_back(bounds[k].lo);
      width_.push_back(bounds[k].hi - bounds[k].lo);
      if (!held[k]) free_.push_back(k);
    }
    const std::size_t runs = residuals_.NumRuns();
    r_.resize(runs * 3);
    jacobians_.resize(NeedsGradient(options) ? runs * 3 * n_ : 0);
    best_u_.assign(free_.size(), 0.0);
  }

  unsigned dimension() const { return static_cast<unsigned>(free_.size()); }

  std::vector<double> ToParameters(const double* u) const {
    std::vector<double> p = start_;
    for (std::size_t j = 0; j < free_.size(); ++j) {
      const int k = free_[j];
      p[k] = lo_[k] + u[j] * width_[k];
    }
    return p;
  }
  std::vector<double> ToNormalised(const std::vector<double>& p) const {
    std::vector<double> u(free_.size());
    for (std::size_t j = 0; j < free_.size(); ++j) {
      const int k = free_[j];
      u[j] = std::min(1.0, std::max(0.0, (p[k] - lo_[k]) / width_[k]));
    }
    return u;
  }

  // Objective value at u; fills grad (d/du) when it is not null. Also returns the CF.
  double Evaluate(const double* u, double* grad, double* cf) {
    const std::vector<double> p = ToParameters(u);
    const std::size_t n = residuals_.NumRuns();
    if (grad == nullptr) {
      residuals_.Prepare(p.data());
      pool_.Run(n, [&](std::size_t i) { residuals_.Residual(i, p.data(), &r_[3 * i]); });
    } else {
      pool_.Run(n, [&](std::size_t i) {
        residuals_.ResidualAndJacobian(i, p.data(), &r_[3 * i], &jacobians_[3 * n_ * i]);
      });
    }
    const bool norms = options_.objective == FinalPoseObjective::kSumOfNorms;
    double sum_norm = 0.0, sum_squares = 0.0;
    std::vector<double> dp(grad != nullptr ? n_ : 0, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      const double* r = &r_[3 * i];
      const double sq = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      const double norm = std::sqrt(sq);
      sum_norm += norm;
      sum_squares += sq;
      if (grad != nullptr) {
        // d|r|/dp = J^T r / |r| (a run fit exactly contributes no gradient); d|r|^2/dp = 2 J^T r.
        const double scale = norms ? (norm > 0.0 ? 1.0 / norm : 0.0) : 2.0;
        const double* J = &jacobians_[3 * n_ * i];  // row-major 3 x n
        for (int k = 0; k < n_; ++k) {
          dp[k] += scale * (J[k] * r[0] + J[n_ + k] * r[1] + J[2 * n_ + k] * r[2]);
        }
      }
    }
    const double inv_n = 1.0 / static_cast<double>(n);
    if (grad != nullptr) {
      for (std::size_t j = 0; j < free_.size(); ++j) {
        grad[j] = dp[free_[j]] * inv_n * width_[free_[j]];
      }
    }
    // The CF of Eq. 14 is reported with sigmas of 1; with other weights it is the weighted one.
    *cf = sum_norm * inv_n;
    return (norms ? sum_norm : sum_squares) * inv_n;
  }

  // The NLopt callback: counts, keeps the best point, records the trace, reports progress.
  static double Callback(unsigned dim, const double* u, double* grad, void* data) {
    auto* self = static_cast<Objective*>(data);
    try {
      double cf = 0.0;
      const double f = self->Evaluate(u, grad, &cf);
      self->Record(dim, u, f, cf);
      return f;
    } catch (...) {
      self->error_ = std::current_exception();
      nlopt_force_stop(self->opt_);
      return std::numeric_limits<double>::infinity();
    }
  }

  void Record(unsigned dim, const double* u, double f, double cf) {
    ++evaluations_;
    if (std::isfinite(f) && f < best_f_) {
      best_f_ = f;
      best_cf_ = cf;
      std::copy(u, u + dim, best_u_.begin());
      if (options_.record_trace) trace_.push_back({evaluations_, cf, SecondsSince(t0_)});
    }
    if (options_.progress && SecondsSince(last_progress_) >= kNloptProgressIntervalS) {
      last_progress_ = Clock::now();
      options_.progress({evaluations_, best_cf_, SecondsSince(t0_)});
    }
  }

  void SetCurrentOpt(nlopt_opt opt) { opt_ = opt; }
  void RethrowIfFailed() const {
    if (error_) std::rethrow_exception(error_);
  }

  int evaluations() const { return evaluations_; }
  double best_f() const { return best_f_; }
  double best_cf() const { return best_cf_; }
  const std::vector<double>& best_u() const { return best_u_; }
  std::vector<ConvergencePoint> TakeTrace() { return std::move(trace_); }
  double elapsed_s() const { return SecondsSince(t0_); }

 private:
  RunResiduals& residuals_;
  const NloptFitOptions& options_;
  WorkerPool pool_;
  Clock::time_point t0_;
  Clock::time_point last_progress_ = Clock::now();
  std::vector<double> start_;
  int n_;
  std::vector<double> lo_, width_;
  std::vector<int> free_;  // the searched parameters, in parameter order
  std::vector<double> r_, jacobians_;
  int evaluations_ = 0;
  double best_f_ = std::numeric_limits<double>::infinity();
  double best_cf_ = std::numeric_limits<double>::infinity();
  std::vector<double> best_u_;
  std::vector<ConvergencePoint> trace_;
  nlopt_opt opt_ = nullptr;
  std::exception_ptr error_;
};

nlopt_algorithm Algorithm(NloptMethod method) {
  switch (method) {
    case NloptMethod::kCrs2Lm:
      return NLOPT_GN_CRS2_LM;
    case NloptMethod::kIsres:
      return NLOPT_GN_ISRES;
    case NloptMethod::kEsch:
      return NLOPT_GN_ESCH;
    case NloptMethod::kMlslLds:
      return NLOPT_G_MLSL_LDS;
    case NloptMethod::kDirectL:
      return NLOPT_GN_DIRECT_L;
    case NloptMethod::kBobyqa:
      return NLOPT_LN_BOBYQA;
    case NloptMethod::kSbplx:
      return NLOPT_LN_SBPLX;
    case NloptMethod::kSlsqp:
      return NLOPT_LD_SLSQP;
    case NloptMethod::kMma:
      return NLOPT_LD_MMA;
  }
  throw std::logic_error("unknown NloptMethod");
}

struct OptDeleter {
  void operator()(nlopt_opt opt) const { nlopt_destroy(opt); }
};
using OptPtr = std::unique_ptr<std::remove_pointer_t<nlopt_opt>, OptDeleter>;

OptPtr MakeOpt(nlopt_algorithm algorithm, Objective* objective, double ftol_rel, double xtol_rel,
               int max_evaluations) {
  const unsigned dim = objective->dimension();
  OptPtr opt(nlopt_create(algorithm, dim));
  if (!opt) throw std::runtime_error("NLopt could not create the optimizer");
  const std::vector<double> zeros(dim, 0.0), ones(dim, 1.0);
  nlopt_set_lower_bounds(opt.get(), zeros.data());
  nlopt_set_upper_bounds(opt.get(), ones.data());
  nlopt_set_min_objective(opt.get(), &Objective::Callback, objective);
  nlopt_set_ftol_rel(opt.get(), ftol_rel);
  nlopt_set_xtol_rel(opt.get(), xtol_rel);
  nlopt_set_maxeval(opt.get(), max_evaluations);
  return opt;
}

bool Succeeded(nlopt_result r) { return r > 0 || r == NLOPT_ROUNDOFF_LIMITED; }

}  // namespace

const std::vector<NloptMethodInfo>& NloptMethods() {
  static const std::vector<NloptMethodInfo> kMethods = {
      {NloptMethod::kCrs2Lm, "crs2lm", true, false,
       "NLopt CRS2-LM, controlled random search with local mutation (global)"},
      {NloptMethod::kIsres, "isres", true, false,
       "NLopt ISRES, stochastic ranking evolution strategy (global)"},
      {NloptMethod::kEsch, "esch", true, false, "NLopt ESCH, evolutionary algorithm (global)"},
      {NloptMethod::kMlslLds, "mlsl-lds", true, false,
       "NLopt MLSL-LDS, Sobol multistart with BOBYQA local searches (global)"},
      {NloptMethod::kDirectL, "direct-l", true, false,
       "NLopt DIRECT-L, deterministic box division (global)"},
      {NloptMethod::kBobyqa, "bobyqa", false, false,
       "NLopt BOBYQA, local derivative-free quadratic models"},
      {NloptMethod::kSbplx, "sbplx", false, false, "NLopt SBPLX, local derivative-free simplex"},
      {NloptMethod::kSlsqp, "slsqp", false, true,
       "NLopt SLSQP, local bounded SQP with the autodiff gradient"},
      {NloptMethod::kMma, "mma", false, true,
       "NLopt MMA, local moving asymptotes with the autodiff gradient"},
  };
  return kMethods;
}

const NloptMethodInfo& Info(NloptMethod method) {
  for (const NloptMethodInfo& info : NloptMethods()) {
    if (info.method == method) return info;
  }
  throw std::logic_error("NloptMethod missing from NloptMethods()");
}

bool NloptFitOptions::IsValid(std::string* error) const {
  if (!(weights.position_sigma_m > 0.0) || !(weights.heading_sigma_rad > 0.0))
    return Invalid(error, "residual sigmas must be positive");
  if (max_evaluations < 1) return Invalid(error, "max_evaluations must be at least 1");
  if (local_polish && Info(method).global && local_polish_evaluations >= max_evaluations)
    return Invalid(error,
                   "local_polish_evaluations must leave part of max_evaluations to the search");
  if (local_polish && local_polish_evaluations < 1)
    return Invalid(error, "local_polish_evaluations must be at least 1");
  if (ftol_rel < 0.0 || xtol_rel < 0.0) return Invalid(error, "tolerances must be >= 0");
  if (num_threads < 0) return Invalid(error, "num_threads must be >= 0");
  return true;
}

namespace {

// Runs the configured method (and the polish) on the objective from u; fills the result's stop
// reason and returns whether NLopt reported success.
bool Search(const NloptFitOptions& options, Objective& objective, std::vector<double>& u,
            NloptSearchResult* result) {
  const NloptMethodInfo& info = Info(options.method);
  const bool polish = options.local_polish && info.global;
  const int search_budget =
      polish ? options.max_evaluations - options.local_polish_evaluations : options.max_evaluations;
  OptPtr opt = MakeOpt(Algorithm(options.method), &objective, options.ftol_rel, options.xtol_rel,
                       search_budget);
  OptPtr local;
  if (options.method == NloptMethod::kMlslLds) {
    // MLSL's local searches: BOBYQA to a moderate tolerance; the budget is MLSL's.
    local = MakeOpt(NLOPT_LN_BOBYQA, &objective, std::max(options.ftol_rel, 1e-9),
                    std::max(options.xtol_rel, 1e-6), 0);
    nlopt_set_local_optimizer(opt.get(), local.get());
  }

  nlopt_srand(static_cast<unsigned long>(options.seed));
  objective.SetCurrentOpt(opt.get());
  double f = 0.0;
  nlopt_result code = nlopt_optimize(opt.get(), u.data(), &f);
  objective.RethrowIfFailed();
  result->termination = nlopt_result_to_string(code);
  result->message = std::string(info.description) + ": " + result->termination;
  bool ok = Succeeded(code);

  if (polish && objective.evaluations() > 0) {
    u = objective.best_u();
    OptPtr polisher = MakeOpt(NLOPT_LD_SLSQP, &objective, options.ftol_rel, options.xtol_rel,
                              options.local_polish_evaluations);
    objective.SetCurrentOpt(polisher.get());
    const int before = objective.evaluations();
    const nlopt_result polish_code = nlopt_optimize(polisher.get(), u.data(), &f);
    objective.RethrowIfFailed();
    result->message += std::string("; SLSQP polish ") + nlopt_result_to_string(polish_code) +
                       " after " + std::to_string(objective.evaluations() - before) +
                       " evaluations";
    ok = ok && Succeeded(polish_code);
  }
  return ok;
}

}  // namespace

NloptSearchResult RunNloptSearch(RunResiduals& residuals, const std::vector<double>& start,
                                 const std::vector<Interval>& bounds, const std::vector<bool>& held,
                                 const NloptFitOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("NloptFitOptions: " + error);
  if (residuals.NumRuns() == 0) throw std::invalid_argument("NLopt search: no training runs");
  const std::size_t n = start.size();
  if (bounds.size() != n || held.size() != n) {
    throw std::invalid_argument("NLopt search: start, bounds and held differ in length");
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (!held[k] && !(bounds[k].hi > bounds[k].lo)) {
      throw std::invalid_argument("NLopt search: an empty box for a free parameter");
    }
  }

  Objective objective(residuals, start, bounds, held, options);
  NloptSearchResult result;
  std::vector<double> u = objective.ToNormalised(start);
  {
    double cf = 0.0;
    // The starting point's value, not counted as a search evaluation.
    result.initial_objective = objective.Evaluate(u.data(), nullptr, &cf);
    result.initial_cf = cf;
  }
  const bool ok = objective.dimension() > 0 && Search(options, objective, u, &result);

  result.evaluations = objective.evaluations();
  result.solve_time_s = objective.elapsed_s();
  result.trace = objective.TakeTrace();
  // The best point seen (NLopt's x is the same for these methods, but ISRES/ESCH may return
  // the last population's best); the start counts as seen.
  if (objective.best_f() <= result.initial_objective) {
    result.parameters = objective.ToParameters(objective.best_u().data());
    result.final_objective = objective.best_f();
    result.final_cf = objective.best_cf();
  } else {  // nothing better than the start: keep the start
    result.parameters = start;
    result.final_objective = result.initial_objective;
    result.final_cf = result.initial_cf;
  }

  bool finite = true;
  result.at_bound.assign(n, false);
  for (std::size_t k = 0; k < n; ++k) {
    finite = finite && std::isfinite(result.parameters[k]);
    if (held[k]) continue;
    const double tol = 1e-6 * bounds[k].Width();  // as the Ceres fit
    result.at_bound[k] =
        result.parameters[k] <= bounds[k].lo + tol || result.parameters[k] >= bounds[k].hi - tol;
  }
  result.usable = finite && ok && std::isfinite(result.final_objective);
  return result;
}

}  // namespace fitcal
