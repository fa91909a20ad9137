#pragma once
// The closed-form geometric calibration of an ASOC vehicle, Doebbler Sec. III-A, Eq. 1-9, from
// internal sensors only. The manoeuvre: hold castor j still and drive the others so the body
// rotates about pivot j, once clockwise and once counter-clockwise. For every active castor i:
//   gamma_cw, gamma_ccw  its pivot encoder reading during the CW / CCW rotation (steady state),
//   c_cw1..c_ccw2        the angles its wheels turned,
//   dtheta_cw, dtheta_ccw the angle pivot j's encoder turned (the body's rotation, > 0).
// With D = |p_i - p_j| known (the pivot layout is known geometry):
//   Gamma = (180 deg - (gamma_ccw - gamma_cw)) / 2                           Eq. 1
//   beta  = (gamma_ccw + gamma_cw - 180 deg) / 2 - theta_perp                Eq. 2
//   r_c   = D sin Gamma                                                      Eq. 3
//   r_wk  = 2 D cos Gamma dth_ccw dth_cw / (dth_ccw c_cwk + dth_cw c_ccwk)   Eq. 8
//   d_k   = s_k D cos Gamma (dth_ccw c_cwk - dth_cw c_ccwk) / (same)         Eq. 9, s = (+1, -1)
// where theta_perp, the castor angle aligned with the CW direction of travel, is the body angle of
// (p_i - p_j) minus 90 deg (the CW velocity of pivot i). Holding each of the three castors in turn
// gives two estimates per castor; they are averaged (beta on the circle).
//
// Runs are found by trajectory label "hold_<j>_cw" / "hold_<j>_ccw" (j 1-based); the steady
// castor angle is read over the middle of the run (kSteadyFraction), which skips start/stop
// transients when the castors were not pre-aligned.
//
// Uncertainty: the estimates of castor i with castor j held and with castor k held come from
// different runs, so their spread measures what the encoders' quantisation and noise do to
// Eq. 1-9 (mostly the pivot readings for r_c and beta, Eq. 2-3). Each parameter's variance is
// pooled over the three castors and widened by Student's t for its few degrees of freedom, and
// the variance the pivot encoders' step propagates through Eq. 1-9 is added: quantised readings
// of two hold runs often agree exactly, and their spread is then 0 although each is off by up to
// half a step (SpreadSigmas, QuantisationVariance in the .cc); checked against the simulator's
// truth in docs/asoc.md.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "models/asoc/asoc_model.h"
#include "odometry/encoder_samples.h"
#include "odometry/run_log.h"

namespace fitcal::asoc {

// The measurements Eq. 1-9 use for one (active castor i, held castor j) pair.
struct HoldMeasurement {
  double gamma_cw_rad = 0.0;
  double gamma_ccw_rad = 0.0;
  std::array<double, 2> wheel_cw_rad{};
  std::array<double, 2> wheel_ccw_rad{};
  double rotation_cw_rad = 0.0;   // dtheta_cw, magnitude
  double rotation_ccw_rad = 0.0;  // dtheta_ccw, magnitude
};

// Eq. 1-9 for one pair: D the pivot distance, theta_perp as above.
CastorParameters SolveHoldPair(const HoldMeasurement& m, double pivot_distance_m,
                               double theta_perp_rad);

// What one hold run contributes (measured from the encoders only, from either kind of log).
struct HoldRun {
  int held = 0;               // 0-based castor held still
  int direction = 0;          // -1 CW, +1 CCW (from the label)
  double rotation_rad = 0.0;  // the held castor's pivot encoder turn, unwrapped, signed
  std::array<double, kNumCastors> steady_gamma_rad{};          // per castor, circular mean
  std::array<std::array<double, 2>, kNumCastors> wheel_rad{};  // angle each wheel turned
};

inline constexpr double kSteadyFraction = 0.5;
// A hold run's Eq. 1-9 measurements from the model's channels, when `trajectory` names one and it
// has at least 4 intervals: steady angles as the circular mean over the middle kSteadyFraction of
// the intervals, the held pivot's turn from the interval means (mid first to mid last interval)
// and each wheel's angle over the same span.
std::optional<HoldRun> MeasureHoldRun(const std::string& trajectory,
                                      const EncoderSamples& samples);

struct GeometricResult {
  bool usable = false;
  std::string message;  // why not usable, or a summary
  Vehicle estimate;     // nominal pivot layout + the calibrated castors
  // Per castor: how many pair estimates were averaged.
  std::array<int, kNumCastors> num_estimates{};
  // Per castor, the 1-sigma uncertainty of every estimated parameter from the spread of its pair
  // estimates over runs (the two estimates of one castor should agree to quantisation level), with
  // sigma_dof degrees of freedom; sigma_dof 0: no castor has two independent estimates, and the
  // sigmas are 0 (unknown, not exact).
  std::array<CastorParameters, kNumCastors> sigma{};
  int sigma_dof = 0;
};

// Eq. 1-9 on every CW x CCW pair of hold runs of each held castor, averaged per castor. Castors
// without any usable hold pair keep their nominal parameters and make the result unusable.
GeometricResult CalibrateFromHoldRuns(const std::vector<HoldRun>& runs, const Vehicle& nominal,
                                      double pivot_resolution_rad = 0.0);

// The hold runs among `runs` (MeasureHoldRun on the model's channels) through
// CalibrateFromHoldRuns.
GeometricResult CalibrateGeometric(const std::vector<fitcal::RunLog>& runs, const Vehicle& nominal,
                                   double pivot_resolution_rad = 0.0);

}  // namespace fitcal::asoc
