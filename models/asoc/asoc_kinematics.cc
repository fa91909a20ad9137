#include "models/asoc/asoc_kinematics.h"

#include <cmath>

#include "odometry/invalid.h"

namespace fitcal {

bool AsocOdometryOptions::Parse(const std::string& name, AsocOdometryOptions* out) {
  if (name.size() != 6 || name[4] != '-' || name[5] < '0' || name[5] > '3') return false;
  const std::string kind = name.substr(0, 4);
  if (kind != "CAST" && kind != "IPEC") return false;
  out->method = kind == "IPEC" ? asoc::Method::kIpec : asoc::Method::kCast;
  out->excluded_castor = name[5] - '0';
  return true;
}

bool AsocOdometryOptions::IsValid(std::string* error) const {
  if (excluded_castor < 0 || excluded_castor > asoc::kNumCastors)
    return Invalid(error, "the castor left out must be 1, 2 or 3 (0: none)");
  if (method == asoc::Method::kIpec && excluded_castor == 0)
    return Invalid(error, "IPEC uses two castors: IPEC-1, IPEC-2 or IPEC-3");
  if (redundancy_check && (method != asoc::Method::kCast || excluded_castor != 0))
    return Invalid(error, "the redundancy check needs all three castors (CAST-0)");
  return true;
}

bool AsocKinematics::ChannelsForTwist(const double* p, const Twist& twist, double* values) const {
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    const asoc::CastorParameters c =
        asoc::CastorParameters::FromArray(p + i * asoc::kParametersPerCastor);
    double* v = values + i * asoc::kChannelsPerCastor;
    const std::array<double, 2> pivot_velocity = asoc::PivotVelocity(twist, pivots[i]);
    if (std::hypot(pivot_velocity[0], pivot_velocity[1]) < 1e-12 && twist.omega_rad_s == 0.0) {
      v[asoc::kWheelAChannel] = v[asoc::kWheelBChannel] = 0.0;  // at rest: the castor keeps
      v[asoc::kPivotChannel] = c.encoder_bias_rad;                // theta = 0
      continue;
    }
    double theta = 0.0, along = 0.0;
    if (!asoc::TrailingCastorAngle(pivot_velocity, c.offset_m, twist.omega_rad_s, &theta, &along))
      return false;
    const double lateral = c.offset_m * twist.omega_rad_s;  // w = r_c chi_dot, chi_dot = omega
    const auto rates = asoc::WheelRatesFromPivotMotion(c, along, lateral);
    v[asoc::kWheelAChannel] = rates[0];
    v[asoc::kWheelBChannel] = rates[1];
    v[asoc::kPivotChannel] = theta + c.encoder_bias_rad;  // gamma = theta + beta (Eq. 2)
  }
  return true;
}

}  // namespace fitcal
