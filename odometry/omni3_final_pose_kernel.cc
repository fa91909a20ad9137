#include "odometry/omni3_final_pose_kernel.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace fitcal::omni3 {
namespace {

// The block sums are the whole cost of an evaluation and their speed is the vector width, so on
// x86-64 they are compiled twice, for the baseline and for AVX2+FMA (x86-64-v3), and the loader
// picks the one the CPU runs. Sums are taken in the order the vector width gives: the two builds
// agree to rounding, not bit for bit.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FITCAL_VECTOR_CLONES __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define FITCAL_VECTOR_CLONES
#endif

// Largest |delta| of each series; the truncation |delta|^(d+1)/(d+1)! of degree d stays below
// 1e-18: 0.02^8/8! = 6e-19, 0.15^12/12! = 3e-19, 1^20/20! = 4e-19.
constexpr double kShortMaxDelta = 0.02;
constexpr double kMediumMaxDelta = 0.15;
constexpr double kLongMaxDelta = 1.0;

// Taylor coefficients (-1)^k/(2k)! of cos and (-1)^k/(2k+1)! of sin/delta.
struct SeriesCoefficients {
  double cos[10];
  double sin[10];
};
constexpr SeriesCoefficients MakeSeriesCoefficients() {
  SeriesCoefficients c{};
  double factorial = 1.0;
  for (int k = 0; k < 10; ++k) {
    c.cos[k] = (k % 2 ? -1.0 : 1.0) / factorial;
    factorial *= 2 * k + 1;
    c.sin[k] = (k % 2 ? -1.0 : 1.0) / factorial;
    factorial *= 2 * k + 2;
  }
  return c;
}
constexpr SeriesCoefficients kSeries = MakeSeriesCoefficients();

// cos and sin of d from their first kTerms terms, Horner in d^2.
template <int kTerms>
inline void CosSinSeries(double d, double* c, double* s) {
  static_assert(kTerms <= 10, "kSeries holds 10 terms");
  const double d2 = d * d;
  double cc = kSeries.cos[kTerms - 1], ss = kSeries.sin[kTerms - 1];
  for (int k = kTerms - 2; k >= 0; --k) {
    cc = kSeries.cos[k] + d2 * cc;
    ss = kSeries.sin[k] + d2 * ss;
  }
  *c = cc;
  *s = d * ss;
}

// sum_j cos(delta_j) u_j and sum_j sin(delta_j) u_j over one block, with cos_sin(d, &c, &s)
// giving cos and sin of d.
template <typename CosSin>
inline void CosSinSums(const double* delta, const double* u0, const double* u1, const double* u2,
                       std::size_t len, CosSin cos_sin, double* sums) {
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, b0 = 0.0, b1 = 0.0, b2 = 0.0;
#pragma omp simd reduction(+ : a0, a1, a2, b0, b1, b2)
  for (std::size_t j = 0; j < len; ++j) {
    double c, s;
    cos_sin(delta[j], &c, &s);
    a0 += c * u0[j];
    a1 += c * u1[j];
    a2 += c * u2[j];
    b0 += s * u0[j];
    b1 += s * u1[j];
    b2 += s * u2[j];
  }
  sums[0] = a0, sums[1] = a1, sums[2] = a2, sums[3] = b0, sums[4] = b1, sums[5] = b2;
}

template <int kTerms>
inline void SeriesSums(const double* delta, const double* u0, const double* u1, const double* u2,
                       std::size_t len, double* sums) {
  CosSinSums(
      delta, u0, u1, u2, len, [](double d, double* c, double* s) { CosSinSeries<kTerms>(d, c, s); },
      sums);
}

FITCAL_VECTOR_CLONES
void BlockSums(const double* m3, const double* d0, const double* d1, const double* d2,
               const double* u0, const double* u1, const double* u2, std::size_t len,
               double* sums) {
  double delta[FinalPoseKernel::kBlock];
  double max_abs = 0.0;
#pragma omp simd reduction(max : max_abs)
  for (std::size_t j = 0; j < len; ++j) {
    delta[j] = m3[0] * d0[j] + m3[1] * d1[j] + m3[2] * d2[j];
    max_abs = std::max(max_abs, std::abs(delta[j]));
  }
  if (max_abs < kShortMaxDelta) {
    SeriesSums<4>(delta, u0, u1, u2, len, sums);  // degree 6/7
  } else if (max_abs < kMediumMaxDelta) {
    SeriesSums<6>(delta, u0, u1, u2, len, sums);  // degree 10/11
  } else if (max_abs < kLongMaxDelta) {
    SeriesSums<10>(delta, u0, u1, u2, len, sums);  // degree 18/19
  } else {
    CosSinSums(
        delta, u0, u1, u2, len,
        [](double d, double* c, double* s) {
          *c = std::cos(d);
          *s = std::sin(d);
        },
        sums);
  }
}

}  // namespace

FinalPoseKernel::FinalPoseKernel(const EncoderSamples& samples, std::size_t begin_sample,
                                 std::size_t n) {
  // Rows of three channels, [dt, w_0, w_1, w_2].
  constexpr std::size_t kStride = 4;
  assert(samples.stride() == static_cast<int>(kStride));
  assert(begin_sample + n <= samples.size());
  const double* rows = samples.data() + begin_sample * kStride;
  for (int i = 0; i < 3; ++i) {
    step_[i].resize(n);
    offset_[i].resize(n);
  }
  anchor_.resize((n + kBlock - 1) / kBlock);
  std::array<double, 3> before_block{};  // W at the block's first sample
  for (std::size_t b = 0; b < anchor_.size(); ++b) {
    const std::size_t begin = b * kBlock, len = std::min(kBlock, n - begin);
    const std::size_t mid = begin + len / 2;
    // Offsets from sums inside the block (small numbers), not from differences of W (large).
    std::array<double, 3> local{};  // W(k) - W(begin)
    std::array<double, 3> local_at_mid{};
    for (std::size_t k = begin; k < begin + len; ++k) {
      if (k == mid) local_at_mid = local;
      for (int i = 0; i < 3; ++i) {
        step_[i][k] = rows[k * kStride + 1 + i] * rows[k * kStride];
        offset_[i][k] = local[i];
        local[i] += step_[i][k];
      }
    }
    for (int i = 0; i < 3; ++i) {
      for (std::size_t k = begin; k < begin + len; ++k) offset_[i][k] -= local_at_mid[i];
      anchor_[b][i] = before_block[i] + local_at_mid[i];
      before_block[i] += local[i];
    }
  }
  total_ = before_block;
}

Pose2d FinalPoseKernel::FinalPose(const Matrix3<double>& m_inv, const Pose2d& start) const {
  const double m3[3] = {m_inv(2, 0), m_inv(2, 1), m_inv(2, 2)};
  double c_sum[3] = {0.0, 0.0, 0.0}, s_sum[3] = {0.0, 0.0, 0.0};
  const std::size_t n = size();
  for (std::size_t b = 0; b < anchor_.size(); ++b) {
    const std::size_t begin = b * kBlock, len = std::min(kBlock, n - begin);
    double sums[6];
    BlockSums(m3, &offset_[0][begin], &offset_[1][begin], &offset_[2][begin], &step_[0][begin],
              &step_[1][begin], &step_[2][begin], len, sums);
    // cos(theta_b + d) = cb cos(d) - sb sin(d); sin(theta_b + d) = sb cos(d) + cb sin(d)
    const double theta_b =
        start.theta + m3[0] * anchor_[b][0] + m3[1] * anchor_[b][1] + m3[2] * anchor_[b][2];
    const double cb = std::cos(theta_b), sb = std::sin(theta_b);
    for (int i = 0; i < 3; ++i) {
      c_sum[i] += cb * sums[i] - sb * sums[3 + i];
      s_sum[i] += sb * sums[i] + cb * sums[3 + i];
    }
  }
  Pose2d end = start;
  for (int i = 0; i < 3; ++i) {
    end.x += m_inv(0, i) * c_sum[i] - m_inv(1, i) * s_sum[i];
    end.y += m_inv(0, i) * s_sum[i] + m_inv(1, i) * c_sum[i];
    end.theta += m3[i] * total_[i];
  }
  return end;
}

}  // namespace fitcal::omni3
