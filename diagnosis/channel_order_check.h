#pragma once
// Checks, before fitting, that the encoder columns are the channels the robot YAML says they are,
// for any robot model. The most common silent failure of odometry calibration is a swapped or
// sign-flipped encoder column (wiring, driver config): the fit then "converges" to nonsense.
//
// Each of the model's candidate miswirings (RobotModelInterface::CandidateMiswirings: the
// permutations within each kind of channel and the sign patterns) is a hypothesis "channel i
// reads sign_i * column_i". All are scored by a sum of squared residuals (SSR) at the nominal
// parameters: final poses (Palacin Eq. 14 residuals), or segments (relative pose over disjoint
// windows of ground-truth path) when the ground truth has intermediate poses - closed paths hide
// some miswirings from final poses. When another hypothesis beats the recorded one at the
// nominal, both are fitted (fit/model_fit.h) so that neither is penalised for the nominal being
// off, and the other is declared "far better" when
//
//     SSR_recorded / SSR_other > F^-1(1 - alpha / (H - 1); d, d),   d = residuals - free params
//
// i.e. when the ratio exceeds what two models that both explain the data down to Gaussian noise
// would show by chance, the false-alarm probability alpha spread over the H - 1 alternatives
// (Bonferroni). With too few residuals to fit, the nominal SSRs are compared with d = residuals.

#include <string>
#include <vector>

#include "diagnosis/wheel_order_check.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

// Copies of the runs with the mapping applied to every sample.
std::vector<AlignedRun> ApplyChannelMapping(const std::vector<AlignedRun>& runs,
                                            const ChannelMapping& mapping);

// Words for a mapping against the recorded columns, with the robot's own column names, e.g.
// "columns w_left and w_right swapped" or "steering = -steering (sign flipped)".
std::string DescribeChannelMapping(const Robot& robot, const ChannelMapping& mapping);

struct ChannelOrderOptions {
  ResidualWeights weights;
  double false_alarm_probability = 1e-6;  // alpha above
  int num_threads = 0;
  bool IsValid(std::string* error) const;
};

// The scores and decision as in wheel_order_check.h.
struct ChannelOrderReport : MiswiringScores {
  ChannelMapping best;  // the best other mapping when likely_miswired
};

// segments: empty for the final-pose test, else one window list per run (segment test).
ChannelOrderReport CheckChannelOrder(const std::vector<AlignedRun>& runs,
                                     const std::vector<std::vector<Segment>>& segments,
                                     const RobotModelInterface& model,
                                     const ChannelOrderOptions& options = {});

}  // namespace fitcal
