#include "sim/model_simulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/dataset.h"
#include "odometry/parallel_for.h"
#include "odometry/split_mix.h"
#include "odometry/text_format.h"
#include "sim/stepped_run.h"

namespace fitcal::sim {

namespace {

// splitmix64 (Steele, Lea, Flood 2014): small, fast, the same bits everywhere.
class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream)
      : state_(seed ^ (0x9E3779B97F4A7C15ULL * (stream + 1))) {
    Next();
  }
  std::uint64_t Next() {
    const std::uint64_t z = SplitMix(state_);
    state_ += 0x9E3779B97F4A7C15ULL;
    return z;
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  // [0, 1)
  // Box-Muller; sigma 0 draws nothing, so noise-free runs do not depend on the stream.
  double Normal(double sigma) {
    if (sigma == 0.0) return 0.0;
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::uint64_t state_;
};

// The commanded twist over time: levels between boundaries, raised-cosine ramps centred on each
// boundary (header).
class TwistProfile {
 public:
  TwistProfile(const std::vector<TwistSegment>& segments, const SimulationOptions& options) {
    levels_.push_back(Twist{});
    double t = options.rest_before_s;
    for (const TwistSegment& s : segments) {
      if (!(s.duration_s >= kRampTimeS)) {
        throw std::invalid_argument("a trajectory segment of " + std::to_string(s.duration_s) +
                                    " s is shorter than the ramp (" + std::to_string(kRampTimeS) +
                                    " s)");
      }
      boundaries_.push_back(t);
      levels_.push_back(s.twist);
      t += s.duration_s;
    }
    boundaries_.push_back(t);
    levels_.push_back(Twist{});
    end_s_ = t + options.rest_after_s;
  }

  double end_s() const { return end_s_; }

  Twist At(double t) const {
    const std::size_t j = static_cast<std::size_t>(
        std::upper_bound(boundaries_.begin(), boundaries_.end(), t) - boundaries_.begin());
    // The ramps of boundary j-1 (ending) and j (starting); at most one covers t.
    if (j > 0 && t - boundaries_[j - 1] < 0.5 * kRampTimeS) return Blend(j - 1, t);
    if (j < boundaries_.size() && boundaries_[j] - t < 0.5 * kRampTimeS) return Blend(j, t);
    return levels_[j];
  }

 private:
  Twist Blend(std::size_t boundary, double t) const {
    const double u = (t - boundaries_[boundary] + 0.5 * kRampTimeS) / kRampTimeS;
    const double s = 0.5 * (1.0 - std::cos(M_PI * std::clamp(u, 0.0, 1.0)));
    const Twist& a = levels_[boundary];
    const Twist& b = levels_[boundary + 1];
    return {a.vx_m_s + s * (b.vx_m_s - a.vx_m_s), a.vy_m_s + s * (b.vy_m_s - a.vy_m_s),
            a.omega_rad_s + s * (b.omega_rad_s - a.omega_rad_s)};
  }

  double end_s_ = 0.0;
  std::vector<double> boundaries_;
  std::vector<Twist> levels_;  // levels_[j] holds before boundaries_[j]
};

// The fine grid: every encoder and ground-truth time, gaps split into steps <= substep_s.
struct FineGrid {
  std::vector<double> t_s;                 // grid times, t_s[0] = 0
  std::vector<std::size_t> encoder_index;  // grid index of each encoder time
  std::vector<std::size_t> gt_index;       // grid index of each ground-truth time
};

FineGrid MakeGrid(double end_s, const SimulationOptions& o) {
  const auto num = [](double end, double period) {
    return static_cast<std::size_t>(std::ceil(end / period - 1e-9));
  };
  const std::size_t num_encoder = num(end_s, o.encoder_period_s);
  const double last_s = static_cast<double>(num_encoder) * o.encoder_period_s;
  std::vector<std::pair<double, int>> anchors;  // time, 0 encoder / 1 ground truth
  anchors.reserve(num_encoder + num(last_s, o.ground_truth_period_s) + 2);
  for (std::size_t k = 0; k <= num_encoder; ++k) {
    anchors.push_back({static_cast<double>(k) * o.encoder_period_s, 0});
  }
  for (std::size_t j = 0; static_cast<double>(j) * o.ground_truth_period_s <= last_s + 1e-9; ++j) {
    anchors.push_back({std::min(static_cast<double>(j) * o.ground_truth_period_s, last_s), 1});
  }
  std::sort(anchors.begin(), anchors.end());
  // Sized once: every gap between anchors is split into at most gap / substep + 1 steps. A
  // vector grown row by row is copied at every doubling (most of a simulation's page faults
  // under the sanitizers).
  FineGrid grid;
  grid.t_s.reserve(num(last_s, o.substep_s) + anchors.size() + 1);
  grid.encoder_index.reserve(num_encoder + 1);
  grid.gt_index.reserve(anchors.size() - num_encoder - 1);
  grid.t_s.push_back(0.0);
  for (const auto& [t, kind] : anchors) {
    const double gap = t - grid.t_s.back();
    if (gap > 1e-9) {
      const int steps = static_cast<int>(std::ceil(gap / o.substep_s - 1e-9));
      const double t0 = grid.t_s.back();
      for (int i = 1; i < steps; ++i) grid.t_s.push_back(t0 + gap * i / steps);
      grid.t_s.push_back(t);
    }
    (kind == 0 ? grid.encoder_index : grid.gt_index).push_back(grid.t_s.size() - 1);
  }
  return grid;
}

Pose2d StartPose(const SimulationOptions& o, Rng& rng) {
  Pose2d p = o.start_pose;
  if (o.start_position_range_m > 0.0) {
    p.x += o.start_position_range_m * (2.0 * rng.Uniform() - 1.0);
    p.y += o.start_position_range_m * (2.0 * rng.Uniform() - 1.0);
  }
  if (o.random_start_heading) p.theta = -M_PI + 2.0 * M_PI * rng.Uniform();
  return p;
}

// Channel values at the middle of every fine step.
EncoderSamples FineChannels(const RobotModelInterface& model, const double* p,
                            const TwistProfile& profile, const FineGrid& grid) {
  const int c = model.robot().NumChannels();
  EncoderSamples fine(c);
  fine.reserve(grid.t_s.size());
  std::vector<double> values(c);
  for (std::size_t k = 1; k < grid.t_s.size(); ++k) {
    const Twist v = profile.At(0.5 * (grid.t_s[k - 1] + grid.t_s[k]));
    if (!model.ChannelsForTwist(p, v, values.data())) {
      throw std::invalid_argument(StrFormat("the %s model cannot drive the twist (%f, %f, %f)",
                                            model.robot().model.c_str(), v.vx_m_s, v.vy_m_s,
                                            v.omega_rad_s));  // std::to_string's %f
    }
    fine.push_back(grid.t_s[k] - grid.t_s[k - 1], values.data());
  }
  return fine;
}

// Channel values of every fine step from the model's own dynamics, and the angle readings at
// every grid time (readings[k], grid time k).
EncoderSamples DynamicChannels(ChannelDynamics& dynamics, int c, const TwistProfile& profile,
                               const FineGrid& grid, std::vector<std::vector<double>>* readings) {
  EncoderSamples fine(c);
  fine.reserve(grid.t_s.size());
  readings->reserve(grid.t_s.size());
  std::vector<double> values(c, 0.0);
  dynamics.Read(values.data());
  readings->push_back(values);
  for (std::size_t k = 1; k < grid.t_s.size(); ++k) {
    const double dt = grid.t_s[k] - grid.t_s[k - 1];
    dynamics.Step(profile.At(grid.t_s[k - 1] + 0.5 * dt), dt, values.data());
    fine.push_back(dt, values.data());
    dynamics.Read(values.data());
    readings->push_back(values);
  }
  return fine;
}

// The encoder log and the recorded rows from the fine channel values (header: noise model);
// `readings` per grid time when the model's dynamics read the angles, else empty.
void RecordEncoders(const RobotModelInterface& model, const double* p, const TwistProfile& profile,
                    const FineGrid& grid, const EncoderSamples& fine,
                    const std::vector<std::vector<double>>& readings, const SimulationOptions& o,
                    Rng& rng, ModelSimulatedRun* run) {
  const Robot& robot = model.robot();
  const int c = robot.NumChannels();
  std::vector<double> reading(c), previous(c), value(c), angle(c, 0.0), counted(c, 0.0), tmp(c);
  const auto ticks_of = [&o](int i) {
    return o.ticks_per_rev.empty() ? 0.0 : o.ticks_per_rev[static_cast<std::size_t>(i)];
  };
  const auto read_angles = [&](std::size_t k, std::vector<double>* out) {
    if (readings.empty()) model.ChannelsForTwist(p, profile.At(grid.t_s[k]), tmp.data());
    const std::vector<double>& read = readings.empty() ? tmp : readings[k];
    for (int i = 0; i < c; ++i) {
      if (robot.channels[i].kind == ChannelKind::kAngle)
        (*out)[i] = read[i] + rng.Normal(o.angle_sigma_rad);
    }
  };
  for (int i = 0; i < c; ++i) {
    // The wheel starts at a random phase within a tick, so counting is unbiased.
    if (ticks_of(i) > 0.0) angle[i] = rng.Uniform() * 2.0 * M_PI / ticks_of(i);
    counted[i] = ticks_of(i) > 0.0 ? std::floor(angle[i] * ticks_of(i) / (2.0 * M_PI)) : angle[i];
  }
  read_angles(0, &previous);
  run->log.encoders.samples = EncoderSamples(c);
  run->log.encoders.samples.reserve(grid.encoder_index.size());
  run->log.encoders.t_s.reserve(grid.encoder_index.size());
  run->recorded.reserve(grid.encoder_index.size());
  run->log.encoders.t_s.push_back(0.0);
  run->recorded.push_back(std::vector<double>(c, 0.0));
  for (int i = 0; i < c; ++i) {
    if (robot.channels[i].kind == ChannelKind::kAngle) run->recorded.back()[i] = previous[i];
  }
  for (std::size_t k = 1; k < grid.encoder_index.size(); ++k) {
    const std::size_t a = grid.encoder_index[k - 1], b = grid.encoder_index[k];
    const double dt = grid.t_s[b] - grid.t_s[a];
    read_angles(b, &reading);
    std::vector<double> row(c);
    for (int i = 0; i < c; ++i) {
      if (robot.channels[i].kind == ChannelKind::kAngle) {
        value[i] = 0.5 * (previous[i] + reading[i]);
        row[i] = reading[i];
        continue;
      }
      double advance = 0.0;
      for (std::size_t j = a; j < b; ++j) advance += fine[j].value[i] * fine[j].dt_s;
      advance *= 1.0 + rng.Normal(o.wheel_relative_sigma);
      angle[i] += advance + rng.Normal(o.wheel_rate_sigma_rad_s * dt);
      const double ticks = ticks_of(i);
      const double now = ticks > 0.0 ? std::floor(angle[i] * ticks / (2.0 * M_PI)) : angle[i];
      const double counted_advance =
          ticks > 0.0 ? (now - counted[i]) * 2.0 * M_PI / ticks : now - counted[i];
      counted[i] = now;
      value[i] = row[i] = counted_advance / dt;
    }
    previous = reading;
    run->log.encoders.t_s.push_back(grid.t_s[b]);
    run->log.encoders.samples.push_back(dt, value.data());
    run->recorded.push_back(std::move(row));
  }
}

ModelSimulatedRun SimulateRun(const RobotModelInterface& model, const std::vector<double>& p,
                              const TrajectorySpec& spec, const SimulationOptions& o, Rng& rng) {
  const TwistProfile profile(spec.segments, o);
  const FineGrid grid = MakeGrid(profile.end_s(), o);
  std::vector<std::vector<double>> readings;
  const EncoderSamples fine =
      o.dynamics ? DynamicChannels(*o.dynamics(model, p, spec), model.robot().NumChannels(),
                                   profile, grid, &readings)
                 : FineChannels(model, p.data(), profile, grid);
  ModelSimulatedRun run;
  run.true_start_pose = StartPose(o, rng);
  // The truth: the true model replayed on the fine grid.
  std::vector<Pose2d> truth(grid.t_s.size());
  truth[0] = run.true_start_pose;
  model.Replay(p.data(), fine, 0, fine.size(), run.true_start_pose,
               [&truth](std::size_t k, const Pose2d& pose) { truth[k + 1] = pose; });
  run.log.id = StrFormat("%s-rep%02d", spec.label.c_str(), spec.repetition);
  run.log.trajectory = spec.label;
  run.log.repetition = spec.repetition;
  for (const ChannelInfo& ch : model.robot().channels)
    run.encoder_columns.push_back(ch.rate_column);
  RecordEncoders(model, p.data(), profile, grid, fine, readings, o, rng, &run);
  run.log.ground_truth.t_s.reserve(grid.gt_index.size());
  run.log.ground_truth.world_T_robot.reserve(grid.gt_index.size());
  for (std::size_t j : grid.gt_index) {
    const Pose2d& t = truth[j];
    run.log.ground_truth.t_s.push_back(grid.t_s[j]);
    run.log.ground_truth.world_T_robot.push_back({t.x + rng.Normal(o.gt_position_sigma_m),
                                                  t.y + rng.Normal(o.gt_position_sigma_m),
                                                  t.theta + rng.Normal(o.gt_heading_sigma_rad)});
  }
  run.true_final_pose = truth[grid.encoder_index.back()];
  if (o.record_start_pose) run.log.start_pose = run.true_start_pose;
  return run;
}

}  // namespace

std::string SimulationOptions::Check(int num_channels) const {
  if (!(encoder_period_s > 0.0) || !(ground_truth_period_s > 0.0) || !(substep_s > 0.0)) {
    return "encoder_period_s, ground_truth_period_s and substep_s must be positive";
  }
  // The stepped physics has no ramps (the controller lag smooths the commands).
  const double half_ramp_s = stepped ? 0.0 : 0.5 * kRampTimeS;
  if (!(rest_before_s >= half_ramp_s) || !(rest_after_s >= half_ramp_s)) {
    return "rest_before_s and rest_after_s must hold half a ramp";
  }
  if (!ticks_per_rev.empty() && static_cast<int>(ticks_per_rev.size()) != num_channels) {
    return "ticks_per_rev needs one value per channel (" + std::to_string(num_channels) + ")";
  }
  for (double t : ticks_per_rev) {
    if (!(t >= 0.0)) return "ticks_per_rev must be >= 0";
  }
  if (stepped) {
    const std::string problem = CheckSteppedOptions(*stepped, encoder_period_s, num_channels);
    if (!problem.empty()) return problem;
  }
  if (stepped && dynamics) return "a model's own channel dynamics need perfect tracking";
  if (!(wheel_rate_sigma_rad_s >= 0.0) || !(wheel_relative_sigma >= 0.0) ||
      !(angle_sigma_rad >= 0.0) ||
      !(gt_position_sigma_m >= 0.0) || !(gt_heading_sigma_rad >= 0.0) ||
      !(start_position_range_m >= 0.0)) {
    return "noise sigmas and the start range must be >= 0";
  }
  return "";
}

std::vector<ModelSimulatedRun> SimulateRuns(const RobotModelInterface& model,
                                            const std::vector<double>& true_parameters,
                                            const std::vector<TrajectorySpec>& trajectories,
                                            const SimulationOptions& options) {
  const std::string problem = options.Check(model.robot().NumChannels());
  if (!problem.empty()) throw std::invalid_argument("simulation options: " + problem);
  if (static_cast<int>(true_parameters.size()) != model.robot().NumParameters()) {
    throw std::invalid_argument("the true parameter vector has the wrong length");
  }
  if (options.stepped && !options.stepped->commanded_parameters.empty() &&
      options.stepped->commanded_parameters.size() != true_parameters.size()) {
    throw std::invalid_argument("the commanded parameter vector has the wrong length");
  }
  // Runs are independent (each draws from its own generator): the output does not depend on the
  // number of threads.
  std::vector<ModelSimulatedRun> runs(trajectories.size());
  ParallelFor(runs.size(), 0, [&](std::size_t i) {
    if (options.stepped) {
      runs[i] = SimulateSteppedRun(model, true_parameters, trajectories[i], options, i);
      return;
    }
    Rng rng(options.seed, i);
    runs[i] = SimulateRun(model, true_parameters, trajectories[i], options, rng);
  });
  return runs;
}

std::string SimulatedEncoderCsv(const ModelSimulatedRun& run, EncoderCsvDigits digits) {
  const bool round_trip = digits == EncoderCsvDigits::kRoundTrip;
  std::string out = "t";
  for (const std::string& column : run.encoder_columns) out += "," + column;
  out += "\n";
  // At most 25 characters a field with its comma ("%.17g" of a negative number with a
  // three-digit exponent), 17 for "%.9g"; sized once, as the grid above.
  const std::size_t fields = run.recorded.size() * (1 + run.encoder_columns.size());
  out.reserve(out.size() + fields * (round_trip ? 25 : 17) + run.recorded.size());
  char field[64];
  for (std::size_t k = 0; k < run.recorded.size(); ++k) {
    std::snprintf(field, sizeof field, round_trip ? "%.17g" : "%.6f", run.log.encoders.t_s[k]);
    out += field;
    for (double v : run.recorded[k]) {
      std::snprintf(field, sizeof field, round_trip ? ",%.17g" : ",%.9g", v + 0.0);
      out += field;
    }
    out += "\n";
  }
  return out;
}

void WriteSimulatedDataset(const std::string& dir, const std::string& robot_yaml_text,
                           const std::vector<ModelSimulatedRun>& runs, EncoderCsvDigits digits) {
  namespace fs = std::filesystem;
  const fs::path out(dir);
  fs::create_directories(out / "runs");
  std::vector<io::DatasetEntry> entries;
  for (const ModelSimulatedRun& run : runs) {
    const RunLog& log = run.log;
    io::DatasetEntry e{log.id, log.trajectory, log.repetition, "runs/" + log.id + "_encoders.csv",
                       "runs/" + log.id + "_ground_truth.csv"};
    io::WriteFileAtomically((out / e.encoders).string(), SimulatedEncoderCsv(run, digits));
    io::WriteFileAtomically((out / e.ground_truth).string(),
                            io::GroundTruthCsv(run.log.ground_truth));
    entries.push_back(e);
  }
  io::WriteFileAtomically((out / "robot.yaml").string(), robot_yaml_text);
  io::WriteFileAtomically((out / "dataset.yaml").string(), io::DatasetYaml("robot.yaml", entries));
}

}  // namespace fitcal::sim
