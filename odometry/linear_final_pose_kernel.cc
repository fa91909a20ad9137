#include "odometry/linear_final_pose_kernel.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <type_traits>

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

// sum_j cos(delta_j) u_i(j) and sum_j sin(delta_j) u_i(j) for every channel i over one block,
// delta_j = m_theta . offset(j): into cu[i], su[i]. One call per block (the clones' dispatch is an
// indirect call).
FITCAL_VECTOR_CLONES
void BlockSums(const double* m_theta, const double* const* offsets, const double* const* steps,
               int num_channels, std::size_t len, double* cu, double* su) {
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
  double c[kBlock], s[kBlock];
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
  for (int i = 0; i < num_channels; ++i) {
    const double* u = steps[i];
    double a = 0.0, b = 0.0;
#pragma omp simd reduction(+ : a, b)
    for (std::size_t j = 0; j < len; ++j) {
      a += c[j] * u[j];
      b += s[j] * u[j];
    }
    cu[i] = a;
    su[i] = b;
  }
}

// BlockSums for 3 or 4 channels: delta, cos/sin and the sums in one pass over the block, on named
// accumulators (what the vectoriser reduces best), as omni3's own kernel did - about twice as fast
// as the loops over a run-time channel count.
template <int N, typename CosSin>
inline void FusedSums(const double* delta, const double* const* steps, std::size_t len,
                      CosSin cos_sin, double* cu, double* su) {
  static_assert(N == 3 || N == 4, "fused for 3 or 4 channels");
  const double* u0 = steps[0];
  const double* u1 = steps[1];
  const double* u2 = steps[2];
  const double* u3 = steps[N - 1];  // read only when N == 4
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0, b0 = 0.0, b1 = 0.0, b2 = 0.0, b3 = 0.0;
#pragma omp simd reduction(+ : a0, a1, a2, a3, b0, b1, b2, b3)
  for (std::size_t j = 0; j < len; ++j) {
    double c, s;
    cos_sin(delta[j], &c, &s);
    a0 += c * u0[j];
    a1 += c * u1[j];
    a2 += c * u2[j];
    b0 += s * u0[j];
    b1 += s * u1[j];
    b2 += s * u2[j];
    if constexpr (N == 4) {
      a3 += c * u3[j];
      b3 += s * u3[j];
    }
  }
  cu[0] = a0, cu[1] = a1, cu[2] = a2, su[0] = b0, su[1] = b1, su[2] = b2;
  if constexpr (N == 4) cu[3] = a3, su[3] = b3;
}

template <int N>
FITCAL_VECTOR_CLONES void BlockSumsN(const double* m_theta, const double* const* offsets,
                                     const double* const* steps, std::size_t len, double* cu,
                                     double* su) {
  const double* o0 = offsets[0];
  const double* o1 = offsets[1];
  const double* o2 = offsets[2];
  const double* o3 = offsets[N - 1];  // read only when N == 4
  const double m0 = m_theta[0], m1 = m_theta[1], m2 = m_theta[2], m3 = m_theta[N - 1];
  double delta[kBlock];
  double max_abs = 0.0;
#pragma omp simd reduction(max : max_abs)
  for (std::size_t j = 0; j < len; ++j) {
    double d = m0 * o0[j] + m1 * o1[j] + m2 * o2[j];
    if constexpr (N == 4) d += m3 * o3[j];
    delta[j] = d;
    max_abs = std::max(max_abs, std::abs(d));
  }
  const auto series = [&](auto terms) {
    constexpr int kTerms = decltype(terms)::value;
    FusedSums<N>(
        delta, steps, len,
        [](double d, double* c, double* s) {
          const double d2 = d * d;
          double cc = kSeries.cos[kTerms - 1], ss = kSeries.sin[kTerms - 1];
          for (int k = kTerms - 2; k >= 0; --k) {
            cc = kSeries.cos[k] + d2 * cc;
            ss = kSeries.sin[k] + d2 * ss;
          }
          *c = cc;
          *s = d * ss;
        },
        cu, su);
  };
  if (max_abs < kShortMaxDelta) {
    series(std::integral_constant<int, 4>());  // degree 6/7
  } else if (max_abs < kMediumMaxDelta) {
    series(std::integral_constant<int, 6>());  // degree 10/11
  } else if (max_abs < kLongMaxDelta) {
    series(std::integral_constant<int, 10>());  // degree 18/19
  } else {
    FusedSums<N>(
        delta, steps, len,
        [](double d, double* c, double* s) {
          *c = std::cos(d);
          *s = std::sin(d);
        },
        cu, su);
  }
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
  std::array<const double*, kMaxChannels> offsets{}, steps{};
  std::array<double, kMaxChannels> cu{}, su{};
  for (std::size_t b = 0; b * kBlock < size_; ++b) {
    const std::size_t first = b * kBlock, len = std::min(kBlock, size_ - first);
    double theta_b = start.theta;
    for (int i = 0; i < channels; ++i) {
      offsets[i] = &offset_[i][first];
      steps[i] = &step_[i][first];
      theta_b += m_theta[i] * anchor_[i][b];
    }
    switch (channels) {  // the common wheel counts get the fused loop
      case 3:
        BlockSumsN<3>(m_theta, offsets.data(), steps.data(), len, cu.data(), su.data());
        break;
      case 4:
        BlockSumsN<4>(m_theta, offsets.data(), steps.data(), len, cu.data(), su.data());
        break;
      default:
        BlockSums(m_theta, offsets.data(), steps.data(), channels, len, cu.data(), su.data());
    }
    // cos(theta_b + d) = cb cos(d) - sb sin(d); sin(theta_b + d) = sb cos(d) + cb sin(d)
    const double cb = std::cos(theta_b), sb = std::sin(theta_b);
    for (int i = 0; i < channels; ++i) {
      c_sum[i] += cb * cu[i] - sb * su[i];
      s_sum[i] += sb * cu[i] + cb * su[i];
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
