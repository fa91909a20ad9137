#pragma once
// Whether a re-stamped ground truth (fit/segment_cost.h, EstimateClockMap / ApplyClockMap) is
// kept, run by run: a map fitted to noise would shift a run that was on time.
//
// The clock map matches the speed profiles of odometry and ground truth; on a ground truth
// sampled every 0.2-0.3 s the interpolated speed profile is smeared, and a map estimated on a
// correctly clocked run can shift it by tens of milliseconds (measured: the held-out CF of
// `diagnose --clock-map` doubled on such simulated sets). So the map is a hypothesis, checked
// against the identity by the criterion the track fit itself uses: run i keeps its map only when
//   J_i(mapped) < J_i(identity),
// J_i the run's mean squared track error (effect_fit.h, ScoreModel) under the model's final-pose
// fit p (which does not depend on the clocks: the runs end at rest). A correctly clocked data
// set thus keeps the identity wherever the map would make it worse.

#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/run_log.h"

namespace fitcal {

struct ClockChoice {
  std::vector<bool> mapped;  // per run: the re-stamped ground truth was kept
  std::vector<double> objective_identity, objective_mapped;  // J_i under p
  int num_mapped = 0;
};

// `original` and `mapped` hold the same runs (same order), the latter with re-stamped ground
// truth; wheel_mask as WheelChannelMask(robot). Throws std::invalid_argument on a size mismatch.
ClockChoice ChooseClocks(const RobotModelInterface& model, const std::vector<double>& p,
                         const std::vector<RunLog>& original, const std::vector<RunLog>& mapped,
                         unsigned wheel_mask, int num_threads = 0);

// The runs with the chosen ground truth of each.
std::vector<RunLog> ApplyClockChoice(const ClockChoice& choice, std::vector<RunLog> original,
                                     const std::vector<RunLog>& mapped);

// `diagnose --clock-map`: re-stamps each run's ground truth on the encoder clock (the speed-profile
// match of the model's body velocities at the nominal, EstimateClockMap), keeping the map only on
// the runs whose track error under the final-pose fit of `runs` it lowers (ChooseClocks; that fit
// falls back to the nominal when it is not usable): a correctly clocked data set keeps the
// identity. Returns the choice (num_mapped: the runs re-stamped).
ClockChoice MapGroundTruthClocks(const RobotModelInterface& model, int num_threads,
                                 std::vector<RunLog>* runs);

}  // namespace fitcal
