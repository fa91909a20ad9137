#include "sim/stepped_run.h"

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "odometry/text_format.h"

namespace fitcal::sim {

namespace {

// Portable random numbers: mt19937_64 is fully specified by the standard, the distributions on
// top of it are not, so they are written out here.
class FlowerRandom {
 public:
  explicit FlowerRandom(std::uint64_t seed) : engine_(seed) {}
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  double Gaussian() {  // Box-Muller
    double u1 = Uniform();
    while (u1 <= 0.0) u1 = Uniform();
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 engine_;
};

// The body twist of channel values: the model's body step over a probe interval, divided by it.
// A power of two, so a step linear in dt (omni3's dt M^-1 w) gives the twist exactly; for a
// chord step (diff drive) the relative error is ~(omega dt)^2 / 6 < 1e-12.
constexpr double kTwistProbeS = 0x1p-20;

class SteppedRun {
 public:
  SteppedRun(const RobotModelInterface& model, const std::vector<double>& p_true,
             const TrajectorySpec& spec, const SimulationOptions& o, std::uint64_t stream);
  ModelSimulatedRun Run();

 private:
  void Start();
  void Substep(long n);
  void ApplyEffects(double t, double t_mid, const std::vector<double>& accel, Twist* v,
                    double* v_world);
  Twist BodyTwist() const;
  void Latch(double t);
  void LatchEncoder(double t);
  double EncoderTime(int k);
  const std::vector<double>& TargetAt(double t_mid) const;

  const Robot& robot_;
  const TrajectorySpec& spec_;
  const SimulationOptions& o_;
  const SteppedOptions& s_;
  const std::uint64_t stream_;
  const int c_;
  const double h_;
  FlowerRandom rng_;
  std::unique_ptr<const PreparedKinematics<double>> truth_;
  std::vector<double> boundaries_;            // segment starts, then the last segment's end
  std::vector<std::vector<double>> targets_;  // per segment; targets_.back() = rest
  double t_end_ = 0.0;
  double lag_ = 0.0, slip_decay_ = 0.0, slip_kick_ = 0.0;
  std::vector<double> x_, slip_, angle_, wheel_start_, contact_, counts_, last_counts_;
  std::vector<double> last_reading_;
  std::vector<effects::ActiveEffect<double>> active_;
  effects::EffectMemory<double> memory_;  // the injected effects' memory (gear play), one run
  double latency_s_ = 0.0;
  bool injecting_ = false, eccentric_ = false;
  Pose2d pose_;
  int next_encoder_ = 0;
  double next_encoder_t_ = 0.0, next_gt_t_ = 0.0, last_encoder_t_ = 0.0;
  ModelSimulatedRun out_;
};

SteppedRun::SteppedRun(const RobotModelInterface& model, const std::vector<double>& p_true,
                       const TrajectorySpec& spec, const SimulationOptions& o, std::uint64_t stream)
    : robot_(model.robot()),
      spec_(spec),
      o_(o),
      s_(*o.stepped),
      stream_(stream),
      c_(model.robot().NumChannels()),
      h_(o.stepped->substep_s),
      rng_(SplitMix(o.seed ^ SplitMix(stream))),
      truth_(model.PrepareKinematics(p_true.data())) {
  const std::vector<double>& commanded =
      s_.commanded_parameters.empty() ? p_true : s_.commanded_parameters;
  double t = o.rest_before_s;
  for (const TwistSegment& segment : spec.segments) {
    std::vector<double> target(c_);
    if (!model.ChannelsForTwist(commanded.data(), segment.twist, target.data())) {
      throw std::invalid_argument(StrFormat("the %s model cannot drive the twist (%f, %f, %f)",
                                            robot_.model.c_str(), segment.twist.vx_m_s,
                                            segment.twist.vy_m_s, segment.twist.omega_rad_s));
    }
    boundaries_.push_back(t);
    targets_.push_back(std::move(target));
    t += segment.duration_s;
  }
  boundaries_.push_back(t);
  targets_.push_back(std::vector<double>(c_, 0.0));  // at rest
  t_end_ = t + o.rest_after_s;
  lag_ = 1.0 - std::exp(-h_ / s_.controller_time_constant_s);
  slip_decay_ = std::exp(-h_ / s_.slip_correlation_time_s);
  slip_kick_ = s_.slip_sigma * std::sqrt(1.0 - slip_decay_ * slip_decay_);
  for (const auto& e : s_.injected_effects) active_.push_back({e.id, e.value.data()});
  latency_s_ = effects::TotalLatency(active_);
  injecting_ = !active_.empty() || static_cast<bool>(s_.hook);
  for (double e : s_.wheel_eccentricity) eccentric_ = eccentric_ || e != 0.0;
}

// The segment whose interval holds t_mid, or rest before and after them.
const std::vector<double>& SteppedRun::TargetAt(double t_mid) const {
  for (std::size_t j = 0; j + 1 < boundaries_.size(); ++j) {
    if (t_mid >= boundaries_[j] && t_mid < boundaries_[j + 1]) return targets_[j];
  }
  return targets_.back();
}

double SteppedRun::EncoderTime(int k) {
  return k * o_.encoder_period_s +
         (k == 0 ? 0.0 : rng_.Uniform(-s_.encoder_jitter_s, s_.encoder_jitter_s));
}

// The run's initial state, drawing in the flower's order (header).
void SteppedRun::Start() {
  const double range = o_.start_position_range_m;
  pose_ = o_.start_pose;
  pose_.x += rng_.Uniform(-range, range);
  pose_.y += rng_.Uniform(-range, range);
  if (o_.random_start_heading) pose_.theta = rng_.Uniform(-M_PI, M_PI);
  out_.true_start_pose = pose_;
  x_.assign(c_, 0.0);
  angle_.assign(c_, 0.0);
  slip_.assign(c_, 0.0);
  // Last channel first: the flower drew its initial slips as the arguments of one constructor
  // call, which GCC evaluates right to left.
  for (int i = c_ - 1; i >= 0; --i) {
    if (robot_.channels[i].kind == ChannelKind::kWheelRate) {
      slip_[i] = s_.slip_sigma * rng_.Gaussian();
    }
  }
  wheel_start_.assign(c_, 0.0);
  if (s_.random_wheel_start_angle) {
    FlowerRandom wheel_rng(SplitMix(o_.seed ^ SplitMix(stream_) ^ 0x57686565ull));
    for (int i = 0; i < c_; ++i) wheel_start_[i] = wheel_rng.Uniform(0.0, 2.0 * M_PI);
    out_.log.encoders.start_angle_rad = wheel_start_;
  }
  next_encoder_t_ = EncoderTime(0);
  next_gt_t_ = rng_.Uniform(0.0, s_.gt_period_max_s);
  counts_.assign(c_, 0.0);
  last_counts_.assign(c_, 0.0);
  last_reading_.assign(c_, 0.0);
}

ModelSimulatedRun SteppedRun::Run() {
  out_.log.id = StrFormat("%s-rep%02d", spec_.label.c_str(), spec_.repetition);
  out_.log.trajectory = spec_.label;
  out_.log.repetition = spec_.repetition;
  out_.log.encoders.samples = EncoderSamples(c_);
  for (const ChannelInfo& ch : robot_.channels) out_.encoder_columns.push_back(ch.rate_column);
  Start();
  const long steps = static_cast<long>(std::ceil(t_end_ / h_));
  Latch(0.0);
  for (long n = 0; n < steps; ++n) Substep(n);
  out_.true_final_pose = pose_;
  if (o_.record_start_pose) out_.log.start_pose = out_.true_start_pose;
  return std::move(out_);
}

Twist SteppedRun::BodyTwist() const {
  double d[3];
  truth_->Step(contact_.data(), kTwistProbeS, &d[0], &d[1], &d[2]);
  return {d[0] / kTwistProbeS, d[1] / kTwistProbeS, d[2] / kTwistProbeS};
}

// One substep of the header's equations; the arithmetic is the flower's, operation for
// operation, so that the shipped data set is reproduced bit for bit.
void SteppedRun::Substep(long n) {
  const double h = h_;
  const double t = n * h;
  const double t_mid = t + 0.5 * h;
  const std::vector<double>& goal = TargetAt(t_mid);
  for (int i = 0; i < c_; ++i) x_[i] += lag_ * (goal[i] - x_[i]);
  for (int i = 0; i < c_; ++i) {
    if (robot_.channels[i].kind == ChannelKind::kWheelRate)
      slip_[i] = slip_decay_ * slip_[i] + slip_kick_ * rng_.Gaussian();
  }
  std::vector<double> accel(c_);
  for (int i = 0; i < c_; ++i) accel[i] = (goal[i] - x_[i]) * (lag_ / (1.0 - lag_) / h);
  contact_.resize(c_);
  for (int i = 0; i < c_; ++i) {
    const bool wheel = robot_.channels[i].kind == ChannelKind::kWheelRate;
    contact_[i] = wheel ? x_[i] * (1.0 + slip_[i]) : x_[i];
    if (wheel && eccentric_) {
      const double angle_mid = wheel_start_[i] + angle_[i] + 0.5 * h * x_[i];
      contact_[i] *= 1.0 + s_.wheel_eccentricity[i] * std::cos(angle_mid);
    }
  }
  Twist v;
  double v_world[2] = {0.0, 0.0};
  if (injecting_) {
    ApplyEffects(t, t_mid, accel, &v, v_world);
  } else {
    v = BodyTwist();
  }
  const double heading_mid = pose_.theta + 0.5 * h * v.omega_rad_s;
  pose_.x += h * (std::cos(heading_mid) * v.vx_m_s - std::sin(heading_mid) * v.vy_m_s + v_world[0]);
  pose_.y += h * (std::sin(heading_mid) * v.vx_m_s + std::cos(heading_mid) * v.vy_m_s + v_world[1]);
  pose_.theta += h * v.omega_rad_s;
  for (int i = 0; i < c_; ++i) angle_[i] += h * x_[i];
  Latch((n + 1) * h);
}

// The injected effects and the hook (SteppedOptions) on the contact rates and the twist.
void SteppedRun::ApplyEffects(double t, double t_mid, const std::vector<double>& accel, Twist* v,
                              double* v_world) {
  effects::SampleContext c;
  c.t_s = t;
  c.dt_s = h_;
  c.num_channels = c_;
  c.wheel_mask = 0;
  for (int i = 0; i < c_; ++i) {
    const bool wheel = robot_.channels[i].kind == ChannelKind::kWheelRate;
    c.wheel_mask |= wheel ? 1u << i : 0u;
    c.angle_rad[i] = wheel ? angle_[i] : x_[i];
    c.derivative[i] = accel[i];
    c.moving = c.moving || (wheel && std::abs(x_[i]) > effects::kMovingRateRadS);
  }
  if (c_ == 2 && c.wheel_mask == 0x3u) {
    const double sum = std::abs(x_[0]) + std::abs(x_[1]);
    c.turn_fraction = sum > 0.0 ? std::abs(x_[0] - x_[1]) / sum : 0.0;
  }
  effects::ApplyRateEffects(active_, c, contact_.data(), &memory_);
  *v = BodyTwist();
  double body[3] = {v->vx_m_s, v->vy_m_s, v->omega_rad_s};
  const auto& table = effects::EffectOpsTable<double>();
  for (const auto& e : active_) {
    const auto& ops = table[static_cast<int>(e.id)];
    if (ops.body != nullptr) ops.body(e.q, c, body);
    if (ops.world != nullptr) ops.world(e.q, c, v_world);
  }
  *v = Twist{body[0], body[1], body[2]};
  if (s_.hook) {
    SteppedState state;
    state.t_s = t;
    state.time_since_motion_s = t_mid >= boundaries_.front() ? t - boundaries_.front() : -1.0;
    state.channel_value = x_.data();
    state.pose = pose_;
    s_.hook(state, contact_.data(), v, v_world);
  }
}

// Encoder rows due by t (jittered schedule), then ground-truth samples due by t.
void SteppedRun::Latch(double t) {
  while (next_encoder_t_ <= t + 1e-12 && next_encoder_t_ <= t_end_ + 1e-12) {
    LatchEncoder(t);
    ++next_encoder_;
    next_encoder_t_ = EncoderTime(next_encoder_);
    if (next_encoder_t_ <= t) next_encoder_t_ = t + h_;  // jitter never reorders samples
  }
  while (next_gt_t_ <= t + 1e-12) {
    GroundTruthTrack& gt = out_.log.ground_truth;
    const double sigma = o_.gt_position_sigma_m;
    gt.t_s.push_back(t + latency_s_);
    const double x = pose_.x + sigma * rng_.Gaussian();
    const double y = pose_.y + sigma * rng_.Gaussian();
    gt.world_T_robot.push_back(
        Pose2d{x, y, WrapAngle(pose_.theta + o_.gt_heading_sigma_rad * rng_.Gaussian())});
    next_gt_t_ += rng_.Uniform(s_.gt_period_min_s, s_.gt_period_max_s);
  }
}

// Wheel channels: the angle counted in whole ticks (ticks_per_rev, 0 = not quantised), logged
// as the mean rate over the interval; angle channels: the reading (with angle_sigma_rad), the
// interval holding the mean of its two readings (as the loader makes it).
void SteppedRun::LatchEncoder(double t) {
  std::vector<double> row(c_, 0.0), value(c_);
  for (int i = 0; i < c_; ++i) {
    if (robot_.channels[i].kind == ChannelKind::kAngle) {
      const double reading =
          x_[i] + (o_.angle_sigma_rad > 0.0 ? o_.angle_sigma_rad * rng_.Gaussian() : 0.0);
      value[i] = 0.5 * (last_reading_[i] + reading);
      row[i] = last_reading_[i] = reading;
      continue;
    }
    const double ticks = o_.ticks_per_rev.empty() ? 0.0 : o_.ticks_per_rev[i];
    const double count_rad = ticks > 0.0 ? 2.0 * M_PI / ticks : 1.0;
    counts_[i] = ticks > 0.0 ? std::floor(angle_[i] / count_rad) : angle_[i];
    if (next_encoder_ > 0)
      value[i] = row[i] = (counts_[i] - last_counts_[i]) * count_rad / (t - last_encoder_t_);
    last_counts_[i] = counts_[i];
  }
  if (next_encoder_ > 0) out_.log.encoders.samples.push_back(t - last_encoder_t_, value.data());
  out_.log.encoders.t_s.push_back(t);
  out_.recorded.push_back(std::move(row));
  last_encoder_t_ = t;
}

}  // namespace

std::string CheckSteppedOptions(const SteppedOptions& s, double encoder_period_s,
                                int num_channels) {
  if (!(s.encoder_jitter_s >= 0.0 && s.encoder_jitter_s < 0.5 * encoder_period_s)) {
    return "the encoder jitter must be in [0, period/2)";
  }
  if (!(s.substep_s > 0.0 && s.substep_s <= s.encoder_jitter_s + encoder_period_s)) {
    return "substep_s must be > 0 and not longer than an encoder period";
  }
  if (!(s.controller_time_constant_s > 0.0)) return "the controller time constant must be > 0";
  if (!(s.gt_period_min_s > 0.0 && s.gt_period_max_s >= s.gt_period_min_s)) {
    return "the ground-truth period must satisfy 0 < min <= max";
  }
  if (!(s.slip_sigma >= 0.0 && s.slip_correlation_time_s > 0.0)) {
    return "the slip needs sigma >= 0 and a correlation time > 0";
  }
  if (!s.wheel_eccentricity.empty() &&
      static_cast<int>(s.wheel_eccentricity.size()) != num_channels) {
    return "wheel_eccentricity needs one value per channel (" + std::to_string(num_channels) + ")";
  }
  for (double e : s.wheel_eccentricity) {
    if (!(std::abs(e) < 0.5)) return "wheel_eccentricity must be in (-0.5, 0.5)";
  }
  if (num_channels > effects::kMaxEffectChannels && (!s.injected_effects.empty() || s.hook)) {
    return "injected effects and the hook handle at most " +
           std::to_string(effects::kMaxEffectChannels) + " channels";
  }
  return "";
}

ModelSimulatedRun SimulateSteppedRun(const RobotModelInterface& model,
                                     const std::vector<double>& true_parameters,
                                     const TrajectorySpec& spec, const SimulationOptions& options,
                                     std::uint64_t stream) {
  SteppedRun run(model, true_parameters, spec, options, stream);
  return run.Run();
}

}  // namespace fitcal::sim
