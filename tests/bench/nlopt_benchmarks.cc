// Speed of the NLopt back end (fit/model_nlopt_fit.h, the fit of every model, on omni3). The
// budgets are the paper's and the SciPy reference's:
//   - 37,545 cost evaluations, Palacin Table 4's STE-GA5 (180 training runs); target < 5 s on
//     2 cores;
//   - 25,000 evaluations on 36 runs, where SciPy's differential evolution needs about 68 s.
// Tolerances are switched off so that every run spends exactly its budget.
//
//   build-X/tests/nlopt_benchmarks --benchmark_repetitions=3 --benchmark_report_aggregates_only

#include <benchmark/benchmark.h>

#include <vector>

#include "fit/model_nlopt_fit.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/aligned_run.h"
#include "tests/flower_scenario.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace {

Omni3Robot NominalRobot() {
  Omni3Robot robot;
  robot.nominal = sim::PalacinNominalParameters();  // Eq. 15
  robot.bounds.distance_m = {0.170, 0.220};         // Eq. 16, as data/robots/apr02.yaml
  robot.bounds.radius_m = {0.138, 0.158};
  robot.bounds.angle_offset_rad = {-2.0 * M_PI / 180.0, 2.0 * M_PI / 180.0};
  return robot;
}

// The whole flower (36 trajectories) with the simulator's default noise, `repetitions` times.
const std::vector<AlignedRun>& Runs(int repetitions) {
  static std::vector<AlignedRun> runs_1, runs_5;
  std::vector<AlignedRun>& runs = repetitions == 1 ? runs_1 : runs_5;
  if (runs.empty()) {
    sim::FlowerSimulation sim_options = sim::PalacinFlower();
    sim_options.repetitions = repetitions;
    sim_options.options.seed = 7;
    for (const sim::ModelSimulatedRun& run : sim::SimulateFlower(sim_options)) {
      runs.push_back(AlignRun(run.log));
    }
  }
  return runs;
}

void RunBudget(benchmark::State& state, NloptMethod method, int repetitions, int evaluations) {
  const std::vector<AlignedRun>& runs = Runs(repetitions);
  const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(NominalRobot());
  NloptFitOptions options;
  options.method = method;
  options.max_evaluations = evaluations;
  options.ftol_rel = 0.0;
  options.xtol_rel = 0.0;
  options.record_trace = false;
  options.seed = 1;
  NloptSearchResult result;
  for (auto _ : state) {
    // The result feeds the counters, which keeps the fit from being optimised away (wrapping
    // result.final_cf in DoNotOptimize made GCC 12 report it as garbage with benchmark 1.7.1).
    result = FitModelNlopt(runs, *model, options);
  }
  state.counters["runs"] = static_cast<double>(runs.size());
  state.counters["evaluations"] = result.evaluations;
  state.counters["cf"] = result.final_cf;
}

// Palacin Table 4, STE-GA5: 37,545 evaluations on 180 runs.
void BM_Global37545Evals180Runs_Crs2Lm(benchmark::State& state) {
  RunBudget(state, NloptMethod::kCrs2Lm, 5, 37545);
}
void BM_Global37545Evals180Runs_Esch(benchmark::State& state) {
  RunBudget(state, NloptMethod::kEsch, 5, 37545);
}
// The SciPy differential-evolution reference: 25,000 evaluations on 36 runs.
void BM_Global25000Evals36Runs_Crs2Lm(benchmark::State& state) {
  RunBudget(state, NloptMethod::kCrs2Lm, 1, 25000);
}
void BM_Global25000Evals36Runs_Esch(benchmark::State& state) {
  RunBudget(state, NloptMethod::kEsch, 1, 25000);
}
BENCHMARK(BM_Global37545Evals180Runs_Crs2Lm)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_Global37545Evals180Runs_Esch)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_Global25000Evals36Runs_Crs2Lm)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_Global25000Evals36Runs_Esch)->Unit(benchmark::kSecond)->Iterations(1);

// One objective evaluation (all runs replayed) and one with the autodiff gradient, 180 runs:
// the unit the budgets above multiply.
void BM_OneEvaluation180Runs(benchmark::State& state) {
  const std::vector<AlignedRun>& runs = Runs(5);
  NloptFitOptions options;
  options.method = state.range(0) ? NloptMethod::kSlsqp : NloptMethod::kBobyqa;
  options.max_evaluations = 1;
  options.record_trace = false;
  const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(NominalRobot());
  for (auto _ : state) {
    benchmark::DoNotOptimize(FitModelNlopt(runs, *model, options).final_cf);
  }
}
BENCHMARK(BM_OneEvaluation180Runs)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace fitcal

BENCHMARK_MAIN();
