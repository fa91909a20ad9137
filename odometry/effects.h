#pragma once
// Candidate effects that a robot's kinematic model lacks (Palacin Eq. 3-6 for omni3; any model
// of models/model_interface.h), as a registry.
//
// Each effect is a small struct with its own parameters (q, at most kMaxEffectParameters, all
// neutral at 0) and a templated transform of one stage of the replay, so that Ceres can
// differentiate through it and the simulator can inject it:
//   rates  - the channel values of one encoder interval, in place, before the model's kinematics
//            (M^-1 of Eq. 4 for omni3): wheel effects act on the wheel-rate channels, steering
//            effects on the angle channels (a tricycle's steering angle)
//   body   - the robot-frame velocity (vx, vy, omega) the kinematics give, in place
//   world  - an additive world-frame velocity (vx, vy) while the robot moves
//   latency- a clock offset between the ground truth and the encoders (used by the residual)
// The table EffectTable() lists every effect's description (names, units, bounds, a realistic
// magnitude, whether the final poses of a flower can separate it from the nine parameters) and
// EffectOpsTable<T>() its transforms; both are indexed by EffectId. Adding an effect = one
// struct + one row in each table. The plain replay (replay.h) is untouched: the effect replay
// below is a separate, slower path.
//
// Sign conventions: w_i is the encoder's wheel rate (rad/s), positive as in Palacin Eq. 1; the
// "effective" rate is what actually moves the robot over the ground.

#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "odometry/encoder_samples.h"
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
  kSteeringScale,
  kSteeringLag,
  kPivotYawGain,
  kCount
};
inline constexpr int kNumEffects = static_cast<int>(EffectId::kCount);
inline constexpr int kMaxEffectParameters = 2;

// The most channels an effect replay handles: an ASOC base of four castors (three channels each),
// the omni model's eight wheels.
inline constexpr int kMaxEffectChannels = 12;

// What an effect may look at for one encoder interval (data only, computed once per run by
// MakeSampleContexts). Times from the start of the replay window. Per channel i:
//   wheel-rate channel: angle_rad = encoder angle since the window start at t_s, accel_rad_s2(i)
//     = smoothed wheel acceleration (see below);
//   angle channel (steering, castor pivot): angle_rad = the measured angle of the interval,
//     angle_rate_rad_s(i) = its smoothed rate of change.
// A channel is one or the other, so the two derivatives share one array: two arrays of 12 doubles
// per sample (as three of 8 did), for every sample of every run of every model.
struct SampleContext {
  double t_s = 0.0;  // start of the interval
  double dt_s = 0.0;
  int num_channels = 3;
  unsigned wheel_mask = 0x7;  // bit i set: channel i is a wheel rate
  double angle_rad[kMaxEffectChannels] = {};
  double derivative[kMaxEffectChannels] = {};  // accel_rad_s2 or angle_rate_rad_s, by the mask
  double accel_rad_s2(int i) const { return derivative[i]; }
  double angle_rate_rad_s(int i) const { return derivative[i]; }
  bool moving = false;  // any wheel turning faster than kMovingRate
  // Data with exactly two channels, both wheel rates (a differential drive's right and left):
  // |w_0 - w_1| / (|w_0| + |w_1|), the pair's turn fraction. It is the half-track over the turning
  // radius, b / (2 R), while both wheels turn one way (0 driving straight), and 1 once they turn
  // against each other (the instantaneous centre of rotation between the wheels: a pivot). 0 for
  // any other channel layout and at rest.
  double turn_fraction = 0.0;
  bool IsWheel(int i) const { return (wheel_mask >> i) & 1u; }
};

inline constexpr double kMovingRateRadS = 0.05;
// Wheel acceleration = (mean rate over [t, t+H] - mean rate over [t-H, t]) / H, with H below:
// encoder quantisation makes sample-to-sample differences useless (one count per 10 ms is
// 0.15 rad/s), a 50 ms window keeps start/stop transients (time constants ~0.1 s) visible.
inline constexpr double kAccelerationWindowS = 0.05;

// Precomputes the contexts of a run's samples; wheel_mask as SampleContext's (default: every
// channel is a wheel rate, as omni3's three). Throws std::invalid_argument for more than
// kMaxEffectChannels channels.
std::vector<SampleContext> MakeSampleContexts(const EncoderSamples& samples,
                                              unsigned wheel_mask = ~0u);

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
  // Parameters a calibration file must give; the others were added later, and a file written
  // before them reads them as 0 (neutral). 0: every parameter.
  int parameters_required = 0;
};

const std::array<EffectInfo, kNumEffects>& EffectTable();
inline const EffectInfo& Info(EffectId id) { return EffectTable()[static_cast<int>(id)]; }
// Throws std::invalid_argument for an unknown name.
EffectId EffectIdFromName(const std::string& name);
// Steering effects transform angle channels only: a robot without one cannot show them.
inline bool NeedsAngleChannel(EffectId id) {
  return id == EffectId::kSteeringScale || id == EffectId::kSteeringLag;
}
// Effects that read SampleContext::turn_fraction: only a robot with two wheel channels and no
// other channel can show them.
inline bool NeedsWheelPair(EffectId id) { return id == EffectId::kPivotYawGain; }
// Whether channels of this kind let the effect act (a steering effect on a robot without an
// angle channel, or the pivot yaw gain on anything but a wheel pair, would be replayed as
// nothing); every other effect acts on any robot.
inline bool ChannelsCanCarry(EffectId id, int num_channels, bool has_angle_channel) {
  if (NeedsAngleChannel(id)) return has_angle_channel;
  if (NeedsWheelPair(id)) return num_channels == 2 && !has_angle_channel;
  return true;
}

// An effect with its parameter values (and one-sigma uncertainties when fitted).
struct EffectValue {
  EffectId id = EffectId::kTimeOffset;
  std::array<double, kMaxEffectParameters> value{};
  std::array<double, kMaxEffectParameters> sigma{};
};

// ---------------------------------------------------------------------------------------------
// The transforms. Every function is pure.

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
  static void Rates(const T* q, const SampleContext& c, T* w) {
    using std::abs;
    for (int i = 0; i < c.num_channels; ++i) {
      if (c.IsWheel(i)) w[i] = w[i] * (T(1.0) - q[0] * abs(w[i]));
    }
  }
};

// Direction-dependent radius: r_i (1 + a) turning forward (w > 0), r_i (1 - a) backward.
struct DirectionRadius {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    for (int i = 0; i < c.num_channels; ++i) {
      if (!c.IsWheel(i)) continue;
      const double sign = w[i] > T(0.0) ? 1.0 : -1.0;
      w[i] = w[i] * (T(1.0) + q[0] * T(sign));
    }
  }
};

// Slip during acceleration, two parts (c, k in s^2/rad):
//   w' = w (1 - c |dw/dt| - k sign(w) dw/dt).
// c: ground lost in every start and stop transient (a wheel that hops or spins either way).
// k: traction slip - the tyre's slip ratio is proportional to the traction force it carries,
// i.e. to the wheel's acceleration in its direction of motion (brush tyre model, linear creep):
// speeding up the wheel loses ground, braking it overruns (the body keeps going while the wheel
// slows). Over a start and a stop k loses nothing (the lag, k w |w| / 2 of wheel angle, is
// given back), but the lag is taken along the heading at the start and returned along the
// heading at the stop, so every arc and every turn between them leaves its mark. Why k: with c
// alone a traction-limited contact (an independent simulator's wheels sliding when asked for
// more than mu g; tests/independent_diagnose_test) was "unexplained structure", since c loses
// ground at the stop where the physics overruns.
struct AccelerationSlip {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    for (int i = 0; i < c.num_channels; ++i) {
      if (!c.IsWheel(i)) continue;
      const double a = c.accel_rad_s2(i);
      const double along = ScalarPart(w[i]) >= 0.0 ? a : -a;
      w[i] = w[i] * (T(1.0) - q[0] * T(std::abs(a)) - q[1] * T(along));
    }
  }
};

// What a replay carries from one encoder interval to the next for the effects with memory: the
// wheel's place in its gear play (Backlash), per channel. A replay starts with a fresh one.
template <typename T>
struct EffectMemory {
  T play_rad[kMaxEffectChannels] = {};  // wheel angle - encoder angle, in [-beta, beta]
};

// Gear backlash: the encoder sits on the motor side of a gear train whose play is 2 beta (rad at
// the wheel); the wheel follows the encoder angle A only when the motor pushes it at an edge of
// the play (the play, or backlash, operator of hysteresis models):
//   phi_k = clamp(phi_{k-1}, A_k - beta, A_k + beta),
// kept as the offset o = phi - A in [-beta, beta] (EffectMemory), o_k = clamp(o_{k-1} - dA, -beta,
// beta), so the transmitted angle of an interval is dA + o_k - o_{k-1}. The wheel starts centred
// (o = 0): a run's first motion loses beta, and every reversal of the motor loses 2 beta while
// the play is crossed. Why the memory: the first version lost beta at the start of a run only
// (phi = sign(A) max(0, |A| - beta)); on a simulator whose gear play is physical (the wheel
// follows the motor through a dead band; tests/independent_sim) every reversal - an inner wheel
// in a turn in place, reverse driving - crosses the play again, and that backlash went unnamed.
// For a wheel that turns one way only the two agree exactly.
struct Backlash {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w, EffectMemory<T>* memory) {
    if (!(c.dt_s > 0.0)) return;
    for (int i = 0; i < c.num_channels; ++i) {
      if (!c.IsWheel(i)) continue;
      // w is the measured rate here (backlash runs first among the rate effects).
      const T moved = w[i] * c.dt_s;
      T& play = memory->play_rad[i];
      T next = play - moved;
      if (next > q[0]) next = q[0];
      if (next < -q[0]) next = -q[0];
      w[i] = w[i] + (next - play) / c.dt_s;
      play = next;
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
    for (int i = 0; i < c.num_channels; ++i) {
      if (!c.IsWheel(i)) continue;
      const double a = c.angle_rad[i] + 0.5 * ScalarPart(w[i]) * c.dt_s;
      w[i] = w[i] * (T(1.0) + q[0] * T(std::cos(a)) + q[1] * T(std::sin(a)));
    }
  }
};

// Encoder clock scale s: the encoder clock runs fast by (1 + s), so every logged rate is low by
// 1/(1 + s). Multiplies every wheel rate by one constant: exactly a common radius scale.
struct EncoderClockScale {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    for (int i = 0; i < c.num_channels; ++i) {
      if (c.IsWheel(i)) w[i] = w[i] * (T(1.0) + q[0]);
    }
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

// Steering-angle scale k: the wheel turns (1 + k) times the measured angle (a potentiometer's
// gain, a linkage ratio). On an angle channel: phi' = phi (1 + k). The steering offset is the
// tricycle's own parameter; the scale is what the offset cannot absorb (turns both ways).
struct SteeringScale {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    for (int i = 0; i < c.num_channels; ++i) {
      if (!c.IsWheel(i)) w[i] = w[i] * (T(1.0) + q[0]);
    }
  }
};

// Steering lag tau (s): the measured angle lags the wheel's by tau (actuator or sensor
// filtering), phi_true(t) = phi_measured(t + tau) ~ phi + tau dphi/dt to first order, with the
// smoothed angle rate of the context.
struct SteeringLag {
  template <typename T>
  static void Rates(const T* q, const SampleContext& c, T* w) {
    for (int i = 0; i < c.num_channels; ++i) {
      if (!c.IsWheel(i)) w[i] = w[i] + q[0] * T(c.angle_rate_rad_s(i));
    }
  }
};

// Pivot yaw gain g: the yaw rate grows with the turn fraction s of the wheel pair (SampleContext),
//   omega' = omega (1 + g s),
// i.e. the effective wheel separation is b / (1 + g s): b driving gently curved arcs, b / (1 + g)
// pivoting on the spot. Why: the wheels' contact patches have a width, and where in each patch
// the wheel effectively rolls depends on how the patch scrubs - on the turning radius. In a pivot
// turn the patches twist about points inside the track, in a wide arc they roll. A castor
// dragged sideways in a pivot does the same. Constant parameters fit one turning radius; runs at
// two (circles and UMBmark squares, whose corners are pivots) each pull b their own way.
struct PivotYawGain {
  template <typename T>
  static void Body(const T* q, const SampleContext& c, T* v) {
    v[2] = v[2] * (T(1.0) + q[0] * T(c.turn_fraction));
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
      {nullptr, nullptr, nullptr, nullptr},  // Backlash: ApplyRateEffects, with its memory
      {nullptr, nullptr, &FloorSlope::World<T>, nullptr},
      {nullptr, &YawRateSlip::Body<T>, nullptr, nullptr},
      {&OncePerRevolution::Rates<T>, nullptr, nullptr, nullptr},
      {&EncoderClockScale::Rates<T>, nullptr, nullptr, nullptr},
      {nullptr, &TranslationYawGain::Body<T>, nullptr, nullptr},
      {nullptr, &GroundTruthOffset::Body<T>, nullptr, nullptr},
      {&SteeringScale::Rates<T>, nullptr, nullptr, nullptr},
      {&SteeringLag::Rates<T>, nullptr, nullptr, nullptr},
      {nullptr, &PivotYawGain::Body<T>, nullptr, nullptr},
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
// on the measured encoder angle. `memory` is the replay's (one per run, carried across its
// samples).
template <typename T>
void ApplyRateEffects(const std::vector<ActiveEffect<T>>& active, const SampleContext& c, T* w,
                      EffectMemory<T>* memory) {
  const auto& table = EffectOpsTable<T>();
  for (const auto& e : active) {
    if (e.id == EffectId::kBacklash) Backlash::Rates(e.q, c, w, memory);
  }
  for (const auto& e : active) {
    const auto& ops = table[static_cast<int>(e.id)];
    if (ops.rates != nullptr) ops.rates(e.q, c, w);
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

// Dead reckoning with effects, Palacin Eq. 4 (the generic replay of odometry/replay.h) with the
// stages above:
//   w' = rates(w);  (dx, dy, dtheta) = step(w', dt);  v = body((dx, dy, dtheta) / dt);
//   pose += R(theta) v dt + world(v) dt
// `step(values, dt, &dx, &dy, &dtheta)` is the model's body step (PreparedKinematics::Step;
// dt M^-1 w for omni3). Without body effects the step is used as it is, so the replay equals the
// plain one. visit(k, pose before sample k, pose after it). Returns the final pose.
template <typename T, typename Step, typename Visitor>
Pose2<T> ReplayStepsWithEffects(const Step& step, const std::vector<ActiveEffect<T>>& active,
                                const EncoderSamples& samples,
                                const std::vector<SampleContext>& contexts, const Pose2<T>& start,
                                Visitor&& visit) {
  using std::cos;
  using std::sin;
  const auto& table = EffectOpsTable<T>();
  bool any_body = false;
  for (const auto& e : active) any_body = any_body || table[static_cast<int>(e.id)].body;
  const int n = samples.num_channels();
  if (n > kMaxEffectChannels) {
    throw std::invalid_argument("the effect replay handles at most " +
                                std::to_string(kMaxEffectChannels) + " channels");
  }
  T w[kMaxEffectChannels];
  EffectMemory<T> memory;
  Pose2<T> pose = start;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const SampleContext& c = contexts[k];
    const double dt = samples[k].dt_s;
    for (int i = 0; i < n; ++i) w[i] = T(samples[k].value[i]);
    ApplyRateEffects(active, c, w, &memory);
    T d[3];
    step(w, dt, &d[0], &d[1], &d[2]);
    T v_world[2] = {T(0.0), T(0.0)};
    if (any_body && dt > 0.0) {
      for (T& x : d) x = x / dt;
      for (const auto& e : active) {
        const auto& ops = table[static_cast<int>(e.id)];
        if (ops.body != nullptr) ops.body(e.q, c, d);
      }
      for (T& x : d) x = x * dt;
    }
    for (const auto& e : active) {
      const auto& ops = table[static_cast<int>(e.id)];
      if (ops.world != nullptr) ops.world(e.q, c, v_world);
    }
    const T cs = cos(pose.theta);
    const T sn = sin(pose.theta);
    Pose2<T> next;
    next.x = pose.x + (cs * d[0] - sn * d[1]) + T(dt) * v_world[0];
    next.y = pose.y + (sn * d[0] + cs * d[1]) + T(dt) * v_world[1];
    next.theta = pose.theta + d[2];
    visit(k, pose, next);
    pose = next;
  }
  return pose;
}

}  // namespace fitcal::effects
