// Speed of the core: the replay (Palacin Eq. 4) in double and in Jets, loading the shipped flower
// data set, the 180-run Ceres fit, and the whole `fitcal` process. Run with
//   build/tests/fitcal_benchmarks --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// from the repository root (the data set is data/flower).

#include <benchmark/benchmark.h>
#include <ceres/jet.h>

#include <cstdlib>
#include <random>

#include "fit/model_fit.h"
#include "fit/run_split.h"
#include "io/dataset.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/linear_final_pose_kernel.h"
#include "tests/omni3_reference_replay.h"
#include "tests/flower_scenario.h"
#include "tests/test_paths.h"
#include "tests/omni3_robot.h"
#include "tests/three_wheel_files.h"

namespace fitcal {
namespace {

const std::string kData = std::string(FITCAL_SOURCE_DIR) + "/data/flower";

EncoderSamples RandomLog(std::size_t n) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> rate(-3.0, 3.0), dt(0.009, 0.011);
  EncoderSamples samples(3);
  samples.resize(n);
  for (auto&& s : samples) {
    s.dt_s = dt(rng);
    for (int i = 0; i < 3; ++i) s.value[i] = rate(rng);
  }
  return samples;
}

void BM_ReplayDouble(benchmark::State& state) {
  const EncoderSamples samples = RandomLog(static_cast<std::size_t>(state.range(0)));
  const auto p = sim::PalacinTable5Parameters().ToArray();
  for (auto _ : state) {
    const Pose2d end = omni3::ReplayFinalPose(p.data(), samples, Pose2d{});
    benchmark::DoNotOptimize(end);
  }
  // One item = one encoder sample (the three wheel rates of one interval).
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_ReplayDouble)->Arg(400)->Arg(1 << 20);

void BM_ReplayJet9(benchmark::State& state) {
  using Jet = ceres::Jet<double, omni3::kNumParameters>;
  const EncoderSamples samples = RandomLog(static_cast<std::size_t>(state.range(0)));
  const auto p = sim::PalacinTable5Parameters().ToArray();
  std::array<Jet, omni3::kNumParameters> pj;
  for (int k = 0; k < omni3::kNumParameters; ++k) pj[k] = Jet(p[k], k);
  for (auto _ : state) {
    const Pose2<Jet> end = omni3::ReplayFinalPose(pj.data(), samples, Pose2<Jet>{});
    benchmark::DoNotOptimize(end);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_ReplayJet9)->Arg(400);

// The final pose of every training run of data/flower (180 runs): the unit of an NLopt
// evaluation, by the model's replay (/0) and by the final-pose kernel of a model linear in its
// channels (/1, odometry/linear_final_pose_kernel.h, what fit/model_nlopt_fit.h evaluates), on one
// core.
void BM_FinalPoses180Runs(benchmark::State& state) {
  const io::Dataset dataset = io::LoadDataset(kData);
  const RunSplit split = SplitByRepetition(AlignRuns(dataset.runs), {1, 2, 3, 4, 5});
  std::vector<LinearFinalPoseKernel> kernels;
  std::size_t samples = 0;
  for (const AlignedRun& run : split.training) {
    kernels.emplace_back(run.samples);
    samples += run.samples.size();
  }
  const auto table5 = sim::PalacinTable5Parameters().ToArray();
  const std::vector<double> p(table5.begin(), table5.end());
  const Omni3Model& model = DefaultOmni3Model();
  const bool use_kernel = state.range(0) != 0;
  std::vector<double> m(9);
  for (auto _ : state) {
    model.StepMatrix(p.data(), m.data());
    double sum = 0.0;
    for (std::size_t i = 0; i < kernels.size(); ++i) {
      const AlignedRun& run = split.training[i];
      const Pose2d end = use_kernel ? kernels[i].FinalPose(m.data(), run.start)
                                    : model.ReplayFinalPose(p.data(), run.samples, run.start);
      sum += end.x + end.y + end.theta;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(samples));
  state.SetLabel(use_kernel ? "LinearFinalPoseKernel" : "model replay");
}
BENCHMARK(BM_FinalPoses180Runs)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_LoadFlowerDataset(benchmark::State& state) {
  for (auto _ : state) {
    const io::Dataset dataset = io::LoadDataset(kData);
    benchmark::DoNotOptimize(AlignRuns(dataset.runs));
  }
  state.SetLabel("360 runs, load + align");
}
BENCHMARK(BM_LoadFlowerDataset)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CeresFitFlower180Runs(benchmark::State& state) {
  const io::Dataset dataset = io::LoadDataset(kData);
  const RobotModelPtr model = ReadRobotModelFile(dataset.robot_path);
  const RunSplit split = SplitByRepetition(AlignRuns(dataset.runs), {1, 2, 3, 4, 5});
  ModelFitOptions options;
  options.ceres.compute_covariance = state.range(0) != 0;
  for (auto _ : state) {
    const ModelFitResult fit = FitModel(split.training, *model, options);
    if (!fit.usable) state.SkipWithError("fit not usable");
    benchmark::DoNotOptimize(fit);
  }
  state.SetLabel(options.ceres.compute_covariance ? "fit + covariance" : "fit only");
}
BENCHMARK(BM_CeresFitFlower180Runs)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FitcalProcessEndToEnd(benchmark::State& state) {
  const std::string command = std::string(FITCAL_BINARY_DIR) + "/tools/fitcal --logs " + kData +
                              " --method ceres --no-output > /dev/null";
  for (auto _ : state) {
    if (std::system(command.c_str()) != 0) state.SkipWithError("fitcal failed");
  }
  state.SetLabel("process start, load 360 runs, fit, covariance, validate, print");
}
BENCHMARK(BM_FitcalProcessEndToEnd)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace fitcal

BENCHMARK_MAIN();
