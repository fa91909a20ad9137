#pragma once
// What an ASOC vehicle offers beyond the seam (models/model_extras.h): its calibration scenario on
// the one simulator (sim/model_simulator.h), recorded as the paper's prototype, the castor
// dynamics the simulator integrates, the closed form of Eq. 1-9 and the reproduction of Tables I
// and II (asoc_tables.h).
//
// Castor dynamics (Doebbler Sec. II, no lateral slip): each castor turns so that its pivot moves
// with no lateral slip of its wheels, chi_dot_i = (v_pivot_i . c2_i) / r_c (asoc_model.h), i.e.
// in the body frame theta_dot_i = (v_pivot_i . c2_i) / r_c - omega; the wheels turn as the true
// parameters require (WheelRatesFromPivotMotion). RK4 over each half of every fine step. The pivot
// encoders read gamma_i = theta_i + beta_i in steps of the robot's pivot_resolution_deg (an
// absolute encoder; the recorded readings are unwrapped, as ASOC's own files are on load).
//
// Scenario, per data set: the calibration manoeuvre of Sec. III-A (repetition 1), the UMBmark
// square (Sec. IV-B) as repetitions 6-10, each at its own speed so that no two are one recording
// copied, and `repetitions` random excursions (1..N, the fit's training data; 5 by default);
// below. Castors are aligned for the first segment before a run starts. Recorded as the
// prototype (PrototypeRecorder).
//
// The true robot (default_truth): drawn about the nominal as Doebbler Table I (ParameterSpread)
// from std::mt19937_64(SplitMix(seed)), the draw of ASOC's own simulator before the one simulator.

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "models/asoc/asoc_model.h"
#include "models/model_extras.h"
#include "odometry/split_mix.h"

namespace fitcal {

ModelExtras AsocExtras();

namespace asoc {

// The simulated prototype's encoders (Doebbler Sec. IV-B, V): 20 Hz, wheel angles counted in
// 0.3 deg steps, pivot angles read in 0.07 deg steps (kAsocExampleYaml's pivot_resolution_deg).
inline constexpr double kPrototypeSamplePeriodS = 0.05;
inline constexpr double kPrototypeWheelTicksPerRev = 1200.0;
inline constexpr double kPrototypePivotQuantumRad = 0.07 * M_PI / 180.0;

// The prototype's recorder: the encoders above, noise-free ground truth at every encoder time,
// every run from the origin at a random heading, no wheel noise unless a caller sets
// wheel_relative_sigma (a relative error on each 20 Hz wheel increment).
ScenarioRecorder PrototypeRecorder();

// Draws a vehicle around `nominal` as Doebbler Table I: every r_c, r_w, d scaled by
// (1 + U(-f, f)) with its own f, beta uniform in +-beta_range_rad. Pivot layout unchanged.
struct ParameterSpread {
  double offset_fraction = 0.0042;               // twice Table I's 0.21 % mean absolute error
  double wheel_radius_fraction = 0.0414;         // twice 2.07 %
  double wheel_offset_fraction = 0.0178;         // twice 0.89 %
  double bias_range_rad = 15.96 * M_PI / 180.0;  // twice 7.98 deg
};
Vehicle DrawVehicle(const Vehicle& nominal, const ParameterSpread& spread, std::mt19937_64& rng);

// Body-relative castor angles theta_i at which every castor trails its pivot in steady state for
// a body twist; a castor whose pivot does not move keeps `rest_angle_rad`.
std::array<double, kNumCastors> SteadyCastorAngles(const Vehicle& truth, const Twist& twist,
                                                   double rest_angle_rad = 0.0);

// The castor dynamics of the header from body-relative castor angles theta0; pivot readings in
// steps of pivot_quantum_rad (0: exact).
std::unique_ptr<ChannelDynamics> MakeCastorDynamics(const Vehicle& truth,
                                                    const std::array<double, kNumCastors>& theta0,
                                                    double pivot_quantum_rad);

// The six hold runs of the calibration manoeuvre (rotation 1.5 pi at 0.4 rad/s about each pivot
// of `nominal`, CW then CCW), repetition 1.
std::vector<sim::TrajectorySpec> HoldTrajectories(const Vehicle& nominal);
// `per_direction` UMBmark circuits CW, then as many CCW, repetitions first_repetition.. (1.5 m
// sides; repetition k drives at 0.3 (1 + 0.02 (k - first)) m/s, turns at 0.5 rad/s).
std::vector<sim::TrajectorySpec> UmbmarkTrajectories(int per_direction, int first_repetition);
// `num_segments` random holonomic moves (translation up to 0.4 m/s in any direction, rotation up
// to 0.6 rad/s, 2-5 s each) drawn from the repetition: excitation for a final-pose fit.
sim::TrajectorySpec ExcursionTrajectory(int repetition, int num_segments = 8);

}  // namespace asoc
}  // namespace fitcal
