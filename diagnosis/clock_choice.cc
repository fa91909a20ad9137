#include "diagnosis/clock_choice.h"

#include <stdexcept>

#include "fit/effect_fit.h"
#include "fit/model_fit.h"
#include "fit/segment_cost.h"
#include "odometry/aligned_run.h"
#include "odometry/parallel_for.h"

namespace fitcal {

ClockChoice ChooseClocks(const RobotModelInterface& model, const std::vector<double>& p,
                         const std::vector<RunLog>& original, const std::vector<RunLog>& mapped,
                         unsigned wheel_mask, int num_threads) {
  if (original.size() != mapped.size()) {
    throw std::invalid_argument("ChooseClocks: the mapped runs are not the original runs");
  }
  const ModelScore identity =
      ScoreModel(model, p, {}, PrepareTrackRuns(original, wheel_mask), {}, num_threads);
  const ModelScore remapped =
      ScoreModel(model, p, {}, PrepareTrackRuns(mapped, wheel_mask), {}, num_threads);
  ClockChoice out;
  for (std::size_t i = 0; i < original.size(); ++i) {
    out.objective_identity.push_back(identity.runs[i].objective);
    out.objective_mapped.push_back(remapped.runs[i].objective);
    const bool keep = remapped.runs[i].objective < identity.runs[i].objective;
    out.mapped.push_back(keep);
    out.num_mapped += keep ? 1 : 0;
  }
  return out;
}

std::vector<RunLog> ApplyClockChoice(const ClockChoice& choice, std::vector<RunLog> original,
                                     const std::vector<RunLog>& mapped) {
  for (std::size_t i = 0; i < original.size() && i < choice.mapped.size(); ++i) {
    if (choice.mapped[i]) original[i].ground_truth = mapped[i].ground_truth;
  }
  return original;
}

ClockChoice MapGroundTruthClocks(const RobotModelInterface& model, int num_threads,
                                 std::vector<RunLog>* runs) {
  const std::vector<double>& nominal = model.robot().nominal;
  std::vector<RunLog> mapped = *runs;
  ParallelFor(mapped.size(), num_threads, [&](std::size_t i) {
    RunLog& run = mapped[i];
    const ClockMap map = EstimateClockMap(model, nominal.data(), AlignRun(run), run.ground_truth);
    run.ground_truth = ApplyClockMap(run.ground_truth, map);
  });
  ModelFitOptions fit_options;
  fit_options.ceres.num_threads = num_threads;
  const ModelFitResult fit = FitModel(AlignRuns(*runs), model, fit_options);
  const std::vector<double>& p = fit.usable ? fit.parameters : nominal;
  ClockChoice choice =
      ChooseClocks(model, p, *runs, mapped, WheelChannelMask(model.robot()), num_threads);
  *runs = ApplyClockChoice(choice, std::move(*runs), mapped);
  return choice;
}

}  // namespace fitcal
