#pragma once
// Multi-castor odometry of an ASOC vehicle, Doebbler Sec. III-B:
//   - every update, each castor's pivot displacement (dx_i, dy_i) in the world frame comes from its
//     wheel increments and its heading chi_i = psi + gamma_i - beta_i (asoc_model.h);
//   - CAST-n: the linear least squares of Eq. 13-17 over any subset of >= 2 castors,
//       dx_i = dx_c - dpsi R_i sin(psi + phi_i)   (Eq. 13)
//       dy_i = dy_c + dpsi R_i cos(psi + phi_i)   (Eq. 14)
//     solved with the closed-form (H^T H)^-1 of Eq. 18-21 for pivots anywhere on the body (Eq. 22,
//     for pivots centred on the body origin, is its special case: tests/asoc_odometry_test.cc);
//   - IPEC (Borenstein, Eq. 10) on two castors as the baseline;
//   - the final step both share: each castor's heading is updated from the new vehicle heading and
//     its measured castor angle (chi_i = psi+ + gamma_i+ - beta_i).
// Naming as in Doebbler Table II: CAST-i / IPEC-i leave castor i out (1-based), CAST-0 uses all.
//
// Linearisation heading: Eq. 13-14 linearise about psi- (the paper). With
// `midpoint_linearisation` the solve is repeated about psi- + dpsi/2, which makes Eq. 13-14 exact
// to second order in dpsi (2 sin(dpsi/2) R about the mid heading); default off (the paper).
//
// Redundancy check (the paper's future work, Sec. III-B end): with three castors, each castor's
// displacement is predicted from the other two (CAST on the pair). The pair whose own two
// displacements agree best (least change of their pivot distance) names the suspect, the third
// castor; it is dropped for this update when its measured displacement differs from the
// prediction by more than tolerance_m + tolerance_fraction * (the step length).

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "models/asoc/asoc_model.h"
#include "models/asoc/asoc_run_log.h"
#include "odometry/pose2.h"

namespace fitcal::asoc {

using CastorMask = unsigned;  // bit i set = castor i (0-based) is used
inline constexpr CastorMask kAllCastors = 0b111;
// CAST-i / IPEC-i of Doebbler Table II: castor i (1-based) left out; i = 0 keeps all.
inline CastorMask MaskExcluding(int castor_one_based) {
  return castor_one_based == 0 ? kAllCastors : (kAllCastors & ~(1u << (castor_one_based - 1)));
}
inline int MaskCount(CastorMask mask) {
  int n = 0;
  for (int i = 0; i < kNumCastors; ++i) n += (mask >> i) & 1u;
  return n;
}

template <typename T>
struct BodyStep {
  T dx_m;  // dx_c, world frame
  T dy_m;  // dy_c
  T dpsi_rad;
};

// CAST general solution, Eq. 15 with the closed-form inverse of Eq. 18-21:
//   H^T H = [[n, 0, b], [0, n, c], [b, c, d]],
//   b = -n (m_y cos psi + m_x sin psi), c = n (m_x cos psi - m_y sin psi), d = sum R_i^2,
// (Eq. 19 prints m_v for m_y), and H^T Y = [sum dx_i, sum dy_i, sum R_i (c_i dy_i - s_i dx_i)]
// with s_i, c_i = sin, cos(psi + phi_i). (m_x, m_y) is the mean of the used pivots in B.
template <typename T>
BodyStep<T> SolveCastGeneral(const std::array<PivotPosition, kNumCastors>& pivots, CastorMask mask,
                             const T& psi, const T* dx, const T* dy) {
  using std::cos;
  using std::sin;
  const T cp = cos(psi), sp = sin(psi);
  double n = 0.0, mx = 0.0, my = 0.0, d = 0.0;
  T sum_dx(0.0), sum_dy(0.0), sum_rot(0.0);
  for (int i = 0; i < kNumCastors; ++i) {
    if (!((mask >> i) & 1u)) continue;
    const double px = pivots[i].x_m(), py = pivots[i].y_m();
    n += 1.0;
    mx += px;
    my += py;
    d += px * px + py * py;
    const T r_sin = py * cp + px * sp;  // R_i sin(psi + phi_i)
    const T r_cos = px * cp - py * sp;  // R_i cos(psi + phi_i)
    sum_dx += dx[i];
    sum_dy += dy[i];
    sum_rot += r_cos * dy[i] - r_sin * dx[i];
  }
  mx /= n;
  my /= n;
  const T b = -n * (my * cp + mx * sp);  // Eq. 19
  const T c = n * (mx * cp - my * sp);   // Eq. 20
  // Eq. 18: (H^T H)^-1 = 1 / (n (b^2 + c^2 - n d)) [[c^2-nd, -bc, nb], [-bc, b^2-nd, nc],
  //                                                 [nb, nc, -n^2]]
  const T inv = T(1.0) / (n * (b * b + c * c - n * d));
  BodyStep<T> out;
  out.dx_m = inv * ((c * c - n * d) * sum_dx - b * c * sum_dy + n * b * sum_rot);
  out.dy_m = inv * (-b * c * sum_dx + (b * b - n * d) * sum_dy + n * c * sum_rot);
  out.dpsi_rad = inv * (n * b * sum_dx + n * c * sum_dy - n * n * sum_rot);
  return out;
}

// Pivot displacements of all castors over one update, castor headings from psi- (the shared final
// step of the previous update) and the pivot encoders at the update's start.
template <typename T>
void PivotDisplacements(const T* p, const EncoderSample& before, const EncoderSample& after,
                        const T& psi, T* dx, T* dy) {
  for (int i = 0; i < kNumCastors; ++i) {
    const T* castor = p + i * kParametersPerCastor;
    const T heading = psi + (before.pivot_rad[i] - castor[kBiasIndex]);
    PivotDisplacement(castor, T(after.wheel_rad[i][0] - before.wheel_rad[i][0]),
                      T(after.wheel_rad[i][1] - before.wheel_rad[i][1]), heading, &dx[i], &dy[i]);
  }
}

// One CAST update of the body pose (general solution; the centred one is the same number when the
// pivots are centred, tests/asoc_odometry_test.cc).
template <typename T>
BodyStep<T> CastStep(const std::array<PivotPosition, kNumCastors>& pivots, CastorMask mask,
                     bool midpoint_linearisation, const T& psi, const T* dx, const T* dy) {
  BodyStep<T> step = SolveCastGeneral(pivots, mask, psi, dx, dy);
  if (midpoint_linearisation) {
    step = SolveCastGeneral(pivots, mask, T(psi + step.dpsi_rad * 0.5), dx, dy);
  }
  return step;
}

// The redundancy check (Doebbler Sec. III-B, end; header above): the castor whose displacement
// (dx_i, dy_i) disagrees with the CAST prediction of the other two by more than
// tolerance_m + tolerance_fraction * (the step length), or -1. psi: the heading the displacements
// are expressed at (the body frame's, Eq. 13-14).
inline int InconsistentCastor(const std::array<PivotPosition, kNumCastors>& pivots, double psi,
                              const double* dx, const double* dy, double tolerance_m,
                              double tolerance_fraction) {
  int suspect = -1;
  double best_pair_residual = 0.0;
  double step_length = 0.0;
  for (int i = 0; i < kNumCastors; ++i)
    step_length = std::max(step_length, std::hypot(dx[i], dy[i]));
  const double c = std::cos(psi), s = std::sin(psi);
  for (int k = 0; k < kNumCastors; ++k) {
    const int i = (k + 1) % kNumCastors, j = (k + 2) % kNumCastors;
    // Change of the distance between pivots i and j: zero for a rigid body (first order).
    const double ex = pivots[j].x_m() - pivots[i].x_m();
    const double ey = pivots[j].y_m() - pivots[i].y_m();
    const double wx = c * ex - s * ey, wy = s * ex + c * ey;
    const double residual =
        std::abs(((dx[j] - dx[i]) * wx + (dy[j] - dy[i]) * wy) / std::hypot(wx, wy));
    if (suspect < 0 || residual < best_pair_residual) {
      suspect = k;
      best_pair_residual = residual;
    }
  }
  const BodyStep<double> pair =
      SolveCastGeneral(pivots, kAllCastors & ~(1u << suspect), psi, dx, dy);
  const PivotPosition& q = pivots[suspect];
  const double pred_x = pair.dx_m - pair.dpsi_rad * (q.y_m() * c + q.x_m() * s);  // Eq. 13
  const double pred_y = pair.dy_m + pair.dpsi_rad * (q.x_m() * c - q.y_m() * s);  // Eq. 14
  const double miss = std::hypot(dx[suspect] - pred_x, dy[suspect] - pred_y);
  return miss > tolerance_m + tolerance_fraction * step_length ? suspect : -1;
}

enum class Method { kCast, kIpec };

struct OdometryOptions {
  Method method = Method::kCast;
  // CAST: castors used (>= 2). IPEC: exactly two; the lower-numbered one is the anchor whose
  // position the other is re-placed from (Doebbler: "the position of the second castor is
  // updated to be consistent with the pose of the first castor").
  CastorMask castors = kAllCastors;
  bool midpoint_linearisation = false;
  // Redundancy check (CAST with all three castors only).
  bool drop_inconsistent_castor = false;
  double consistency_tolerance_m = 0.5e-3;
  double consistency_tolerance_fraction = 0.1;

  bool IsValid(std::string* error) const {
    const int n = MaskCount(castors);
    if (castors & ~kAllCastors) {
      *error = "castor mask names a castor that does not exist";
      return false;
    }
    if (method == Method::kCast && n < 2) {
      *error = "CAST needs at least two castors";
      return false;
    }
    if (method == Method::kIpec && n != 2) {
      *error = "IPEC uses exactly two castors";
      return false;
    }
    if (drop_inconsistent_castor && (method != Method::kCast || n != 3)) {
      *error = "the redundancy check needs CAST with all three castors";
      return false;
    }
    if (!(consistency_tolerance_m >= 0.0) || !(consistency_tolerance_fraction >= 0.0)) {
      *error = "consistency tolerances must be >= 0";
      return false;
    }
    return true;
  }
};

// Incremental odometry over a stream of encoder samples (double): the paper's replay, which the
// simulator's UMBmark (Tables I-II) runs; fits replay through the seam (asoc_kinematics.h).
class Odometry {
 public:
  Odometry(const Vehicle& vehicle, const OdometryOptions& options, const Pose2d& start,
           const EncoderSample& first)
      : vehicle_(vehicle),
        options_(options),
        params_(vehicle.ToArray()),
        pose_(start),
        last_(first) {
    std::string error;
    if (!options.IsValid(&error)) throw std::invalid_argument("asoc::OdometryOptions: " + error);
    if (options.method == Method::kIpec) {
      for (int i = 0; i < kNumCastors; ++i) {
        if ((options.castors >> i) & 1u) (anchor_ < 0 ? anchor_ : other_) = i;
      }
      anchor_pos_ = PivotWorld(anchor_);
      other_pos_ = PivotWorld(other_);
    }
  }

  void Step(const EncoderSample& next) {
    double dx[kNumCastors], dy[kNumCastors];
    PivotDisplacements(params_.data(), last_, next, pose_.theta, dx, dy);
    if (options_.method == Method::kIpec) {
      IpecStep(dx, dy);
    } else {
      CastorMask mask = options_.castors;
      if (options_.drop_inconsistent_castor) {
        const int suspect = InconsistentCastor(dx, dy);
        if (suspect >= 0) {
          mask &= ~(1u << suspect);
          ++dropped_[suspect];
        }
      }
      const BodyStep<double> step =
          CastStep(vehicle_.pivots, mask, options_.midpoint_linearisation, pose_.theta, dx, dy);
      pose_.x += step.dx_m;
      pose_.y += step.dy_m;
      pose_.theta += step.dpsi_rad;
    }
    last_ = next;  // final step: castor headings follow from pose_.theta and the new gamma_i
  }

  const Pose2d& pose() const { return pose_; }
  // Updates in which castor i was dropped by the redundancy check.
  const std::array<int, kNumCastors>& dropped() const { return dropped_; }

  // The castor the redundancy check would drop for these displacements, or -1.
  int InconsistentCastor(const double* dx, const double* dy) const {
    return asoc::InconsistentCastor(vehicle_.pivots, pose_.theta, dx, dy,
                                    options_.consistency_tolerance_m,
                                    options_.consistency_tolerance_fraction);
  }

 private:
  Eigen::Vector2d PivotWorld(int i) const {
    const double c = std::cos(pose_.theta), s = std::sin(pose_.theta);
    const PivotPosition& q = vehicle_.pivots[i];
    return {pose_.x + c * q.x_m() - s * q.y_m(), pose_.y + s * q.x_m() + c * q.y_m()};
  }

  // IPEC, Doebbler Eq. 10 on the pivots: move both pivots, take the heading from the line through
  // them, re-place the second pivot at its known distance from the first along that line.
  void IpecStep(const double* dx, const double* dy) {
    anchor_pos_ += Eigen::Vector2d(dx[anchor_], dy[anchor_]);
    other_pos_ += Eigen::Vector2d(dx[other_], dy[other_]);
    const PivotPosition& a = vehicle_.pivots[anchor_];
    const PivotPosition& b = vehicle_.pivots[other_];
    const double body_angle = std::atan2(b.y_m() - a.y_m(), b.x_m() - a.x_m());
    const Eigen::Vector2d line = other_pos_ - anchor_pos_;
    const double psi = std::atan2(line.y(), line.x()) - body_angle;  // Eq. 10
    pose_.theta += WrapAngle(psi - pose_.theta);
    other_pos_ = anchor_pos_ + vehicle_.PivotDistance(anchor_, other_) * line.normalized();
    const double c = std::cos(pose_.theta), s = std::sin(pose_.theta);
    pose_.x = anchor_pos_.x() - (c * a.x_m() - s * a.y_m());
    pose_.y = anchor_pos_.y() - (s * a.x_m() + c * a.y_m());
  }

  Vehicle vehicle_;
  OdometryOptions options_;
  std::array<double, kNumParameters> params_;
  Pose2d pose_;
  EncoderSample last_;
  std::array<int, kNumCastors> dropped_{};
  int anchor_ = -1;
  int other_ = -1;
  Eigen::Vector2d anchor_pos_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d other_pos_ = Eigen::Vector2d::Zero();
};

// Runs the odometry over a whole log; returns the final pose.
inline Pose2d RunOdometry(const Vehicle& vehicle, const OdometryOptions& options,
                          const EncoderLog& log, const Pose2d& start) {
  if (log.samples.empty()) return start;
  Odometry odometry(vehicle, options, start, log.samples.front());
  for (std::size_t k = 1; k < log.samples.size(); ++k) odometry.Step(log.samples[k]);
  return odometry.pose();
}

}  // namespace fitcal::asoc
