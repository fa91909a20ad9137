// Import + fit of the published OptiOdom recordings in ../shared/data/optiodom, as a user runs
// them: `fitcal import optiodom <sessions> --out <temp>` then `fitcal fit --logs <temp>
// --no-output --threads 1`. Both run as child processes, so the benchmark's own CPU time says
// nothing: it reports wall time (UseRealTime) and the children's CPU time per iteration
// (counter child_cpu_s, from getrusage). The import's wall time includes an fsync per written
// file (io/atomic_file.h), which depends on the disk, not on fitcal.
//
// Skipped with an error when ../shared is missing (a checkout without the shared data);
// FITCAL_SHARED_DIR in the environment points elsewhere.

#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/bench/bench_support.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

// robot: a folder of ../shared/data/optiodom; fit_flags: what `fit` gets besides the data set.
void BM_ImportAndFit(benchmark::State& state, const std::string& robot,
                     const std::string& fit_flags) {
  const fs::path source = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / robot;
  if (!fs::is_directory(source / "circular") || !fs::is_directory(source / "square")) {
    state.SkipWithError(("no shared data at " + source.string()).c_str());
    return;
  }
  const fs::path out =
      fs::temp_directory_path() / ("fitcal_bench_" + robot + "_" + std::to_string(::getpid()));
  const std::string fitcal = std::string(FITCAL_BINARY_DIR) + "/tools/fitcal";
  const std::string import = fitcal + " import optiodom " + (source / "circular").string() + "/* " +
                             (source / "square").string() + "/* --out " + out.string() +
                             " > /dev/null";
  const std::string fit = fitcal + " fit --logs " + out.string() + " --no-output --threads 1 " +
                          fit_flags + " > /dev/null";
  double cpu_s = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    fs::remove_all(out);
    state.ResumeTiming();
    const double cpu_before = bench::ChildrenCpuSeconds();
    if (std::system(import.c_str()) != 0 || std::system(fit.c_str()) != 0) {
      state.SkipWithError("fitcal import or fit failed");
      break;
    }
    cpu_s += bench::ChildrenCpuSeconds() - cpu_before;
  }
  fs::remove_all(out);
  state.counters["child_cpu_s"] = benchmark::Counter(cpu_s, benchmark::Counter::kAvgIterations);
  state.SetLabel("import " + robot + " circles + squares, fit on one thread");
}
BENCHMARK_CAPTURE(BM_ImportAndFit, diff, std::string("diff"), std::string())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The calibration that carries the diff drive's pivot effect (README, "The other OptiOdom robots").
BENCHMARK_CAPTURE(BM_ImportAndFit, diff_pivot, std::string("diff"),
                  std::string("--effects pivot_yaw_gain"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ImportAndFit, omni4, std::string("omni4"), std::string("--train-reps 1-5"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace fitcal

BENCHMARK_MAIN();
