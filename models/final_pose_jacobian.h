#pragma once
// The final-pose residual (Palacin Eq. 14) of one run with an analytic Jacobian, for kinematics
// that declare how (FinalPoseJacobianKind in model_interface.h). Same residuals as the autodiff
// ModelFinalPoseResidual (kinematic_model.h), same Jacobian to rounding
// (tests/final_pose_jacobian_test.cc); far cheaper, because Ceres' autodiff carries a Jet of all P
// parameters through every sample of the replay.
//
// The replay (odometry/replay.h, Palacin Eq. 4 and 5) moves the pose by the body step
// (dx_k, dy_k, dtheta_k) = S(p, w_k, dt_k), rotated by the heading before it, c_k = cos theta_k,
// s_k = sin theta_k:
//   x_N = x_0 + sum_k (c_k dx_k - s_k dy_k),  y_N = y_0 + sum_k (s_k dx_k + c_k dy_k),
//   theta_N = theta_0 + sum_k dtheta_k.
// The start pose is the ground truth's and does not depend on p. With G_k = dS/dp (3 x P) and
// T_k = dtheta_k/dp = sum_{j<k} G_j,theta the heading's derivative before step k, the chain rule
// (d c_k = -s_k T_k, d s_k = c_k T_k) gives
//   dx_N/dp = sum_k (c_k G_kx - s_k G_ky - Dy_k T_k),   Dy_k = s_k dx_k + c_k dy_k,
//   dy_N/dp = sum_k (s_k G_kx + c_k G_ky + Dx_k T_k),   Dx_k = c_k dx_k - s_k dy_k,
//   dtheta_N/dp = sum_k G_k,theta,
// with (Dx_k, Dy_k) the world-frame step. The poses and (c_k, s_k) are the replay's own (a
// StepVisitor of ReplaySteps, two samples per iteration as the plain replay on double), so the
// residuals are the residual-only evaluation's bit for bit, and the autodiff path's (one sample at
// a time on Jets) to rounding.
//
// kPerSampleStep: G_k from a Jet of the body step alone; O(P) doubles per sample after it.
// kLinearInChannels: the step is S = dt_k M(p) w_k with M 3 x n, so G_k = dt_k (dM/dp) w_k and
// T_k = (dM_theta/dp) W_k with W_k = sum_{j<k} dt_j w_j. The sums over k then run over the n
// channels instead of the P parameters:
//   dx_N/dp = dM_x/dp . A_c - dM_y/dp . A_s - dM_theta/dp . B_y,
//   dy_N/dp = dM_x/dp . A_s + dM_y/dp . A_c + dM_theta/dp . B_x,
//   dtheta_N/dp = dM_theta/dp . W_N,
// A_c = sum_k c_k dt_k w_k, A_s = sum_k s_k dt_k w_k, B_x = sum_k Dx_k W_k, B_y = sum_k Dy_k W_k,
// and M, dM/dp are computed once per evaluation (Jets on the 3 x n matrix).

#include <ceres/jet.h>
#include <ceres/sized_cost_function.h>

#include <array>
#include <cstddef>
#include <type_traits>

#include "models/model_interface.h"
#include "models/pose_errors.h"
#include "models/replay_kinematics.h"
#include "odometry/aligned_run.h"
#include "odometry/replay.h"

namespace fitcal {

// K::kFinalPoseJacobianKind, kAutodiff when K does not declare it.
template <class K, class = void>
struct FinalPoseJacobianKindOf
    : std::integral_constant<FinalPoseJacobianKind, FinalPoseJacobianKind::kAutodiff> {};
template <class K>
struct FinalPoseJacobianKindOf<K, std::void_t<decltype(K::kFinalPoseJacobianKind)>>
    : std::integral_constant<FinalPoseJacobianKind, K::kFinalPoseJacobianKind> {};

namespace final_pose_jacobian_internal {

template <int P>
using Row = std::array<double, P>;

// Whether K writes its body step's Jacobian by hand:
// K::StepJacobian(p, values, dt, dx, dy, g[3][P]), (dx, dy) the step BodyStep made.
template <class K, class = void>
struct HasStepJacobian : std::false_type {};
template <class K>
struct HasStepJacobian<
    K, std::void_t<decltype(K::StepJacobian(static_cast<const double*>(nullptr),
                                            static_cast<const double*>(nullptr), 0.0, 0.0, 0.0,
                                            static_cast<double (*)[K::kNumParameters]>(nullptr)))>>
    : std::true_type {};

// Accumulates dx_N/dp, dy_N/dp, dtheta_N/dp with each body step's Jacobian G_k (kPerSampleStep):
// K's StepJacobian where it has one, else a Jet of the body step.
template <class K, typename Prepared>
class PerSampleSums : public StepVisitor {
 public:
  static constexpr int P = K::kNumParameters;
  using JetP = ceres::Jet<double, P>;

  PerSampleSums(const K& kinematics, const double* p, const Prepared& prepared_jet,
                const EncoderSamples& samples)
      : kinematics_(kinematics),
        p_(p),
        prepared_jet_(prepared_jet),
        rows_(samples.data()),
        stride_(static_cast<std::size_t>(samples.stride())) {}

  // The sums run in local copies, as ChannelSums' (members would stay in memory).
  void Steps(std::size_t k0, std::size_t m, const double* c, const double* s, const double* dx,
             const double* dy, const double* /*dtheta*/) {
    Row<P> l_d_x = d_x, l_d_y = d_y, l_d_theta = d_theta;
    for (std::size_t j = 0; j < m; ++j) {
      const double* row = rows_ + (k0 + j) * stride_;
      double g[3][P];
      StepJacobian(row, dx[j], dy[j], g);
      const double world_dx = c[j] * dx[j] - s[j] * dy[j];
      const double world_dy = s[j] * dx[j] + c[j] * dy[j];
      for (int i = 0; i < P; ++i) {
        l_d_x[i] += c[j] * g[0][i] - s[j] * g[1][i] - world_dy * l_d_theta[i];
        l_d_y[i] += s[j] * g[0][i] + c[j] * g[1][i] + world_dx * l_d_theta[i];
        l_d_theta[i] += g[2][i];
      }
    }
    d_x = l_d_x, d_y = l_d_y, d_theta = l_d_theta;
  }

  Row<P> d_x{}, d_y{}, d_theta{};  // derivatives of the pose after the last visited step

 private:
  void StepJacobian(const double* row, double dx, double dy, double g[3][P]) const {
    if constexpr (HasStepJacobian<K>::value) {
      kinematics_.StepJacobian(p_, row + 1, row[0], dx, dy, g);
    } else {
      JetP gx, gy, gt;
      kinematics_.BodyStep(prepared_jet_, row + 1, row[0], &gx, &gy, &gt);
      for (int i = 0; i < P; ++i) g[0][i] = gx.v[i], g[1][i] = gy.v[i], g[2][i] = gt.v[i];
    }
  }

  const K& kinematics_;
  const double* p_;
  const Prepared& prepared_jet_;
  const double* rows_;
  std::size_t stride_;
};

// The channel sums A_c, A_s, B_x, B_y, W of kLinearInChannels.
template <int N>
class ChannelSums : public StepVisitor {
 public:
  explicit ChannelSums(const EncoderSamples& samples)
      : rows_(samples.data()), stride_(static_cast<std::size_t>(samples.stride())) {}

  // The sums run in local copies: members would stay in memory, since the compiler cannot rule
  // out that they alias the rows it reads (same type), and every add would go through a store.
  void Steps(std::size_t k0, std::size_t m, const double* c, const double* s, const double* dx,
             const double* dy, const double* /*dtheta*/) {
    std::array<double, N> l_a_c = a_c, l_a_s = a_s, l_b_x = b_x, l_b_y = b_y, l_w = w;
    for (std::size_t j = 0; j < m; ++j) {
      const double* row = rows_ + (k0 + j) * stride_;
      const double dt = row[0];
      const double world_dx = c[j] * dx[j] - s[j] * dy[j];
      const double world_dy = s[j] * dx[j] + c[j] * dy[j];
      for (int i = 0; i < N; ++i) {
        const double u = dt * row[1 + i];
        l_a_c[i] += c[j] * u;
        l_a_s[i] += s[j] * u;
        l_b_x[i] += world_dx * l_w[i];
        l_b_y[i] += world_dy * l_w[i];
        l_w[i] += u;
      }
    }
    a_c = l_a_c, a_s = l_a_s, b_x = l_b_x, b_y = l_b_y, w = l_w;
  }

  std::array<double, N> a_c{}, a_s{}, b_x{}, b_y{}, w{};

 private:
  const double* rows_;
  std::size_t stride_;
};

// Column i of M and of dM/dp (kLinearInChannels): the step of a unit rate on channel i over 1 s
// (the step is linear in the rates, so this is exact).
template <int N, class K, typename Prepared>
auto StepMatrixJets(const K& kinematics, const Prepared& prepared_jet) {
  using JetP = ceres::Jet<double, K::kNumParameters>;
  std::array<std::array<JetP, 3>, N> m;
  for (int i = 0; i < N; ++i) {
    std::array<double, N> unit{};
    unit[i] = 1.0;
    kinematics.BodyStep(prepared_jet, unit.data(), 1.0, &m[i][0], &m[i][1], &m[i][2]);
  }
  return m;
}

// dx/dp, dy/dp, dtheta/dp of the pose after the samples `sums` visited (kLinearInChannels, the
// header's sums over the channels).
// m is StepMatrixJets' result.
template <int P, int N, typename StepMatrix>
std::array<Row<P>, 3> PoseDerivatives(const StepMatrix& m, const ChannelSums<N>& sums) {
  std::array<Row<P>, 3> d;
  for (int j = 0; j < P; ++j) {
    double dx = 0.0, dy = 0.0, dtheta = 0.0;
    for (int i = 0; i < N; ++i) {
      const double mx = m[i][0].v[j], my = m[i][1].v[j], mt = m[i][2].v[j];
      dx += mx * sums.a_c[i] - my * sums.a_s[i] - mt * sums.b_y[i];
      dy += mx * sums.a_s[i] + my * sums.a_c[i] + mt * sums.b_x[i];
      dtheta += mt * sums.w[i];
    }
    d[0][j] = dx;
    d[1][j] = dy;
    d[2][j] = dtheta;
  }
  return d;
}

}  // namespace final_pose_jacobian_internal

template <class K>
class FinalPoseJacobianCost final : public ceres::SizedCostFunction<3, K::kNumParameters> {
 public:
  static constexpr int P = K::kNumParameters;
  static constexpr FinalPoseJacobianKind kKind = FinalPoseJacobianKindOf<K>::value;
  static_assert(kKind != FinalPoseJacobianKind::kAutodiff, "K has no analytic final-pose Jacobian");
  using JetP = ceres::Jet<double, P>;
  using Row = final_pose_jacobian_internal::Row<P>;

  FinalPoseJacobianCost(const AlignedRun& run, const ResidualWeights& weights, const K& kinematics)
      : run_(run), weights_(weights), kinematics_(kinematics) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* p = parameters[0];
    if (jacobians == nullptr || jacobians[0] == nullptr) {
      // The plain replay, as the autodiff functor runs on double.
      FinalPoseError(
          ReplayKinematics(kinematics_, p, run_.samples, 0, run_.samples.size(), run_.start),
          run_.final_ground_truth, weights_, residuals);
      return true;
    }
    std::array<Row, 3> d{};
    FinalPoseError(ReplayWithDerivatives(p, &d), run_.final_ground_truth, weights_, residuals);
    // residual = (pose - ground truth) / sigma; the heading's wrap has derivative 1.
    const double inv_sigma[3] = {1.0 / weights_.position_sigma_m, 1.0 / weights_.position_sigma_m,
                                 1.0 / weights_.heading_sigma_rad};
    for (int r = 0; r < 3; ++r) {
      for (int j = 0; j < P; ++j) jacobians[0][r * P + j] = d[r][j] * inv_sigma[r];
    }
    return true;
  }

 private:
  Pose2d ReplayWithDerivatives(const double* p, std::array<Row, 3>* d) const {
    std::array<JetP, P> p_jet;
    for (int j = 0; j < P; ++j) p_jet[j] = JetP(p[j], j);
    const auto prepared_jet = kinematics_.Prepare(p_jet.data());
    const std::size_t n = run_.samples.size();
    if constexpr (kKind == FinalPoseJacobianKind::kPerSampleStep) {
      final_pose_jacobian_internal::PerSampleSums<K, decltype(prepared_jet)> sums(
          kinematics_, p, prepared_jet, run_.samples);
      const Pose2d final_pose =
          ReplayKinematics(kinematics_, p, run_.samples, 0, n, run_.start, sums);
      *d = {sums.d_x, sums.d_y, sums.d_theta};
      return final_pose;
    } else {
      constexpr int N = K::kNumChannels;
      const auto m = final_pose_jacobian_internal::StepMatrixJets<N>(kinematics_, prepared_jet);
      final_pose_jacobian_internal::ChannelSums<N> sums(run_.samples);
      const Pose2d final_pose =
          ReplayKinematics(kinematics_, p, run_.samples, 0, n, run_.start, sums);
      *d = final_pose_jacobian_internal::PoseDerivatives<P>(m, sums);
      return final_pose;
    }
  }

  const AlignedRun& run_;
  ResidualWeights weights_;
  K kinematics_;
};

}  // namespace fitcal
