#pragma once
// The track residual of one run: the odometry's pose relative to the run's start at checkpoints
// along the ground-truth path, against the ground truth's, with the ground-truth clock shifted by
// an estimated offset. It is OptiOdom's cost (Sousa et al., J. Intell. Robot. Syst. 2022: the
// position from the run's start every 0.5 m of path and at the end, fit/segment_cost.h
// MakeCheckpointsFromStart) with the heading added as in Palacin Eq. 14, one clock offset per
// session, a robust loss per checkpoint and a weight per run.
//
// For checkpoint k at encoder time t_k (the run starts at t_0), with the odometry replayed from
// the identity, P_k = P_0^-1 P_k (Palacin Eq. 4), and the ground truth interpolated at t + dt,
//   Q_k(dt) = Q(t_0 + dt)^-1 Q(t_k + dt),
//   e_k = [ R(-theta_Qk) (t_Pk - t_Qk) / sigma_xy,  wrap(theta_Pk - theta_Qk) / sigma_th ]
// (the segment error of models/pose_errors.h with the window [0, k]), and the residual is
//   r_k = w sqrt(rho(|e_k|^2) / |e_k|^2) e_k,  w = 1 / sqrt(K),
// so |r_k|^2 = w^2 rho(|e_k|^2) exactly: each run adds the mean over its K checkpoints of the
// Huber loss rho(s) = s below c^2, 2 c sqrt(s) - c^2 above (Ceres' convention). A run of 40 m
// weighs what a run of 4 m does; a ground-truth glitch at one checkpoint grows the cost linearly.
//
// The ground truth at t + dt is interpolated linearly between its samples, as everywhere else.
// Its derivative in dt is piecewise constant (the sample interval's velocity) and the cost has a
// kink wherever a checkpoint crosses a sample - on a synchronised file (OptiOdom), where the
// ground truth is sampled at the encoder times the checkpoints lie on, every checkpoint at once.
// FitModel therefore does not let Gauss-Newton step in dt: it estimates the offsets by turns with
// the parameters, each offset by a search on this exact cost (fit/model_fit.cc).
//
// Why the clock offset: the encoders and the ground truth are on different clocks (OptiOdom's
// are mapped by hand-picked instants); a lag dt moves each checkpoint by |v| dt. The final pose,
// at rest, does not see it; the track does. dt is one more parameter block, bounded, shared by
// the runs of one session.
//
// Derivatives are exact: the model's own autodiff through the replay (its SegmentCost on windows
// [0, k] with an identity ground truth gives P_k and dP_k/dp), chained with Jets through the
// error, the interpolation in time and the loss.

#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/run_log.h"

namespace fitcal {

// The heading term of checkpoint k: the heading from the run's start (theta_Pk - theta_Qk, as
// Palacin Eq. 14 at every checkpoint), or its increment over the last checkpoint spacing
// ((theta_Pk - theta_Pk-1) - (theta_Qk - theta_Qk-1); k = 0 against the start), which counts each
// stretch's heading error once instead of carrying it into every later checkpoint.
enum class TrackHeading { kFromStart, kIncrements };
const char* ToString(TrackHeading heading);  // "from-start", "increments"
bool ParseTrackHeading(const std::string& text, TrackHeading* out);

struct TrackResidualOptions {
  double checkpoint_spacing_m = 0.5;  // OptiOdom's
  TrackHeading heading = TrackHeading::kFromStart;
  double huber_scale = 0.1;           // c, residual units (m and rad): a few times a clean error
  bool IsValid(std::string* error) const;
};

// One run prepared for the track residual: checkpoint sample counts and their encoder times.
struct TrackCheckpoints {
  const AlignedRun* run = nullptr;                 // must outlive the cost
  const GroundTruthTrack* ground_truth = nullptr;  // must outlive the cost
  std::vector<Segment> segments;  // windows [0, end_k] with the ground truth at dt = 0
  std::vector<double> t_s;        // encoder time of each checkpoint
  double t_start_s = 0.0;
  int clock_group = 0;  // index of the run's clock offset
};

// How runs share clock offsets: one per session (runs recorded together; the run's trajectory
// label, which `import optiodom` sets to the session), one per run, one for the whole data set (a
// latency common to every recording), or none (held at 0).
enum class ClockGrouping { kPerSession, kPerRun, kDataset, kNone };
const char* ToString(ClockGrouping grouping);  // "session", "run", "dataset", "none"
bool ParseClockGrouping(const std::string& text, ClockGrouping* out);

// The clock group a run belongs to under `grouping`: its trajectory label (session), its id
// (run), or "all" (dataset, and none).
std::string ClockGroupOf(const std::string& run_id, const std::string& trajectory,
                         ClockGrouping grouping);

// The runs' clock groups under `grouping`: the groups' names in the order of their first run, and
// each run's index into them.
struct RunGroups {
  std::vector<std::string> names;
  std::vector<int> of_run;
};
RunGroups GroupRuns(const std::vector<AlignedRun>& runs, ClockGrouping grouping);

// Applies clock offsets to recorded runs: every ground-truth stamp of a run whose clock group
// (ClockGroupOf) has an offset dt moves to t - dt, so that the ground truth read at encoder time
// t is the one stamped t + dt (the offsets' meaning, header): the values the track residual
// interpolates at t + dt. Returns how many runs moved.
int ShiftGroundTruthClocks(const std::vector<std::pair<std::string, double>>& offset_of_group,
                           ClockGrouping grouping, std::vector<RunLog>* logs);

// The training runs' tracks for the track residuals: one TrackCheckpoints per training run (same
// order), each naming its clock group (0 .. clock_groups.size() - 1).
struct TrackFitData {
  std::vector<TrackCheckpoints> runs;
  std::vector<std::string> clock_groups;  // names: the session or the run
  bool estimate_clock_offsets = true;     // false: every offset held at 0
  TrackResidualOptions options;
};

// ground_truth[i] is runs[i]'s track (both must outlive the result).
TrackFitData MakeTrackFitData(const std::vector<AlignedRun>& runs,
                              const std::vector<const GroundTruthTrack*>& ground_truth,
                              ClockGrouping grouping, const TrackResidualOptions& options = {});

// Checkpoints every options.checkpoint_spacing_m of ground-truth path and at the end.
TrackCheckpoints MakeTrackCheckpoints(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                                      const TrackResidualOptions& options);

// The ground truth's pose at t_k + dt relative to its pose at t_0 + dt (Q_k(dt) above), on
// double: for metrics and tests.
Pose2d GroundTruthFromStart(const TrackCheckpoints& track, std::size_t k, double dt_s);

// The odometry's poses from one run's start (TrackResidual's inner cost: the replay, most of a
// track fit's CPU) at the last parameters they were computed for, with and without dP/dp, kept
// across the Ceres problems of one fit. Why: a fit with clock offsets solves by turns
// (fit/model_fit.cc), and each turn starts a new problem at the parameters the last one ended
// at with only the offsets moved, which the odometry does not depend on; the offsets' search
// replays the same runs at those parameters again. A request of the same kind (with or without
// the Jacobian) at bitwise the same parameters is answered with a copy of what the cost computed
// there, so every fit takes the same steps to the bit. A request without the Jacobian is also
// answered from one with it where the model's poses are the same either way
// (RobotModelInterface::SegmentResidualsAlikeWithJacobians): Ceres' bounded trust region
// evaluates the Jacobian at each candidate point in its line search, then the cost alone at the
// same point (2.1, trust_region_minimizer.cc), and the offsets' search replays the point a solve
// ended at. One per run, used by one thread at a time.
class OdometryMemo {
 public:
  // Copies the poses (and dP/dp when `jacobian` is not null) kept for `p` of this kind, or, with
  // `values_alike` and no `jacobian`, the poses of an evaluation with dP/dp there.
  bool Recall(const double* p, int num_parameters, double* pose, int num_poses,
              double* jacobian, bool values_alike = false);
  void Keep(const double* p, int num_parameters, const double* pose, int num_poses,
            const double* jacobian);
  // How many requests were answered from the memo (tests).
  int recalled() const { return recalled_; }

 private:
  struct Kept {
    std::vector<double> p, pose, jacobian;
  };
  std::optional<Kept> values_, with_jacobian_;
  int recalled_ = 0;
};

class TrackResidual : public ceres::CostFunction {
 public:
  // Parameter blocks: the model's parameters, then the run's clock offset dt (1 value, seconds).
  // `memo` (may be null) answers the odometry's repeated evaluations; it must outlive the cost.
  static ceres::CostFunction* Create(const TrackCheckpoints& track,
                                     const RobotModelInterface& model,
                                     const ResidualWeights& weights,
                                     const TrackResidualOptions& options,
                                     OdometryMemo* memo = nullptr);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The same residuals in two steps, for a search over dt with the parameters held (the replay
  // does not depend on dt): the odometry's pose at every checkpoint from the run's start (3
  // values each; HUGE_VAL when the replay fails), then |r|^2 for those poses at dt.
  std::vector<double> OdometryFromStart(const double* p) const;
  double SquaredNormAt(const std::vector<double>& pose_from_start, double dt_s) const;

 private:
  // Jet dimensions: the odometry pose (x, y, theta), the clock offset, and the odometry's heading
  // at the checkpoint before (TrackHeading::kIncrements).
  // On double where no derivative is wanted (the search over dt): the same values.
  using ErrorJet = ceres::Jet<double, 5>;
  template <typename T>
  std::vector<Pose2<T>> GroundTruthFromStartAt(double dt_s) const;
  template <typename T>
  std::array<T, 3> CheckpointResidual(const std::vector<double>& pose, int k,
                                      const std::vector<Pose2<T>>& ground_truth) const;

  TrackResidual(const TrackCheckpoints& track, const RobotModelInterface& model,
                const ResidualWeights& weights, const TrackResidualOptions& options,
                OdometryMemo* memo);

  // The odometry's poses (and dP/dp into `jacobian` when not null), from the memo when it has
  // them; false when the replay fails.
  bool EvaluateOdometry(const double* p, double* pose, double* jacobian) const;

  const TrackCheckpoints& track_;
  std::unique_ptr<ceres::CostFunction> odometry_;  // P_k and dP_k/dp: 3 values per checkpoint
  std::vector<Segment> from_start_;                // windows [0, k] with an identity ground truth
  ResidualWeights weights_;
  double huber_scale_;
  TrackHeading heading_;
  double run_weight_;  // 1 / sqrt(K)
  int num_parameters_;
  bool values_alike_;  // model.SegmentResidualsAlikeWithJacobians()
  OdometryMemo* memo_;
};

}  // namespace fitcal
