#include "odometry/linear_final_pose_kernel.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

namespace fitcal {
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

constexpr std::size_t kBlock = LinearFinalPoseKernel::kBlock;

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

// cos and sin of every delta[j] from their first kTerms terms, Horner in d^2.
template <int kTerms>
inline void CosSinSeries(const double* delta, std::size_t len, double* c, double* s) {
  static_assert(kTerms <= 10, "kSeries holds 10 terms");
#pragma omp simd
  for (std::size_t j = 0; j < len; ++j) {
    const double d = delta[j], d2 = d * d;
    double cc = kSeries.cos[kTerms - 1], ss = kSeries.sin[kTerms - 1];
    for (int k = kTerms - 2; k >= 0; --k) {
      cc = kSeries.cos[k] + d2 * cc;
      ss = kSeries.sin[k] + d2 * ss;
    }
    c[j] = cc;
    s[j] = d * ss;
  }
}

// cos and sin of delta_j = m_theta . offset(j) over one block.
FITCAL_VECTOR_CLONES
void BlockCosSin(const double* m_theta, const double* const* offsets, int num_channels,
                 std::size_t len, double* c, double* s) {
  double delta[kBlock] = {};
  for (int i = 0; i < num_channels; ++i) {
    const double m = m_theta[i];
    const double* d = offsets[i];
#pragma omp simd
    for (std::size_t j = 0; j < len; ++j) delta[j] += m * d[j];
  }
  double max_abs = 0.0;
#pragma omp simd reduction(max : max_abs)
  for (std::size_t j = 0; j < len; ++j) max_abs = std::max(max_abs, std::abs(delta[j]));
  if (max_abs < kShortMaxDelta) {
    CosSinSeries<4>(delta, len, c, s);  // degree 6/7
  } else if (max_abs < kMediumMaxDelta) {
    CosSinSeries<6>(delta, len, c, s);  // degree 10/11
  } else if (max_abs < kLongMaxDelta) {
    CosSinSeries<10>(delta, len, c, s);  // degree 18/19
  } else {
    for (std::size_t j = 0; j < len; ++j) {
      c[j] = std::cos(delta[j]);
      s[j] = std::sin(delta[j]);
    }
  }
}

// sum_j c_j u_j and sum_j s_j u_j over one block.
FITCAL_VECTOR_CLONES
void BlockDots(const double* c, const double* s, const double* u, std::size_t len, double* cu,
               double* su) {
  double a = 0.0, b = 0.0;
#pragma omp simd reduction(+ : a, b)
  for (std::size_t j = 0; j < len; ++j) {
    a += c[j] * u[j];
    b += s[j] * u[j];
  }
  *cu = a;
  *su = b;
}

}  // namespace

LinearFinalPoseKernel::LinearFinalPoseKernel(const EncoderSamples& samples,
                                             std::size_t begin_sample, std::size_t n)
    : size_(n) {
  const int channels = samples.num_channels();
  const std::size_t stride = static_cast<std::size_t>(samples.stride());  // [dt, w_0, ...]
  assert(begin_sample + n <= samples.size());
  const double* rows = samples.data() + begin_sample * stride;
  step_.assign(channels, std::vector<double>(n));
  offset_.assign(channels, std::vector<double>(n));
  anchor_.assign(channels, std::vector<double>((n + kBlock - 1) / kBlock));
  total_.assign(channels, 0.0);  // W at the current block's first sample, W(n) at the end
  for (std::size_t b = 0; b * kBlock < n; ++b) {
    const std::size_t first = b * kBlock, len = std::min(kBlock, n - first);
    const std::size_t mid = first + len / 2;
    for (int i = 0; i < channels; ++i) {
      // Offsets from sums inside the block (small numbers), not from differences of W (large).
      double local = 0.0, local_at_mid = 0.0;  // W(k) - W(first)
      for (std::size_t k = first; k < first + len; ++k) {
        if (k == mid) local_at_mid = local;
        step_[i][k] = rows[k * stride + 1 + i] * rows[k * stride];
        offset_[i][k] = local;
        local += step_[i][k];
      }
      for (std::size_t k = first; k < first + len; ++k) offset_[i][k] -= local_at_mid;
      anchor_[i][b] = total_[i] + local_at_mid;
      total_[i] += local;
    }
  }
}

Pose2d LinearFinalPoseKernel::FinalPose(const double* m, const Pose2d& start) const {
  const int channels = num_channels();
  const double* m_x = m;
  const double* m_y = m + channels;
  const double* m_theta = m + 2 * channels;
  // On the stack: this runs once per run and evaluation, a few microseconds each.
  std::array<double, kMaxChannels> c_sum{}, s_sum{};
  std::array<const double*, kMaxChannels> offsets{};
  double c[kBlock], s[kBlock];
  for (std::size_t b = 0; b * kBlock < size_; ++b) {
    const std::size_t first = b * kBlock, len = std::min(kBlock, size_ - first);
    double theta_b = start.theta;
    for (int i = 0; i < channels; ++i) {
      offsets[i] = &offset_[i][first];
      theta_b += m_theta[i] * anchor_[i][b];
    }
    BlockCosSin(m_theta, offsets.data(), channels, len, c, s);
    // cos(theta_b + d) = cb cos(d) - sb sin(d); sin(theta_b + d) = sb cos(d) + cb sin(d)
    const double cb = std::cos(theta_b), sb = std::sin(theta_b);
    for (int i = 0; i < channels; ++i) {
      double cu, su;
      BlockDots(c, s, &step_[i][first], len, &cu, &su);
      c_sum[i] += cb * cu - sb * su;
      s_sum[i] += sb * cu + cb * su;
    }
  }
  Pose2d end = start;
  for (int i = 0; i < channels; ++i) {
    end.x += m_x[i] * c_sum[i] - m_y[i] * s_sum[i];
    end.y += m_x[i] * s_sum[i] + m_y[i] * c_sum[i];
    end.theta += m_theta[i] * total_[i];
  }
  return end;
}

}  // namespace fitcal
