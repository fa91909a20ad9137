// The track fit with clock offsets (fit/track_residual.h, fit/model_fit.h) on the published
// OptiOdom recordings in ../shared/data/optiodom, as `fitcal fit --residuals track
// --clock-offsets session --threads 1` runs it on the imported circles + squares: the default
// split's training runs (repetitions 1-5), one offset per session. The data set is imported once
// (`fitcal import optiodom`, a child process) and loaded outside the timing; each iteration times
// FitModel alone (the direction analysis, the solve and the covariance), which is what the fit
// command's solver line reports. Issue 29's target: <= 1 s on one thread.
//
// Skipped with an error when ../shared is missing (a checkout without the shared data);
// FITCAL_SHARED_DIR in the environment points elsewhere.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "fit/track_residual.h"
#include "io/dataset.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "tests/bench/bench_support.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

// The imported data set of one robot's circles + squares, loaded, and its default training split.
struct ImportedLoops {
  RobotModelPtr model;
  std::vector<RunLog> logs;          // training runs only
  std::vector<AlignedRun> training;  // repetitions 1-5, as `fit`'s default split
  std::vector<const GroundTruthTrack*> tracks;
  std::string error;
};

ImportedLoops ImportLoops(const std::string& robot) {
  ImportedLoops out;
  const fs::path source = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / robot;
  if (!fs::is_directory(source / "circular") || !fs::is_directory(source / "square")) {
    out.error = "no shared data at " + source.string();
    return out;
  }
  const fs::path dir =
      fs::temp_directory_path() / ("fitcal_track_bench_" + robot + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string import = std::string(FITCAL_BINARY_DIR) + "/tools/fitcal import optiodom " +
                             (source / "circular").string() + "/* " +
                             (source / "square").string() + "/* --out " + dir.string() +
                             " > /dev/null";
  if (std::system(import.c_str()) != 0) {
    out.error = "fitcal import optiodom failed";
    return out;
  }
  const io::DatasetIndex index = io::ReadDatasetIndex(dir.string());
  out.model = ReadRobotModelFile(index.robot_path);
  for (RunLog& log : io::LoadDataset(index, out.model->robot()).runs) {
    if (log.repetition >= 1 && log.repetition <= 5) out.logs.push_back(std::move(log));
  }
  fs::remove_all(dir);
  out.training = AlignRuns(out.logs);
  for (const RunLog& log : out.logs) out.tracks.push_back(&log.ground_truth);
  return out;
}

void BM_TrackFitClockOffsets(benchmark::State& state, const std::string& robot,
                             ClockGrouping grouping) {
  static std::map<std::string, ImportedLoops> imported;  // one import per robot and process
  if (imported.count(robot) == 0) imported.emplace(robot, ImportLoops(robot));
  const ImportedLoops& loops = imported.at(robot);
  if (!loops.error.empty()) {
    state.SkipWithError(loops.error.c_str());
    return;
  }
  const TrackFitData data = MakeTrackFitData(loops.training, loops.tracks, grouping);
  ModelFitOptions options;
  options.residuals = ResidualKind::kTrack;
  options.track = &data;
  options.ceres.num_threads = 1;
  ModelFitResult fit;
  for (auto _ : state) {
    fit = FitModel(loops.training, *loops.model, options);
    benchmark::DoNotOptimize(fit.parameters.data());
  }
  if (!fit.usable) state.SkipWithError(("fit not usable: " + fit.termination).c_str());
  state.counters["iterations"] = fit.iterations;
  state.counters["offset_iterations"] = fit.clock_offset_iterations;
  state.counters["runs"] = static_cast<double>(loops.training.size());
  state.counters["clock_groups"] = static_cast<double>(data.clock_groups.size());
  state.SetLabel(robot + " circles + squares (reps 1-5), track, clock offsets " +
                 ToString(grouping) + ", one thread");
}
BENCHMARK_CAPTURE(BM_TrackFitClockOffsets, diff, std::string("diff"), ClockGrouping::kPerSession)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_TrackFitClockOffsets, diff_no_offsets, std::string("diff"),
                  ClockGrouping::kNone)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace fitcal

BENCHMARK_MAIN();
