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
// off - with a dense ground truth the final-pose fits of both orders start from their fits of the
// windows, whose objective has no local minima where final poses from a guess far off do -
// and the other is declared "far better" when
//
//     SSR_recorded / SSR_other > F^-1(1 - alpha / (H - 1); d, d),   d = residuals - free params
//
// i.e. when the ratio exceeds what two models that both explain the data down to Gaussian noise
// would show by chance, the false-alarm probability alpha spread over the H - 1 alternatives
// (Bonferroni). With too few residuals to fit, the nominal SSRs are compared with d = residuals.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/parallel_for.h"
#include "odometry/run_log.h"

namespace fitcal {

// The scores and the decision of the test above.
struct MiswiringScores {
  bool likely_miswired = false;  // another mapping explains the data far better
  double recorded_nominal_ssr = 0.0;
  double best_nominal_ssr = 0.0;
  bool fitted = false;         // SSRs below are after a bounded fit of both hypotheses
  double recorded_ssr = 0.0;   // SSR of the recorded order (fitted when `fitted`)
  double best_ssr = 0.0;       // SSR of the best other mapping (fitted when `fitted`)
  double threshold = 0.0;      // the F quantile the ratio recorded/best had to exceed
  int degrees_of_freedom = 0;  // 0: nothing was decided (too few windows)
  std::string message;         // one line when likely_miswired
};

// What the decision needs besides the nominal SSRs: how many residuals the SSRs sum and how many
// parameters a fit frees (d above), how many other mappings were scored (Bonferroni), the fit of
// a hypothesis, and the words of the message.
struct MiswiringTest {
  int num_residuals = 0;
  int num_free_parameters = 0;
  std::size_t num_alternatives = 0;
  double false_alarm_probability = 0.0;
  // The SSR after a bounded fit of the best other mapping (true) or of the recorded one (false).
  std::function<double(bool best_other)> fitted_ssr;
  std::function<std::string()> describe_best;  // the best other mapping in words
  std::string evidence;                        // e.g. "final-pose SSR"
  std::string sample;                          // e.g. "36 runs"
};

// The decision of the header on scores whose recorded_nominal_ssr and best_nominal_ssr are set:
// fills the rest of *scores (both hypotheses fitted when the other beats the recorded one at the
// nominal and d allows it).
void DecideMiswiring(const MiswiringTest& test, MiswiringScores* scores);

// sum_i ssr(i) over n runs: each run's term computed in parallel, the sum taken in run order (the
// same bits on any number of threads).
template <typename Fn>
double SumOverRuns(std::size_t n, int num_threads, Fn&& ssr) {
  std::vector<double> per_run(n, 0.0);
  ParallelFor(n, num_threads, [&](std::size_t i) { per_run[i] = ssr(i); });
  double sum = 0.0;
  for (double v : per_run) sum += v;
  return sum;
}

// The p-quantile of Fisher's F(d1, d2) (the threshold above), by bisection on statistics.h.
double FDistributionQuantile(double p, double d1, double d2);

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
  // Every other mapping's nominal SSR to the end, for the best other one's (the importer prints
  // it). Otherwise a mapping is scored only as far as it could beat the recorded order: the same
  // decision and the same best mapping when one beats it, else best_nominal_ssr infinite and
  // `best` empty. The real diff drive's 97-run fit (callgrind): the check, its sessions included,
  // 237 M instructions against 510 M for the pool alone scored to the end.
  bool score_every_mapping = false;
  bool IsValid(std::string* error) const;  // alpha in (0, 1), positive weights
};

struct ChannelOrderReport : MiswiringScores {
  ChannelMapping best;      // the best other mapping when likely_miswired
  bool on_windows = false;  // scored on windows of the ground-truth track, not final poses
};

// Whether `mapping` drives the body at the nominal as the recorded order does with the body turned
// 180 deg: every step (dx, dy, dtheta) of the runs becomes (-dx, -dy, dtheta) (a differential
// drive's wheels swapped and both negated, a tricycle's traction and steering negated). Such a
// mapping explains a ground truth whose frame faces backwards exactly as well as the true wiring.
bool TurnsTheBodyHalfway(const RobotModelInterface& model, const ChannelMapping& mapping,
                         const std::vector<AlignedRun>& runs);

// segments: empty for the final-pose test, else one window list per run (segment test).
ChannelOrderReport CheckChannelOrder(const std::vector<AlignedRun>& runs,
                                     const std::vector<std::vector<Segment>>& segments,
                                     const RobotModelInterface& model,
                                     const ChannelOrderOptions& options = {});

// The check of recorded runs against their ground truth, as the importers run it: on the final
// poses (a slow drift the windows' noise hides shows at the end of a long run) and on disjoint
// windows of 0.5 m of ground-truth path when the ground truth has poses between the ends (at
// least 4 windows; closed paths hide some miswirings from final poses, and the windows name the
// mapping when both tests find one). Each test keeps its false-alarm probability, so the pair has
// at most twice it. Where the runs carry several trajectory labels (sessions) and the pool passes,
// each session is checked alone at alpha / sessions: a miswiring in one session hides in the
// pool. tracks[i] is the ground truth of runs[i]. Used by the importers, `fit` and `diagnose`.
ChannelOrderReport CheckRecordedChannelOrder(const std::vector<AlignedRun>& runs,
                                             const std::vector<const GroundTruthTrack*>& tracks,
                                             const RobotModelInterface& model,
                                             const ChannelOrderOptions& options = {});

}  // namespace fitcal
