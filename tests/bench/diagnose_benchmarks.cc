// Speed of `fitcal diagnose` on real data: the OptiOdom three-wheel robot (67 runs, read from
// ../shared/data/optiodom/omni3, imported once into a temporary data set), repetitions 1-3 train,
// the rest validate - the command's work without writing its outputs: load the data set, the
// declared fit, the tracing over every candidate effect, the residual analyses and the covariate
// tests. Run with
//   build/tests/diagnose_benchmarks --benchmark_repetitions=3
//   --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "diagnosis/diagnose.h"
#include "fit/run_split.h"
#include "io/dataset.h"
#include "models/model_registry.h"
#include "tests/bench/bench_support.h"
#include "cli/import_optiodom.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

// Removes the imported data set when the benchmarks end.
struct RemovedAtExit {
  std::string path;
  ~RemovedAtExit() {
    std::error_code ignored;
    if (!path.empty()) fs::remove_all(path, ignored);
  }
};

// The imported data set's directory; empty when ../shared holds no OptiOdom omni3 sessions.
const std::string& ImportedOmni3() {
  static RemovedAtExit cleanup;
  static const std::string directory = [] {
    const fs::path root = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / "omni3";
    optiodom::ImportOptiOdomOptions options;
    for (const char* type : {"circular", "square"}) {
      if (!fs::is_directory(root / type)) return std::string();
      for (const auto& entry : fs::directory_iterator(root / type)) {
        if (entry.is_directory()) options.sessions.push_back(entry.path().string());
      }
    }
    const fs::path out =
        fs::temp_directory_path() / ("fitcal_diagnose_bench_" + std::to_string(::getpid()));
    options.out = out.string();
    options.force = true;
    return tools::RunImportOptiOdomCommand(options) == 0 ? options.out : std::string();
  }();
  cleanup.path = directory;
  return directory;
}

void BM_DiagnoseOptiOdomOmni3(benchmark::State& state) {
  const std::string& directory = ImportedOmni3();
  if (directory.empty()) {
    state.SkipWithError("no OptiOdom omni3 sessions in ../shared/data/optiodom/omni3");
    return;
  }
  std::size_t runs = 0;
  for (auto _ : state) {
    const io::DatasetIndex index = io::ReadDatasetIndex(directory);
    const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
    const io::Dataset dataset = io::LoadDataset(index, model->robot());
    runs = dataset.runs.size();
    const SplitOf<TrackRun> split = SplitByRepetition(
        PrepareTrackRuns(dataset.runs, WheelChannelMask(model->robot())), {1, 2, 3});
    const DiagnoseResult result = Diagnose(split.training, split.validation, *model);
    benchmark::DoNotOptimize(result.final_validation.cf);
  }
  state.counters["runs"] = static_cast<double>(runs);
}
BENCHMARK(BM_DiagnoseOptiOdomOmni3)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace fitcal

BENCHMARK_MAIN();
