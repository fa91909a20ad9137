#include "diagnosis/residual_analysis.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "fit/statistics.h"
#include "odometry/parallel_for.h"
#include "odometry/text_format.h"
#include "validation/trajectory_family.h"

namespace fitcal {

namespace {

constexpr double kCheckpointFractions[] = {0.25, 0.5, 0.75};
constexpr int kLofComponents = 12;  // 4 checkpoints x (x, y, theta)
constexpr double kRotatingRateRadS = 0.02;
// Acceleration phase of a ground-truth interval: the largest smoothed wheel acceleration above
// this counts as accelerating or decelerating (cruising below it).
constexpr double kAccelerationPhaseRadS2 = 1.0;

Pose2d ToFrame(const Pose2d& world_error, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * world_error.x + s * world_error.y, -s * world_error.x + c * world_error.y,
          world_error.theta};
}

RunFeatures Features(const RobotModelInterface& robot_model, const std::vector<double>& p,
                     const TrackRun& run) {
  RunFeatures f;
  f.id = run.aligned.id;
  f.trajectory = run.aligned.trajectory;
  f.family = TrajectoryFamily(run.aligned.trajectory);
  f.repetition = run.aligned.repetition;
  f.start_heading_rad = run.aligned.start.theta;
  f.t_start_s = run.aligned.t_start_s;
  f.duration_s = run.aligned.t_final_s - run.aligned.t_start_s;
  const auto kinematics = robot_model.PrepareKinematics(p.data());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double time = 0.0;
  bool any = false;
  for (std::size_t k = 0; k < run.aligned.samples.size(); ++k) {
    if (!run.contexts[k].moving) continue;
    const auto s = run.aligned.samples[k];
    Eigen::Vector3d step;
    kinematics->Step(s.value, s.dt_s, &step[0], &step[1], &step[2]);
    sum += step;
    f.distance_m += std::hypot(step[0], step[1]);
    time += s.dt_s;
    if (!any) f.motion_begin_s = run.contexts[k].t_s;
    f.motion_end_s = run.contexts[k].t_s + s.dt_s;
    any = true;
  }
  if (time > 0.0) {
    const Eigen::Vector3d v = sum / time;
    f.alpha_rad = std::atan2(v[1], v[0]);
    f.speed_m_s = std::hypot(v[0], v[1]);
    f.rotation_sign = v[2] > kRotatingRateRadS ? 1 : (v[2] < -kRotatingRateRadS ? -1 : 0);
    f.yaw_rate_rad_s = v[2];
  }
  return f;
}

// Whether run b repeats the motion of run a (header: repetitions). Tolerances: what separates
// different commands (a 30 deg step of direction, a second speed, the other turning sign) while
// leaving the spread of one command's repetitions (slip, a few % of wear) inside.
bool SameMotion(const RunFeatures& a, const RunFeatures& b) {
  constexpr double kDirectionTolRad = M_PI / 6.0;
  constexpr double kRelativeTol = 0.2;
  constexpr double kSpeedFloorMS = 0.02, kYawFloorRadS = 0.02, kDistanceFloorM = 0.01;
  const auto close = [&](double x, double y, double floor) {
    return std::abs(x - y) <= kRelativeTol * std::max(std::abs(x), std::abs(y)) + floor;
  };
  if (a.rotation_sign != b.rotation_sign) return false;
  if (!close(a.speed_m_s, b.speed_m_s, kSpeedFloorMS)) return false;
  if (!close(a.yaw_rate_rad_s, b.yaw_rate_rad_s, kYawFloorRadS)) return false;
  if (!close(a.distance_m, b.distance_m, kDistanceFloorM)) return false;
  if (a.speed_m_s > kSpeedFloorMS && b.speed_m_s > kSpeedFloorMS &&
      std::abs(WrapAngle(a.alpha_rad - b.alpha_rad)) > kDirectionTolRad) {
    return false;
  }
  return true;
}

// Splits each label's runs into sets of the same motion, each matched against its first run.
void AssignRepetitionGroups(std::vector<RunFeatures>* runs) {
  std::map<std::string, std::vector<std::size_t>> leaders;  // label -> first run of each set
  for (std::size_t i = 0; i < runs->size(); ++i) {
    RunFeatures& f = (*runs)[i];
    std::vector<std::size_t>& sets = leaders[f.trajectory];
    std::size_t k = 0;
    while (k < sets.size() && !SameMotion((*runs)[sets[k]], f)) ++k;
    if (k == sets.size()) sets.push_back(i);
    f.repetition_group = k == 0 ? f.trajectory : f.trajectory + " #" + std::to_string(k + 1);
  }
}

Pose2d ErrorAt(const TrackErrors& e, double t) {
  if (e.t_s.empty()) return {};
  if (t <= e.t_s.front()) return e.error.front();
  if (t >= e.t_s.back()) return e.error.back();
  const std::size_t hi =
      static_cast<std::size_t>(std::upper_bound(e.t_s.begin(), e.t_s.end(), t) - e.t_s.begin());
  const std::size_t lo = hi - 1;
  const double u = (t - e.t_s[lo]) / (e.t_s[hi] - e.t_s[lo]);
  return {e.error[lo].x + u * (e.error[hi].x - e.error[lo].x),
          e.error[lo].y + u * (e.error[hi].y - e.error[lo].y),
          e.error[lo].theta + u * (e.error[hi].theta - e.error[lo].theta)};
}

using Lof = std::array<double, kLofComponents>;

// The lack-of-fit components of a run: its error at the three checkpoint times and at the end,
// in the start frame (heading theta0).
Lof LofComponents(const TrackErrors& track, const std::array<double, 3>& checkpoint_times,
                  double theta0) {
  Lof out{};
  for (int c = 0; c < 3; ++c) {
    const Pose2d e = ToFrame(ErrorAt(track, checkpoint_times[c]), theta0);
    out[3 * c] = e.x;
    out[3 * c + 1] = e.y;
    out[3 * c + 2] = e.theta;
  }
  const Pose2d f = ToFrame(track.final_error, theta0);
  out[9] = f.x;
  out[10] = f.y;
  out[11] = f.theta;
  return out;
}

void Accumulate(std::map<std::string, GroupStat>& groups, const std::string& by,
                const std::string& bin, const double v[3]) {
  GroupStat& g = groups[by + "\x1f" + bin];
  g.by = by;
  g.bin = bin;
  ++g.count;
  for (int c = 0; c < 3; ++c) {
    g.mean[c] += v[c];
    g.rms[c] += v[c] * v[c];
  }
}

// Wheel channels with a known absolute start angle, the same in every run; empty when a run
// lacks one.
std::vector<int> WheelsWithAbsoluteAngle(const std::vector<const TrackRun*>& runs) {
  std::vector<int> out;
  if (runs.empty() || runs.front()->contexts.empty()) return out;
  const effects::SampleContext& c0 = runs.front()->contexts.front();
  for (int i = 0; i < c0.num_channels; ++i) {
    bool known = c0.IsWheel(i);
    for (const TrackRun* r : runs) {
      known = known && static_cast<int>(r->start_wheel_angle_rad.size()) > i &&
              std::isfinite(r->start_wheel_angle_rad[i]);
    }
    if (known) out.push_back(i);
  }
  return out;
}

// The final-pose (start frame) change per unit of a once-per-revolution rate error of one wheel
// at its absolute angle: the library's once_per_revolution (effects.h) replayed on contexts that
// mark only that wheel and carry its absolute angle. Columns: (cos, sin) per wheel.
Eigen::MatrixXd WheelAngleJacobian(const RobotModelInterface& robot_model,
                                   const std::vector<double>& p, const EffectModel& model,
                                   const TrackRun& run, const std::vector<int>& wheels) {
  constexpr double kStep = 1e-4;  // relative rate error: linear to ~1e-8, far above rounding
  Eigen::MatrixXd out(3, 2 * static_cast<int>(wheels.size()));
  TrackRun moved = run;
  const double theta0 = run.aligned.start.theta;
  for (std::size_t w = 0; w < wheels.size(); ++w) {
    const int i = wheels[w];
    for (std::size_t k = 0; k < run.contexts.size(); ++k) {
      moved.contexts[k].wheel_mask = 1u << i;
      moved.contexts[k].angle_rad[i] = run.contexts[k].angle_rad[i] + run.start_wheel_angle_rad[i];
    }
    EffectModel with = model;
    with.push_back({});
    with.back().id = effects::EffectId::kOncePerRevolution;
    const Pose2d base =
        ToFrame(ComputeTrackErrors(robot_model, p, with, moved, false).final_error, theta0);
    for (int j = 0; j < 2; ++j) {
      with.back().value = {};
      with.back().value[j] = kStep;
      const Pose2d e =
          ToFrame(ComputeTrackErrors(robot_model, p, with, moved, false).final_error, theta0);
      const int col = 2 * static_cast<int>(w) + j;
      out(0, col) = (e.x - base.x) / kStep;
      out(1, col) = (e.y - base.y) / kStep;
      out(2, col) = WrapAngle(e.theta - base.theta) / kStep;
    }
  }
  return out;
}

// The residual against the sensors' own noise (sensor_noise_floor.h), on the lack-of-fit
// components: the three checkpoints and the window's end.
void AddSensorFloor(const std::vector<const TrackRun*>& runs, const std::vector<Lof>& lof,
                    const std::vector<std::vector<Lof>>& lof_jacobian,
                    const std::vector<std::array<double, 3>>& checkpoint_times, int num_threads,
                    ResidualAnalysis* out) {
  out->sensor_noise = EstimateSensorNoise(out->track);
  if (!out->sensor_noise.available) return;
  const std::size_t n = runs.size();
  std::vector<Eigen::VectorXd> e(n);
  std::vector<Eigen::MatrixXd> jacobian(n), covariance(n);
  std::vector<std::string> group(n);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    const TrackErrors& track = out->track[i];
    if (track.t_s.empty()) return;
    const std::vector<double> times = {checkpoint_times[i][0], checkpoint_times[i][1],
                                       checkpoint_times[i][2], track.t_s.back()};
    covariance[i] =
        PropagateSensorNoise(out->sensor_noise, track, times, runs[i]->aligned.start.theta);
    e[i] = Eigen::Map<const Eigen::VectorXd>(lof[i].data(), kLofComponents);
    jacobian[i].resize(kLofComponents, static_cast<int>(lof_jacobian.size()));
    for (std::size_t k = 0; k < lof_jacobian.size(); ++k) {
      jacobian[i].col(static_cast<int>(k)) =
          Eigen::Map<const Eigen::VectorXd>(lof_jacobian[k][i].data(), kLofComponents);
    }
    group[i] = out->runs[i].repetition_group;
  });
  std::vector<Eigen::VectorXd> e_used;
  std::vector<Eigen::MatrixXd> jacobian_used, covariance_used;
  std::vector<std::string> group_used;
  for (std::size_t i = 0; i < n; ++i) {
    if (covariance[i].size() == 0) continue;  // a run without ground truth in its window
    e_used.push_back(e[i]);
    jacobian_used.push_back(jacobian[i]);
    covariance_used.push_back(covariance[i]);
    group_used.push_back(group[i]);
  }
  out->sensor_floor = TestAgainstSensorFloor(e_used, jacobian_used, covariance_used, group_used);
}

// Per run: its features, track errors (every sample), final error in the start frame, the
// checkpoint times (fractions of its motion) and its lack-of-fit components there.
struct RunComponents {
  std::vector<Lof> lof;
  std::vector<std::array<double, 3>> checkpoint_times;
};
RunComponents AddRunResiduals(const RobotModelInterface& robot_model, const std::vector<double>& p,
                              const EffectModel& model, const std::vector<const TrackRun*>& runs,
                              int num_threads, ResidualAnalysis* out) {
  const std::size_t n = runs.size();
  out->runs.resize(n);
  out->track.resize(n);
  out->final_start_frame.resize(n);
  RunComponents rc;
  rc.lof.resize(n);
  rc.checkpoint_times.resize(n);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    const TrackRun& run = *runs[i];
    out->runs[i] = Features(robot_model, p, run);
    out->track[i] = ComputeTrackErrors(robot_model, p, model, run, /*all_samples=*/true);
    const double theta0 = run.aligned.start.theta;
    out->final_start_frame[i] = ToFrame(out->track[i].final_error, theta0);
    const RunFeatures& f = out->runs[i];
    for (int c = 0; c < 3; ++c) {
      rc.checkpoint_times[i][c] = run.aligned.t_start_s + f.motion_begin_s +
                                  kCheckpointFractions[c] * (f.motion_end_s - f.motion_begin_s);
    }
    rc.lof[i] = LofComponents(out->track[i], rc.checkpoint_times[i], theta0);
  });
  return rc;
}

// How the components move with each fitted parameter (forward differences, the checkpoint times
// held): the lack of fit is what no change of the fitted parameters can remove. [parameter][run]:
// the model's free parameters, then every parameter of every effect.
std::vector<std::vector<Lof>> LofJacobian(const RobotModelInterface& robot_model,
                                          const std::vector<double>& p, const EffectModel& model,
                                          const std::vector<const TrackRun*>& runs,
                                          const RunComponents& rc, int num_threads) {
  const std::size_t n = runs.size();
  std::vector<std::vector<Lof>> lof_jacobian;
  // One column: the components' change per unit of the parameter that p_k / model_k moved by h.
  const auto add_column = [&](const std::vector<double>& p_k, const EffectModel& model_k,
                              double h) {
    std::vector<Lof> column(n);
    ParallelFor(n, num_threads, [&](std::size_t i) {
      const TrackErrors moved = ComputeTrackErrors(robot_model, p_k, model_k, *runs[i], true);
      const Lof x = LofComponents(moved, rc.checkpoint_times[i], runs[i]->aligned.start.theta);
      for (int c = 0; c < kLofComponents; ++c) column[i][c] = (x[c] - rc.lof[i][c]) / h;
    });
    lof_jacobian.push_back(std::move(column));
  };
  for (int k = 0; k < static_cast<int>(p.size()); ++k) {
    if (robot_model.robot().IsHeld(k)) continue;  // gauge: no refit can move it
    std::vector<double> p_k = p;
    const double h = 1e-6 * std::max(std::abs(p[k]), 1e-3);
    p_k[k] += h;
    add_column(p_k, model, h);
  }
  for (std::size_t e = 0; e < model.size(); ++e) {
    const effects::EffectInfo& info = effects::Info(model[e].id);
    for (int j = 0; j < info.num_parameters; ++j) {
      EffectModel model_k = model;
      const double h =
          1e-4 * std::max({std::abs(model[e].value[j]), std::abs(info.typical[j]), 1e-9});
      model_k[e].value[j] += h;
      add_column(p, model_k, h);
    }
  }
  return lof_jacobian;
}

// The final-pose rows (components 9-11) of the lack-of-fit Jacobian, one 3 x parameters matrix
// per run.
void AddFinalJacobian(const std::vector<std::vector<Lof>>& lof_jacobian, std::size_t n,
                      ResidualAnalysis* out) {
  out->final_jacobian.assign(n, Eigen::MatrixXd::Zero(3, static_cast<int>(lof_jacobian.size())));
  for (std::size_t k = 0; k < lof_jacobian.size(); ++k) {
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c)
        out->final_jacobian[i](c, static_cast<int>(k)) = lof_jacobian[k][i][9 + c];
    }
  }
}

void AddWheelAngleJacobians(const RobotModelInterface& robot_model, const std::vector<double>& p,
                            const EffectModel& model, const std::vector<const TrackRun*>& runs,
                            int num_threads, ResidualAnalysis* out) {
  const std::vector<int> angle_wheels = WheelsWithAbsoluteAngle(runs);
  if (angle_wheels.empty()) return;
  out->wheel_angle_jacobian.resize(runs.size());
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    out->wheel_angle_jacobian[i] =
        WheelAngleJacobian(robot_model, p, model, *runs[i], angle_wheels);
  });
}

using LofVector = Eigen::Matrix<double, kLofComponents, 1>;
using LofMatrix = Eigen::Matrix<double, kLofComponents, kLofComponents>;

// One trajectory with repetitions: the mean of its runs' components and of their Jacobians.
struct TrajectoryMean {
  double m;  // runs
  LofVector mean;
  Eigen::Matrix<double, kLofComponents, Eigen::Dynamic> jacobian;  // mean over its runs
};

// The runs of every trajectory with repetitions around their trajectory's mean: the pooled
// scatter (pure error) and the systematic / non-systematic sums of the final pose.
struct RepetitionScatter {
  std::vector<TrajectoryMean> means;
  LofMatrix scatter = LofMatrix::Zero();
  double sys_m = 0.0, sys_rad = 0.0, non_m = 0.0, non_rad = 0.0;
  int num_traj = 0, num_runs = 0;
  double df_pe_per_component = 0.0;
};
RepetitionScatter ScatterOverRepetitions(const ResidualAnalysis& a, const std::vector<Lof>& lof,
                                         const std::vector<std::vector<Lof>>& lof_jacobian) {
  std::map<std::string, std::vector<std::size_t>> by_trajectory;
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    by_trajectory[a.runs[i].repetition_group].push_back(i);
  }
  const int num_parameters = static_cast<int>(lof_jacobian.size());
  RepetitionScatter r;
  for (const auto& [label, members] : by_trajectory) {
    if (members.size() < 2) continue;
    ++r.num_traj;
    const double m = static_cast<double>(members.size());
    r.df_pe_per_component += m - 1.0;
    TrajectoryMean t{m, LofVector::Zero(),
                     Eigen::Matrix<double, kLofComponents, Eigen::Dynamic>::Zero(kLofComponents,
                                                                                 num_parameters)};
    for (std::size_t i : members) {
      t.mean += LofVector(lof[i].data()) / m;
      for (int k = 0; k < num_parameters; ++k)
        t.jacobian.col(k) += LofVector(lof_jacobian[k][i].data()) / m;
    }
    for (std::size_t i : members) {
      ++r.num_runs;
      const LofVector d = LofVector(lof[i].data()) - t.mean;
      r.scatter += d * d.transpose();
      r.sys_m += t.mean[9] * t.mean[9] + t.mean[10] * t.mean[10];
      r.sys_rad += t.mean[11] * t.mean[11];
      r.non_m += d[9] * d[9] + d[10] * d[10];
      r.non_rad += d[11] * d[11];
    }
    r.means.push_back(std::move(t));
  }
  return r;
}

// Systematic / non-systematic split and the lack-of-fit test, over trajectories with reps.
// The 12 components of a run (errors at three checkpoints and at the end, x, y, theta) are
// strongly correlated (an error at half way persists to the end), so each trajectory's mean is
// weighed with the inverse of their pooled within-trajectory covariance (a Hotelling-type
// statistic): weighing each component by its own variance alone counts one deviation up to 12
// times and makes F far more variable than F(df_lof, df_pe) (clean simulated data then read as
// "structure" for some seeds).
void AddLackOfFit(const RepetitionScatter& r, int num_parameters, ResidualAnalysis* out) {
  if (r.num_traj == 0 || !(r.df_pe_per_component > 0.0)) return;
  const double runs_d = static_cast<double>(r.num_runs);
  out->systematic_rms_m = std::sqrt(r.sys_m / runs_d);
  out->systematic_rms_rad = std::sqrt(r.sys_rad / runs_d);
  // Scatter around a mean of m values: divide by (m - 1) per trajectory, not m.
  out->nonsystematic_rms_m = std::sqrt(r.non_m / r.df_pe_per_component);
  out->nonsystematic_rms_rad = std::sqrt(r.non_rad / r.df_pe_per_component);
  // Whitening by the pure-error covariance; directions without scatter (noise-free data) are
  // left out.
  const Eigen::SelfAdjointEigenSolver<LofMatrix> eig(r.scatter / r.df_pe_per_component);
  const double largest = eig.eigenvalues().maxCoeff();
  LofMatrix whiten = LofMatrix::Zero();
  int rank = 0;
  for (int c = 0; c < kLofComponents; ++c) {
    const double lambda = eig.eigenvalues()[c];
    if (!(lambda > 1e-12 * largest)) continue;
    whiten.row(rank++) = eig.eigenvectors().col(c).transpose() / std::sqrt(lambda);
  }
  // Weighted least squares over the trajectory means: the linearised refit of the parameters
  // on all runs. lof_w is its residual, ~ chi^2(rank * trajectories - identifiable parameters)
  // when what is left is noise.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(num_parameters, num_parameters);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(num_parameters);
  double total = 0.0;
  for (const TrajectoryMean& t : r.means) {
    const Eigen::VectorXd z = whiten.topRows(rank) * t.mean;
    const Eigen::MatrixXd jz = whiten.topRows(rank) * t.jacobian;
    total += t.m * z.squaredNorm();
    a += t.m * jz.transpose() * jz;
    b += t.m * jz.transpose() * z;
  }
  int identifiable = 0;
  const double explained = ExplainedByLinearisedRefit(a, b, &identifiable);
  const double lof_w = std::max(0.0, total - explained);
  // The covariance is estimated on df_pe_per_component degrees of freedom; the Hotelling
  // correction leaves df_pe_per_component - rank + 1 for the denominator.
  if (rank > 0 && r.df_pe_per_component - rank + 1.0 > 0.0) {
    LackOfFit& l = out->lack_of_fit;
    l.trajectories_with_repetitions = r.num_traj;
    l.df_pe = r.df_pe_per_component - rank + 1.0;
    l.df_lof = std::max(1.0, static_cast<double>(rank * r.num_traj - identifiable));
    l.f = lof_w / l.df_lof;
    l.p_value = stats::FUpperTail(l.f, l.df_lof, l.df_pe);
    l.available = true;
  }
}

// The final error of a run binned by its features: family, direction, rotation, speed.
void AccumulateByFeatures(const RunFeatures& f, const Pose2d& e,
                          std::map<std::string, GroupStat>& groups) {
  const double v[3] = {e.x, e.y, e.theta};
  Accumulate(groups, "family", f.family, v);
  const double alpha_deg = std::fmod(RadToDeg(f.alpha_rad) + 360.0 + 15.0, 360.0) - 15.0;
  Accumulate(groups, "alpha_deg", StrFormat("%+04.0f", 30.0 * std::round(alpha_deg / 30.0) + 0.0),
             v);
  Accumulate(groups, "rotation",
             f.rotation_sign > 0 ? "ccw" : (f.rotation_sign < 0 ? "cw" : "none"), v);
  Accumulate(groups, "speed_m_s", StrFormat("%.2f", 0.05 * std::round(f.speed_m_s / 0.05)), v);
}

// The phase of the motion at `mid` (s since the window's start), from the sample context:
// rest, cruise, accelerate or decelerate by the largest wheel acceleration.
const char* PhaseAt(const TrackRun& run, double mid) {
  // The last sample starting at or before `mid` (the first when none does); the samples are in
  // time order, so a binary search finds it (a scan from the first, per ground-truth sample, made
  // the error-growth table quadratic in a run's length).
  const auto after = std::upper_bound(
      run.contexts.begin() + 1, run.contexts.end(), mid,
      [](double t, const effects::SampleContext& context) { return t < context.t_s; });
  const std::size_t k = static_cast<std::size_t>(after - run.contexts.begin()) - 1;
  const auto& c = run.contexts[k];
  double accel = 0.0, dir = 0.0;
  for (int w = 0; w < c.num_channels; ++w) {
    if (c.IsWheel(w) && std::abs(c.accel_rad_s2(w)) > std::abs(accel)) {
      accel = c.accel_rad_s2(w);
      dir = run.aligned.samples[k].value[w];
    }
  }
  return !c.moving ? "rest"
         : std::abs(accel) < kAccelerationPhaseRadS2
             ? "cruise"
             : (accel * dir > 0.0 ? "accelerate" : "decelerate");
}

// Error growth rate between consecutive ground-truth samples, robot frame, binned by the phase of
// the motion and by the time in the run.
void AccumulateErrorGrowth(const TrackRun& run, const TrackErrors& t, const RunFeatures& f,
                           std::map<std::string, GroupStat>& groups) {
  for (std::size_t j = 1; j < t.t_s.size(); ++j) {
    const double dt = t.t_s[j] - t.t_s[j - 1];
    if (!(dt > 0.0)) continue;
    const Pose2d de{t.error[j].x - t.error[j - 1].x, t.error[j].y - t.error[j - 1].y,
                    t.error[j].theta - t.error[j - 1].theta};
    const Pose2d r = ToFrame(de, t.ground_truth[j - 1].theta);
    const double rate[3] = {r.x / dt, r.y / dt, r.theta / dt};
    const double mid = 0.5 * (t.t_s[j] + t.t_s[j - 1]) - run.aligned.t_start_s;
    Accumulate(groups, "phase", PhaseAt(run, mid), rate);
    const double span = f.motion_end_s - f.motion_begin_s;
    const double frac = span > 0.0 ? (mid - f.motion_begin_s) / span : 0.0;
    const char* when = frac < 0.0    ? "before motion"
                       : frac < 0.25 ? "0-25%"
                       : frac < 0.5  ? "25-50%"
                       : frac < 0.75 ? "50-75%"
                       : frac <= 1.0 ? "75-100%"
                                     : "after motion";
    Accumulate(groups, "time_in_run", when, rate);
  }
}

// Group statistics: mean and RMS of each bin.
void AddGroupStatistics(const std::vector<const TrackRun*>& runs, ResidualAnalysis* out) {
  std::map<std::string, GroupStat> groups;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    AccumulateByFeatures(out->runs[i], out->final_start_frame[i], groups);
    AccumulateErrorGrowth(*runs[i], out->track[i], out->runs[i], groups);
  }
  for (auto& [key, g] : groups) {
    for (int c = 0; c < 3; ++c) {
      g.mean[c] /= g.count;
      g.rms[c] = std::sqrt(g.rms[c] / g.count);
    }
    out->groups.push_back(g);
  }
}

}  // namespace

ResidualAnalysis AnalyzeResiduals(const RobotModelInterface& robot_model,
                                  const std::vector<double>& p, const EffectModel& model,
                                  const std::vector<const TrackRun*>& runs, int num_threads) {
  ResidualAnalysis out;
  const RunComponents rc = AddRunResiduals(robot_model, p, model, runs, num_threads, &out);
  const std::vector<std::vector<Lof>> lof_jacobian =
      LofJacobian(robot_model, p, model, runs, rc, num_threads);
  AddFinalJacobian(lof_jacobian, runs.size(), &out);
  AddWheelAngleJacobians(robot_model, p, model, runs, num_threads, &out);
  AssignRepetitionGroups(&out.runs);
  AddSensorFloor(runs, rc.lof, lof_jacobian, rc.checkpoint_times, num_threads, &out);
  AddLackOfFit(ScatterOverRepetitions(out, rc.lof, lof_jacobian),
               static_cast<int>(lof_jacobian.size()), &out);
  AddGroupStatistics(runs, &out);
  return out;
}

std::string FormatResidualAnalysis(const ResidualAnalysis& a) {
  std::string out = StrFormat(
      "final-pose residual (start frame): systematic %.4f m / %.3f deg, non-systematic (noise "
      "floor) %.4f m / %.3f deg\n",
      a.systematic_rms_m, RadToDeg(a.systematic_rms_rad), a.nonsystematic_rms_m,
      RadToDeg(a.nonsystematic_rms_rad));
  if (a.lack_of_fit.available) {
    out += StrFormat(
        "lack of fit vs pure error (%d trajectories with repetitions): F = %.2f on (%.0f, %.0f) "
        "df, p = %.2g\n",
        a.lack_of_fit.trajectories_with_repetitions, a.lack_of_fit.f, a.lack_of_fit.df_lof,
        a.lack_of_fit.df_pe, a.lack_of_fit.p_value);
  } else {
    out += "lack of fit: not available (no trajectory has two repetitions)\n";
  }
  out += FormatSensorFloor(a.sensor_noise, a.sensor_floor);
  out +=
      "\n| by | bin | n | mean x | mean y | mean theta [deg] | rms x | rms y | rms theta [deg] |\n";
  out += "|---|---|---|---|---|---|---|---|---|\n";
  for (const GroupStat& g : a.groups) {
    const bool rate = g.by == "phase" || g.by == "time_in_run";
    out += StrFormat("| %s%s | %s | %d | %+.4f | %+.4f | %+.3f | %.4f | %.4f | %.3f |\n",
                     g.by.c_str(), rate ? " (rate /s)" : "", g.bin.c_str(), g.count, g.mean[0],
                     g.mean[1], RadToDeg(g.mean[2]), g.rms[0], g.rms[1], RadToDeg(g.rms[2]));
  }
  return out;
}

std::string ResidualSamplesCsv(const ResidualAnalysis& a) {
  std::string out = "run,t,err_x_world_m,err_y_world_m,err_theta_rad,err_x_robot_m,err_y_robot_m\n";
  char line[256];
  for (std::size_t i = 0; i < a.track.size(); ++i) {
    const TrackErrors& t = a.track[i];
    for (std::size_t j = 0; j < t.t_s.size(); ++j) {
      const Pose2d r = ToFrame(t.error[j], t.ground_truth[j].theta);
      std::snprintf(line, sizeof line, "%s,%.6f,%.6g,%.6g,%.6g,%.6g,%.6g\n", a.runs[i].id.c_str(),
                    t.t_s[j], t.error[j].x, t.error[j].y, t.error[j].theta, r.x, r.y);
      out += line;
    }
  }
  return out;
}

}  // namespace fitcal
