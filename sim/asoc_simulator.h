#pragma once
// Simulated runs of an ASOC vehicle (Doebbler Sec. IV). The model:
//
// - The body follows a sequence of segments, each a body-frame twist (vx, vy, omega of the body
//   origin) scaled by the smooth profile 1 - cos(2 pi t / T) (rest to rest, mean 1), so a segment
//   moves the body by exactly its mean twist times its duration.
// - Castor dynamics: each castor turns so that its pivot moves as the body dictates, with no
//   lateral slip: chi_dot_i = (v_pivot . c2) / r_c (asoc_model.h). The wheels turn as the true
//   parameters require (WheelRatesFromPivotMotion). Integrated with RK4 at
//   sample_period_s / substeps.
// - Encoders as on the prototype (Doebbler Sec. V): cumulative wheel angles counted in
//   wheel_quantum_rad (0.3 deg) steps, pivot angles gamma = theta + beta read by an absolute
//   encoder in pivot_quantum_rad (0.07 deg) steps, sampled every sample_period_s (20 Hz).
// - Non-systematic errors (off by default): each wheel encoder increment is scaled by
//   (1 + N(0, wheel_slip_sigma)) per sample (floor roughness, small slips), and SlipEvents make a
//   chosen wheel's encoder over-count by a fraction over a time window (a spinning wheel).
// - Ground truth: the true body pose at every sample (+ optional white noise).
//
// Manoeuvres: the UMBmark square (Borenstein; Doebbler Sec. IV-B) and the calibration manoeuvre of
// Sec. III-A (hold one castor, rotate the body about its pivot CW or CCW).

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "models/asoc/asoc_model.h"
#include "models/asoc/asoc_odometry.h"
#include "models/asoc/asoc_run_log.h"

namespace fitcal::sim {

// The simulated prototype's nominal geometry. Doebbler do not print their dimensions; these are
// plausible one-third-scale values (pivots on a 0.30 m circle, D = 0.52 m, castor offset 0.08 m,
// wheel radius 0.04 m, half axle 0.06 m), stated here and in the README.
asoc::Vehicle AsocPrototypeVehicle();

struct Segment {
  double duration_s = 1.0;
  double vx_m_s = 0.0;  // mean body-frame velocity of the body origin
  double vy_m_s = 0.0;
  double omega_rad_s = 0.0;
};

struct SlipEvent {
  int castor = 0;  // 0-based
  int wheel = 0;   // 0 = wheel 1 ("a"), 1 = wheel 2 ("b")
  double t_begin_s = 0.0;
  double t_end_s = 0.0;
  double extra_fraction = 0.0;  // the encoder counts (1 + extra) times the wheel's rolling
};

struct AsocSimulationOptions {
  double sample_period_s = 0.05;  // 20 Hz (Doebbler Sec. IV-B)
  int substeps = 10;
  double wheel_quantum_rad = 0.3 * M_PI / 180.0;
  double pivot_quantum_rad = 0.07 * M_PI / 180.0;
  double wheel_slip_sigma = 0.0;
  std::vector<SlipEvent> slip_events;
  double gt_position_sigma_m = 0.0;
  double gt_heading_sigma_rad = 0.0;

  bool IsValid(std::string* error) const;
};

// Body-relative castor angles theta_i at which every castor trails its pivot in steady state for
// a body twist (the castors are aligned before a manoeuvre, Doebbler Sec. III-A); a castor whose
// pivot does not move keeps `rest_angle_rad`.
std::array<double, asoc::kNumCastors> SteadyCastorAngles(const asoc::Vehicle& truth,
                                                         const Segment& twist,
                                                         double rest_angle_rad = 0.0);

// Simulates one run from `start` with castor angles theta0 (body-relative, true). `rng` drives
// the non-systematic noise only.
asoc::RunLog SimulateAsocRun(const asoc::Vehicle& truth, const std::vector<Segment>& segments,
                             const Pose2d& start,
                             const std::array<double, asoc::kNumCastors>& theta0,
                             const AsocSimulationOptions& options, std::mt19937_64& rng);

// One UMBmark circuit: four legs of side_m driven forward at mean speed_m_s, each followed by a
// 90 deg turn in place at mean turn_rate_rad_s; direction +1 = CCW (left turns), -1 = CW.
std::vector<Segment> UmbmarkSquare(int direction, double side_m = 1.5, double speed_m_s = 0.3,
                                   double turn_rate_rad_s = 0.5);

// The calibration manoeuvre: rotate the body by angle_rad about the pivot of castor `held`
// (0-based) at mean rate rate_rad_s; direction +1 = CCW, -1 = CW.
std::vector<Segment> RotationAboutPivot(const asoc::Vehicle& nominal, int held, int direction,
                                        double angle_rad = 1.5 * M_PI, double rate_rad_s = 0.4);

// The six calibration runs (hold castor 1, 2, 3; CW then CCW), castors pre-aligned. Trajectory
// labels "hold_<i>_cw" / "hold_<i>_ccw" (1-based), which asoc_geometric.h reads.
std::vector<asoc::RunLog> SimulateCalibrationManoeuvre(const asoc::Vehicle& truth,
                                                       const AsocSimulationOptions& options,
                                                       std::mt19937_64& rng,
                                                       double angle_rad = 1.5 * M_PI);

// UMBmark runs: `repetitions` circuits CW (trajectory "umbmark_cw") and as many CCW
// ("umbmark_ccw"), each from the origin with the castors aligned for the first leg.
std::vector<asoc::RunLog> SimulateUmbmark(const asoc::Vehicle& truth,
                                          const AsocSimulationOptions& options,
                                          std::mt19937_64& rng, int repetitions = 5);

// A run of `num_segments` random holonomic moves (translation up to 0.4 m/s in any direction,
// rotation up to 0.6 rad/s): excitation for a final-pose fit of all parameters.
asoc::RunLog SimulateRandomExcursion(const asoc::Vehicle& truth,
                                     const AsocSimulationOptions& options, std::mt19937_64& rng,
                                     int num_segments = 8);

// Draws a vehicle around `nominal` as Doebbler Table I: every r_c, r_w, d scaled by
// (1 + U(-f, f)) with its own f, beta uniform in +-beta_range_rad. Pivot layout unchanged.
struct ParameterSpread {
  double offset_fraction = 0.0042;               // twice Table I's 0.21 % mean absolute error
  double wheel_radius_fraction = 0.0414;         // twice 2.07 %
  double wheel_offset_fraction = 0.0178;         // twice 0.89 %
  double bias_range_rad = 15.96 * M_PI / 180.0;  // twice 7.98 deg
};
asoc::Vehicle DrawVehicle(const asoc::Vehicle& nominal, const ParameterSpread& spread,
                          std::mt19937_64& rng);

// UMBmark E_max (Borenstein; Doebbler Sec. IV-B): for each direction the distance of the mean of
// the runs' final position errors (odometry - truth) from zero; E_max the larger of the two.
struct UmbmarkResult {
  double r_cw_m = 0.0;
  double r_ccw_m = 0.0;
  double e_max_m = 0.0;
};
UmbmarkResult EvaluateUmbmark(const std::vector<asoc::RunLog>& runs, const asoc::Vehicle& estimate,
                              const asoc::OdometryOptions& odometry);

}  // namespace fitcal::sim
