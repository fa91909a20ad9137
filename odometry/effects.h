#pragma once
// Candidate effects that the nine-parameter omni3 model (Palacin Eq. 3-6) lacks, as a registry.
//
// Each effect is a small struct with its own parameters (q, at most kMaxEffectParameters, all
// neutral at 0) and a templated transform of one stage of the replay, so that Ceres can
// differentiate through it and the simulator can inject it:
//   rates  - the wheel rates of one encoder interval, in place, before M^-1 (Eq. 4)
//   body   - the robot-frame velocity (vx, vy, omega) = M^-1 w, in place
//   world  - an additive world-frame velocity (vx, vy) while the robot moves
//   latency- a clock offset between the ground truth and the encoders (used by the residual)
// The table EffectTable() lists every effect's description (names, units, bounds, a realistic
// magnitude, whether the final poses of a flower can separate it from the nine parameters) and
// EffectOpsTable<T>() its transforms; both are indexed by EffectId. Adding an effect = one
// struct + one row in each table. The plain replay (omni3_replay.h) is untouched: the effect
// replay below is a separate, slower path.
//
// Sign conventions: w_i is the encoder's wheel rate (rad/s), positive as in Palacin Eq. 1; the
// "effective" rate is what actually moves the robot over the ground.

#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <type_traits>
#include <vector>

#include "odometry/encoder_samples.h"
#include "odometry/omni3_model.h"
#include "odometry/pose2.h"

namespace fitcal::effects {

enum class EffectId : int {
  kTimeOffset = 0,
  kWheelSpeedSlip,
  kDirectionRadius,
  kAccelerationSlip,
  kBacklash,
  kFloorSlope,
  kYawRateSlip,
  kOncePerRevolution,
  kEncoderClockScale,
  kTranslationYawGain,
  kGroundTruthOffset,
  kCount
};
inline constexpr int kNumEffects = static_cast<int>(EffectId::kCount);
inline constexpr int kMaxEffectParameters = 2;

// What an effect may look at for one encoder interval (data only, computed once per run by
// MakeSampleContexts). Times from the start of the replay window.
struct SampleContext {
  double t_s = 0.0;  // start of the interval
  double dt_s = 0.0;
  double angle_rad[3] = {0.0, 0.0, 0.0};     // encoder angle since the window start, at t_s
  double accel_rad_s2[3] = {0.0, 0.0, 0.0};  // smoothed wheel acceleration (see below)
  bool moving = false;                       // any wheel turning faster than kMovingRate
};

inline constexpr double kMovingRateRadS = 0.05;
// Wheel acceleration = (mean rate over [t, t+H] - mean rate over [t-H, t]) / H, with H below:
// encoder quantisation makes sample-to-sample differences useless (one count per 10 ms is
// 0.15 rad/s), a 50 ms window keeps start/stop transients (time constants ~0.1 s) visible.
inline constexpr double kAccelerationWindowS = 0.05;

// Precomputes the contexts of a run's samples.
std::vector<SampleContext> MakeSampleContexts(const EncoderSamples& samples);

struct EffectInfo {
  EffectId id;
  const char* name;  // YAML / CLI name
  const char* summary;
  const char* equation;
  int num_parameters;
  std::array<const char*, kMaxEffectParameters> parameter_names;  // with units, YAML keys
  std::array<double, kMaxEffectParameters> lower;
  std::array<double, kMaxEffectParameters> upper;
  std::array<double, kMaxEffectParameters> typical;  // a realistic magnitude (simulation, tests)
  // False when no data of any kind can tell the effect from the nine parameters.
  bool identifiable;
  const char* aliased_with;     // what the effect trades off with
  const char* separating_runs;  // which extra runs separate it from the nine parameters
};

const std::array<EffectInfo, kNumEffects>& EffectTable();
inline const EffectInfo& Info(EffectId id) { return EffectTable()[static_cast<int>(id)]; }
// Throws std::invalid_argument for an unknown name.
EffectId EffectIdFromName(const std::string& name);

// An effect with its parameter values (and one-sigma uncertainties when fitted).
struct EffectValue {
  EffectId id = EffectId::kTimeOffset;
  std::array<double, kMaxEffectParameters> value{};
  std::array<double, kMaxEffectParameters> sigma{};
};

// ---------------------------------------------------------------------------------------------
// The transforms. Every function is pure.

template <typename T>
inline T Sign(double x) {
  return T(x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0));
}

// Ground-truth latency tau (s): the ground-truth sample stamped t shows the pose of encoder time
// t - tau. Invisible in the final pose when runs end at rest: needs the track.
struct TimeOffset {
  template <typename T>
  static T Latency(const T* q) {
    return q[0];
  }
};

// Wheel-speed-dependent slip: effective radius r_i (1 - k |w_i|), k in s/rad.
struct WheelSpeedSlip {
  template <typename T>
  static void Rates(const T* q, const SampleContext&, T* w) {
    using std::abs;
    for (int i = 0; i < 3; ++i) w[i] = w[i] * (T(1.0) - q[0] * abs(w[i]));
  }
};

// Direction-dependent radius: r_i (1 + a) turning forward (w > 0), r_i (1 - a) backward.
struct DirectionRadius {
  template <typename T>
  static void Rates(const T* q, const SampleContext&, T* w) {
    for (int i = 0; i < 3; ++i) {
      const double sign = w[i] > T(0.0) ? 1.0 : -1.0;
      w[i] = w[i] * (T(1.0) + q[0] * T(sign));
    }
  }
};

// Slip during acceleration: effective rate w_i (1 - c |dw_i/dt|), c in s^2/rad; the wheel
// loses ground in start and stop transients.
struct AccelerationSlip {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    for (int i = 0; i < 3; ++i) w[i] = w[i] * (T(1.0) - q[0] * T(std::abs(c.accel_rad_s2[i])));
  }
};

// Gear backlash beta (rad) eaten at the start of a run: the first beta of each wheel's encoder
// angle does not turn the wheel. Transmitted angle phi(A) = sign(A) max(0, |A| - beta) with A
// the encoder angle since the window start (runs start at rest).
struct Backlash {
  template <typename T>
  static T Transmitted(const T& beta, double angle) {
    const T excess = T(std::abs(angle)) - beta;
    return excess > T(0.0) ? T(angle > 0.0 ? 1.0 : -1.0) * excess : T(0.0);
  }
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    if (!(c.dt_s > 0.0)) return;
    for (int i = 0; i < 3; ++i) {
      const double a0 = c.angle_rad[i];
      // The interval's encoder angle; w is the measured rate here (rates effects run first).
      const double a1 = a0 + ToDouble(w[i]) * c.dt_s;
      const T transmitted = Transmitted(q[0], a1) - Transmitted(q[0], a0);
      const double moved = a1 - a0;
      // w * transmitted / moved keeps the derivative chain through w for later effects.
      w[i] = std::abs(moved) > 0.0 ? w[i] * transmitted / T(moved) : w[i];
    }
  }
  template <typename T>
  static double ToDouble(const T& x) {
    if constexpr (std::is_same_v<T, double>) {
      return x;
    } else {
      return x.a;
    }
  }
};

// Floor slope: constant world-frame creep (cx, cy) m/s while the robot moves.
struct FloorSlope {
  template <typename T>
  static void World(const T* q, const SampleContext& c, T* v_world) {
    if (!c.moving) return;
    v_world[0] += q[0];
    v_world[1] += q[1];
  }
};

// Yaw-rate-dependent slip: robot-frame velocity times (1 - k |omega|), k in s/rad.
struct YawRateSlip {
  template <typename T>
  static void Body(const T* q, const SampleContext&, T* v) {
    using std::abs;
    const T scale = T(1.0) - q[0] * abs(v[2]);
    for (int i = 0; i < 3; ++i) v[i] = v[i] * scale;
  }
};

// Once-per-revolution encoder error (eccentric code wheel): the effective rate is
// w_i (1 + a cos A_i + b sin A_i), A_i the encoder angle at the interval's middle (angle since
// the window start: the phase of each run's first sample is taken as the code wheel's zero).
struct OncePerRevolution {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    for (int i = 0; i < 3; ++i) {
      const double a = c.angle_rad[i] + 0.5 * Backlash::ToDouble(w[i]) * c.dt_s;
      w[i] = w[i] * (T(1.0) + q[0] * T(std::cos(a)) + q[1] * T(std::sin(a)));
    }
  }
};

// Encoder clock scale s: the encoder clock runs fast by (1 + s), so every logged rate is low by
// 1/(1 + s). Multiplies all three wheel rates by one constant: exactly a common radius scale.
struct EncoderClockScale {
  template <typename T>
  static void Rates(const T* q, const SampleContext&, T* w) {
    for (int i = 0; i < 3; ++i) w[i] = w[i] * (T(1.0) + q[0]);
  }
};

// Translation-dependent yaw gain (omni-wheel contact-point shift): the yaw rate is scaled by the
// robot-frame translation velocity,
//   omega' = omega (1 + g_x v_x + g_y v_y),   g in s/m.
// Why: the yaw rate of Palacin Eq. 4 is sum_i w_i r_i / R_i-weighted, with R_i the distance from
// the centre to wheel i's contact point. An omni wheel's contact point sits on a roller (or on one
// of two roller rows) and moves along the axle when the wheel is loaded or rolled sideways; when
// the shift of R_i is proportional to the translation velocity (load transfer, lateral roller
// rolling), linearising sum_i w_i / R_i gives exactly the bilinear term above. It is the lowest
// order coupling of translation into heading that the nine parameters cannot produce: their yaw
// rate is linear in the wheel rates, this term is omega times a linear function of them. Signature
// in the residuals: runs with the same yaw rate but different translation directions in the robot
// frame (or the same direction and opposite yaw rates) show heading errors of opposite sign.
struct TranslationYawGain {
  template <typename T>
  static void Body(const T* q, const SampleContext&, T* v) {
    v[2] = v[2] * (T(1.0) + q[0] * v[0] + q[1] * v[1]);
  }
};

// Ground-truth body offset (mocap/SLAM extrinsic): the tracked point sits at e = (e_x, e_y) m in
// the robot frame instead of at the kinematic centre, so it moves with v + omega x e:
//   v_x' = v_x - omega e_y,   v_y' = v_y + omega e_x   (the replay then follows the tracked point).
// Exactly a change of the R_i (Palacin Eq. 1 row i with the reference point moved by e):
//   R_i' = R_i - e_x cos(delta_i) - e_y sin(delta_i),
// so on any data it is indistinguishable from the nine parameters (registry: not identifiable);
// what it explains is why fitted R_i can sit far from the measured ones (a 3 cm offset moves them
// by up to 3 cm). A yaw offset of the tracked frame is likewise a common shift of the delta_i.
struct GroundTruthOffset {
  template <typename T>
  static void Body(const T* q, const SampleContext&, T* v) {
    v[0] = v[0] - v[2] * q[1];
    v[1] = v[1] + v[2] * q[0];
  }
};

template <typename T>
struct EffectOps {
  void (*rates)(const T* q, const SampleContext& c, T* w) = nullptr;
  void (*body)(const T* q, const SampleContext& c, T* v) = nullptr;
  void (*world)(const T* q, const SampleContext& c, T* v_world) = nullptr;
  T (*latency)(const T* q) = nullptr;
};

template <typename T>
const std::array<EffectOps<T>, kNumEffects>& EffectOpsTable() {
  // Same order as EffectId (checked by tests/effects_test.cc).
  static const std::array<EffectOps<T>, kNumEffects> table = {{
      {nullptr, nullptr, nullptr, &TimeOffset::Latency<T>},
      {&WheelSpeedSlip::Rates<T>, nullptr, nullptr, nullptr},
      {&DirectionRadius::Rates<T>, nullptr, nullptr, nullptr},
      {&AccelerationSlip::Rates<T>, nullptr, nullptr, nullptr},
      {&Backlash::Rates<T>, nullptr, nullptr, nullptr},
      {nullptr, nullptr, &FloorSlope::World<T>, nullptr},
      {nullptr, &YawRateSlip::Body<T>, nullptr, nullptr},
      {&OncePerRevolution::Rates<T>, nullptr, nullptr, nullptr},
      {&EncoderClockScale::Rates<T>, nullptr, nullptr, nullptr},
      {nullptr, &TranslationYawGain::Body<T>, nullptr, nullptr},
      {nullptr, &GroundTruthOffset::Body<T>, nullptr, nullptr},
  }};
  return table;
}

// An active effect in a replay: which, and a pointer to its parameters.
template <typename T>
struct ActiveEffect {
  EffectId id;
  const T* q;
};

// Applies the rate stage of every active effect, in list order; backlash first, since it works
// on the measured encoder angle.
template <typename T>
void ApplyRateEffects(const std::vector<ActiveEffect<T>>& active, const SampleContext& c, T* w) {
  const auto& table = EffectOpsTable<T>();
  for (const auto& e : active) {
    if (e.id == EffectId::kBacklash) table[static_cast<int>(e.id)].rates(e.q, c, w);
  }
  for (const auto& e : active) {
    const auto& ops = table[static_cast<int>(e.id)];
    if (ops.rates != nullptr && e.id != EffectId::kBacklash) ops.rates(e.q, c, w);
  }
}

// Ground-truth latency of the active effects (0 without a time-offset effect).
template <typename T>
T TotalLatency(const std::vector<ActiveEffect<T>>& active) {
  T tau(0.0);
  const auto& table = EffectOpsTable<T>();
  for (const auto& e : active) {
    const auto& ops = table[static_cast<int>(e.id)];
    if (ops.latency != nullptr) tau += ops.latency(e.q);
  }
  return tau;
}

// Dead reckoning with effects, Palacin Eq. 4 with the stages above:
//   w' = rates(w);  v = body(M^-1 w');  pose += dt (R(theta)^-1 v + world(v))
// visit(k, pose before sample k, pose after it). Returns the final pose.
template <typename T, typename Visitor>
Pose2<T> ReplayWithEffects(const T* p, const std::vector<ActiveEffect<T>>& active,
                           const EncoderSamples& samples,
                           const std::vector<SampleContext>& contexts, const Pose2<T>& start,
                           Visitor&& visit) {
  using std::cos;
  using std::sin;
  const omni3::Matrix3<T> m_inv = omni3::InverseKinematicMatrix(p);
  const auto& table = EffectOpsTable<T>();
  Pose2<T> pose = start;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const SampleContext& c = contexts[k];
    const double dt = samples[k].dt_s;
    T w[3] = {T(samples[k].value[0]), T(samples[k].value[1]), T(samples[k].value[2])};
    ApplyRateEffects(active, c, w);
    T v[3];
    for (int r = 0; r < 3; ++r) v[r] = m_inv(r, 0) * w[0] + m_inv(r, 1) * w[1] + m_inv(r, 2) * w[2];
    T v_world[2] = {T(0.0), T(0.0)};
    for (const auto& e : active) {
      const auto& ops = table[static_cast<int>(e.id)];
      if (ops.body != nullptr) ops.body(e.q, c, v);
      if (ops.world != nullptr) ops.world(e.q, c, v_world);
    }
    const T cs = cos(pose.theta);
    const T sn = sin(pose.theta);
    Pose2<T> next;
    next.x = pose.x + T(dt) * (cs * v[0] - sn * v[1] + v_world[0]);
    next.y = pose.y + T(dt) * (sn * v[0] + cs * v[1] + v_world[1]);
    next.theta = pose.theta + T(dt) * v[2];
    visit(k, pose, next);
    pose = next;
  }
  return pose;
}

}  // namespace fitcal::effects
