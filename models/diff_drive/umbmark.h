#pragma once
// UMBmark: J. Borenstein, L. Feng, "Measurement and correction of systematic odometry errors in
// mobile robots", IEEE Trans. Robot. Autom. 12(6), 1996. A differential drive drives a square of
// side L clockwise (CW) and counter-clockwise (CCW); the return-position errors separate the
// two dominant systematic errors, and a closed form corrects them:
//
//   Type A, alpha: the wheel separation is wrong; every nominal 90 deg corner really turns
//                  90 deg - alpha (alpha > 0: the robot under-turns, the true separation is
//                  larger than the odometry's, relative to the mean wheel radius).
//   Type B, beta:  the wheel radii are unequal; every nominally straight leg really curves by
//                  beta (beta > 0: counter-clockwise, the right wheel is the larger one).
//
// Conventions (ours, and they reproduce the paper's equations): x along the first leg (the
// robot's heading at the start), y to its left; the error of a run is where the robot really is
// minus where odometry with the nominal parameters says it is, both at the end, in that start
// frame: e = R(-theta_0) (p_ground_truth - p_odometry).
//
// Derivation (first order in alpha, beta). Leg i (i = 0..3) nominally heads psi_i = +-i 90 deg
// (+ CCW, - CW); its true heading error at its start is delta_i, it curves by beta along the leg,
// so its displacement is L u(psi_i) + L (delta_i + beta / 2) n(psi_i) with n the left normal. A
// CCW corner turns -alpha too little in the CCW sense, a CW corner +alpha, so delta_i = i (beta -
// alpha) (CCW) and delta_i = i (beta + alpha) (CW). Summing the four legs:
//   CW:  x_cw  = -2 L (alpha + beta),  y_cw  = -2 L (alpha + beta)
//   CCW: x_ccw = -2 L (alpha - beta),  y_ccw = +2 L (alpha - beta)
// hence the paper's Eq. (9)-(10) (their centres of gravity of n runs per direction):
//   alpha = (x_cw + x_ccw) / (-4 L) = (y_cw - y_ccw) / (-4 L)
//   beta  = (x_cw - x_ccw) / (-4 L) = (y_cw + y_ccw) / (-4 L)
// We take the least-squares solution of the four equations, which is the mean of the x and y
// estimates. The corrections (the paper's Eq. 11-18):
//   R   = (L / 2) / sin(beta / 2)           radius of the curved legs
//   E_d = (R + b / 2) / (R - b / 2)         = D_R / D_L, the true diameter ratio
//   E_b = 90 deg / (90 deg - alpha)         = b_true / b_nominal
//   b'  = E_b b,  D_L' = 2 D_a / (E_d + 1),  D_R' = 2 D_a / (1 / E_d + 1),  D_a = (D_R + D_L) / 2
// With unequal nominal radii the ratio applies on top of them: r_R' / r_L' = E_d r_R / r_L,
// keeping r_R + r_L (for equal nominal radii this is exactly the paper's D_R', D_L').
//
// What the method cannot see: the mean wheel radius (a scaled square still closes; it is kept),
// and the errors are linearised: second-order terms in alpha and beta remain (the corrected
// robot still errs by ~ (alpha^2 + beta^2) L per square).
//
// Runs of different sides L_i can be mixed: the errors are linear in alpha (per corner, not
// scaling with L) and in the legs' curvature kappa = beta / L, and the weighted least squares
// over every run (each direction weighing as much as the other, as the paper's centres of
// gravity do) gives alpha and kappa; beta = kappa L_ref with L_ref the mean side. With one side
// and equal counts per direction this is exactly the formulas above on the centres of gravity.

#include <optional>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal::umbmark {

// One square run's return-position error (ground truth minus odometry, start frame, see above).
struct SquareReturnError {
  bool clockwise = false;
  double side_m = 0.0;
  double x_m = 0.0;
  double y_m = 0.0;
};

// The nominal differential drive.
struct DiffDriveGeometry {
  double r_right_m = 0.0;
  double r_left_m = 0.0;
  double separation_m = 0.0;
};

struct Correction {
  double alpha_rad = 0.0;  // Type A, per corner
  double beta_rad = 0.0;   // Type B, per leg of side side_m
  double side_m = 0.0;     // L_ref
  double e_d = 1.0;        // D_R / D_L
  double e_b = 1.0;        // b_true / b_nominal
  int num_cw = 0;
  int num_ccw = 0;
  DiffDriveGeometry corrected;
};

// The closed form from the squares' errors; nullopt without at least one CW and one CCW run, or
// when the errors are too large for the closed form (|alpha| >= 90 deg, |R| <= b / 2).
std::optional<Correction> Correct(const std::vector<SquareReturnError>& runs,
                                  const DiffDriveGeometry& nominal);

// Measures one run as a UMBmark square from its odometry with parameters p: the turning
// direction from the sign of the total heading change, which must be one lap (|change| in
// [1.25 pi, 2.5 pi]: three or four corners); the side L from the odometry's path length (a
// quarter of it); the path must close (odometry ends within L / 4 of its start). nullopt for a
// run that is not such a square.
std::optional<SquareReturnError> MeasureSquare(const RobotModelInterface& model,
                                               const std::vector<double>& p, const AlignedRun& run);

}  // namespace fitcal::umbmark
