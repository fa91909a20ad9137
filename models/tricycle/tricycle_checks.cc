#include "models/tricycle/tricycle_checks.h"

#include <cmath>
#include <sstream>

#include "io/input_error.h"
#include "odometry/text_format.h"

namespace fitcal::tricycle {

namespace {

using io::InputError;
using io::InputErrorKind;

constexpr int kSteeringChannel = 1;

bool IsMultipleOf(double v, double step) {
  const double n = v / step;
  return std::abs(n - std::round(n)) < 1e-9;
}

// Ticks, not radians: every value a multiple of `step` (1 for readings, 1/2 for the mean of two
// readings) and at least one beyond a whole turn. Returns the index of the largest, or -1.
long TicksLikeIndex(const double* values, std::size_t n, std::size_t stride, double step) {
  long largest = -1;
  double largest_abs = 2.0 * M_PI;
  for (std::size_t k = 0; k < n; ++k) {
    const double v = values[k * stride];
    if (!IsMultipleOf(v, step)) return -1;
    if (std::abs(v) > largest_abs) {
      largest_abs = std::abs(v);
      largest = static_cast<long>(k);
    }
  }
  return largest;
}

void Check(const double* values, std::size_t n, std::size_t stride, double step,
           const std::string& path, int first_line, const char* what) {
  const long ticks = TicksLikeIndex(values, n, stride, step);
  if (ticks >= 0) {
    throw InputError(InputErrorKind::kBadValue, path, first_line + static_cast<int>(ticks),
                     std::string("the steering ") + what + " are whole numbers up to " +
                         MessageNumber(values[static_cast<std::size_t>(ticks) * stride]) +
                         ": encoder ticks, not an angle in rad (counts of an absolute encoder: "
                         "name the column ticks_steering and declare steering_encoder: "
                         "{ticks_per_rev: N, zero_tick: Z} in the robot YAML)");
  }
  for (std::size_t k = 0; k < n; ++k) {
    const double v = values[k * stride];
    if (!(std::abs(v) <= M_PI)) {
      throw InputError(
          InputErrorKind::kBadValue, path, first_line + static_cast<int>(k),
          std::string("steering ") + what + " " + MessageNumber(v) + " rad lies outside [-pi, pi]");
    }
  }
}

}  // namespace

void CheckSteeringReadings(const std::vector<double>& readings_rad, const std::string& path,
                           int first_line) {
  Check(readings_rad.data(), readings_rad.size(), 1, 1.0, path, first_line, "readings");
}

void CheckSteeringSamples(const EncoderLog& log, const std::string& path) {
  const EncoderSamples& samples = log.samples;
  if (samples.num_channels() <= kSteeringChannel) {
    throw InputError(InputErrorKind::kBadHeader, path, 1,
                     "a tricycle needs 2 encoder channels (traction, steering), found " +
                         std::to_string(samples.num_channels()) + ": no steering channel");
  }
  if (samples.empty()) return;
  // Sample k's value sits at data() + k * stride + 1 + channel; it covers CSV rows k and k + 1,
  // the later of which is on line k + 3.
  Check(samples.data() + 1 + kSteeringChannel, samples.size(),
        static_cast<std::size_t>(samples.stride()), 0.5, path, 3, "values");
}

}  // namespace fitcal::tricycle
