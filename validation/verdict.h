#pragma once
// The answer to "is my calibration fine?": PASS, WARN or FAIL with the reasons, from numbers the
// report has already measured on held-out runs. Pure logic (no files, no solver), so that each
// rule can be tested on crafted cases (tests/report_verdict_test.cc).
//
// The checks, each with the report section it links to:
//   convergence      the recorded solver termination: NO_CONVERGENCE -> WARN,
//                    FAILURE -> FAIL; not recorded (a plain robot YAML) -> no finding.
//   bounds           a calibrated parameter resting on a bound of the robot's box -> WARN (the
//                    box, not the data, decided it: its sigma describes the unconstrained problem).
//   improvement      the held-out CF (Palacin Eq. 14) over all validation runs: not lower than the
//                    nominal's -> FAIL (the calibration does not help on data it did not see).
//   regressions      any trajectory group or single trajectory whose mean held-out CF or mean final
//                    position error is more than kRegressionTolerance (5 %) larger with the
//                    calibration than with the nominal -> WARN.
//   generalisation   held-out CF more than kGapFactor times the training CF the calibration
//                    recorded -> WARN (it fits its training runs much better than new ones).
//   noise floor      the systematic part of the final position errors (the mean per trajectory)
//                    is significant against the repeatability of the repetitions (F test,
//                    p < kNoiseFloorAlpha) and larger than one run's noise -> WARN: the model
//                    lacks an effect (`fitcal diagnose`).
//   identifiability  the training runs do not determine every parameter, or two parameters
//                    correlate beyond 0.99, or the condition number exceeds 1000 -> WARN.
// A check without the data to run on (no trajectory with two validation runs for the noise
// floor) is SKIP, with the reason.

#include <string>
#include <vector>

namespace fitcal {

// kSkip: a check that could not run on these data (said so, never counted as a pass); it does not
// change the overall level, which is the worst of the checks that ran.
enum class VerdictLevel { kSkip = -1, kPass = 0, kWarn = 1, kFail = 2 };
const char* ToString(VerdictLevel level);  // "SKIP", "PASS", "WARN", "FAIL"

// Held-out numbers of one group of runs (a trajectory family, one trajectory, or all runs).
struct GroupOutcome {
  std::string name;
  int runs = 0;
  double cf_before = 0.0, cf_after = 0.0;  // Eq. 14, mean over the group's runs
  double final_position_before_m = 0.0, final_position_after_m = 0.0;
};

// The repeatability test of the final position errors after calibration (validation runs).
struct NoiseFloorTest {
  bool available = false;         // needs a trajectory with two or more validation runs
  double noise_sigma_m = 0.0;     // per axis, pooled within-trajectory standard deviation
  double systematic_rms_m = 0.0;  // RMS over runs of their trajectory's mean error vector
  double f_statistic = 0.0;
  double p_value = 1.0;
  int trajectories = 0;
};

// Final position error vectors (start frame, m) of the validation runs after calibration, each
// with its trajectory label: the F test of NoiseFloorTest.
struct FinalErrorSample {
  std::string trajectory;
  double ex_m = 0.0, ey_m = 0.0;
};
NoiseFloorTest TestAgainstNoiseFloor(const std::vector<FinalErrorSample>& errors);

struct VerdictInputs {
  std::string termination;                 // empty = not recorded
  std::vector<std::string> at_bound;       // parameter names
  GroupOutcome overall;                    // all validation runs
  std::vector<GroupOutcome> families;      // Table 6 groups (may be empty)
  std::vector<GroupOutcome> trajectories;  // one per trajectory label
  bool has_training_cf = false;            // recorded by the calibration
  double training_cf_after = 0.0;
  NoiseFloorTest noise_floor;
  bool identifiability_checked = false;  // training runs in this data set
  bool identifiable = true;
  // No drift window fits in any held-out run (an empty table said nothing): the longest run's
  // ground-truth path, said in the SKIP.
  bool drift_measured = true;
  double longest_path_m = 0.0;
};

struct VerdictReason {
  VerdictLevel level = VerdictLevel::kPass;
  std::string check;    // "convergence", "bounds", ... (machine-readable)
  std::string section;  // the report section it refers to (HTML anchor)
  std::string message;  // one sentence for people
};

struct Verdict {
  VerdictLevel level = VerdictLevel::kPass;
  std::vector<VerdictReason> reasons;  // every check made, worst first; PASS ones too
};

// Held-out CF above this multiple of the training CF is a generalisation gap. Measured by the
// training CF, a fit that models the robot leaves the same noise on new runs of the same kind
// (expected ratio 1 + p / (3 N) for p parameters and N runs, ~1.05 for the flower); twice is far
// outside that and still below the 3-8x seen when trained on one path type and used on another.
constexpr double kGapFactor = 2.0;
// A group is worse when its mean CF or final position error grows by more than this fraction.
constexpr double kRegressionTolerance = 0.05;
// Significance of the noise-floor F test (one false alarm in a thousand calibrations).
constexpr double kNoiseFloorAlpha = 1e-3;

Verdict JudgeCalibration(const VerdictInputs& inputs);

}  // namespace fitcal
