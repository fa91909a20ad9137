#include "calib/residual_analysis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "calib/statistics.h"
#include "odometry/parallel_for.h"

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

std::string FamilyOf(const std::string& label) {
  std::string out;
  for (char ch : label) {
    if (std::isalpha(static_cast<unsigned char>(ch)))
      out += ch;
    else
      break;
  }
  return out.empty() ? "-" : out;
}

RunFeatures Features(const Omni3ParameterArray& p, const TrackRun& run) {
  RunFeatures f;
  f.id = run.aligned.id;
  f.trajectory = run.aligned.trajectory;
  f.family = FamilyOf(run.aligned.trajectory);
  f.repetition = run.aligned.repetition;
  const auto m_inv = omni3::InverseKinematicMatrix(p.data());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double time = 0.0;
  bool any = false;
  for (std::size_t k = 0; k < run.aligned.samples.size(); ++k) {
    if (!run.contexts[k].moving) continue;
    const WheelSample& s = run.aligned.samples[k];
    const Eigen::Vector3d w(s.rate_rad_s[0], s.rate_rad_s[1], s.rate_rad_s[2]);
    sum += s.dt_s * (m_inv * w);
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
  }
  return f;
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

}  // namespace

ResidualAnalysis AnalyzeResiduals(const Omni3ParameterArray& p, const EffectModel& model,
                                  const std::vector<TrackRun>& runs, int num_fitted_parameters,
                                  int num_threads) {
  ResidualAnalysis out;
  const std::size_t n = runs.size();
  out.runs.resize(n);
  out.track.resize(n);
  out.final_start_frame.resize(n);
  const ModelScore score = ScoreModel(p, model, runs, ResidualWeights{}, num_threads);
  std::vector<std::array<double, kLofComponents>> lof(n);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    const TrackRun& run = runs[i];
    out.runs[i] = Features(p, run);
    out.track[i] = ComputeTrackErrors(p, model, run, /*all_samples=*/true);
    const RunScore& s = score.runs[i];
    const double theta0 = run.aligned.start.theta;
    out.final_start_frame[i] =
        ToFrame(Pose2d{s.final_dx_m, s.final_dy_m, s.final_dtheta_rad}, theta0);
    const RunFeatures& f = out.runs[i];
    for (int c = 0; c < 3; ++c) {
      const double t = run.aligned.t_start_s + f.motion_begin_s +
                       kCheckpointFractions[c] * (f.motion_end_s - f.motion_begin_s);
      const Pose2d e = ToFrame(ErrorAt(out.track[i], t), theta0);
      lof[i][3 * c] = e.x;
      lof[i][3 * c + 1] = e.y;
      lof[i][3 * c + 2] = e.theta;
    }
    lof[i][9] = out.final_start_frame[i].x;
    lof[i][10] = out.final_start_frame[i].y;
    lof[i][11] = out.final_start_frame[i].theta;
  });

  // Systematic / non-systematic split and the lack-of-fit test, over trajectories with reps.
  std::map<std::string, std::vector<std::size_t>> by_trajectory;
  for (std::size_t i = 0; i < n; ++i) by_trajectory[runs[i].aligned.trajectory].push_back(i);
  std::array<double, kLofComponents> ss_pe{}, ss_lof{};
  double sys_m = 0.0, sys_rad = 0.0, non_m = 0.0, non_rad = 0.0;
  int num_traj = 0, num_runs = 0;
  double df_pe_per_component = 0.0;
  for (const auto& [label, members] : by_trajectory) {
    if (members.size() < 2) continue;
    ++num_traj;
    const double m = static_cast<double>(members.size());
    df_pe_per_component += m - 1.0;
    std::array<double, kLofComponents> mean{};
    for (std::size_t i : members) {
      for (int c = 0; c < kLofComponents; ++c) mean[c] += lof[i][c] / m;
    }
    for (int c = 0; c < kLofComponents; ++c) ss_lof[c] += m * mean[c] * mean[c];
    for (std::size_t i : members) {
      ++num_runs;
      for (int c = 0; c < kLofComponents; ++c) {
        const double d = lof[i][c] - mean[c];
        ss_pe[c] += d * d;
      }
      sys_m += mean[9] * mean[9] + mean[10] * mean[10];
      sys_rad += mean[11] * mean[11];
      non_m += std::pow(lof[i][9] - mean[9], 2) + std::pow(lof[i][10] - mean[10], 2);
      non_rad += std::pow(lof[i][11] - mean[11], 2);
    }
  }
  if (num_traj > 0 && df_pe_per_component > 0.0) {
    const double runs_d = static_cast<double>(num_runs);
    out.systematic_rms_m = std::sqrt(sys_m / runs_d);
    out.systematic_rms_rad = std::sqrt(sys_rad / runs_d);
    // Scatter around a mean of m values: divide by (m - 1) per trajectory, not m.
    out.nonsystematic_rms_m = std::sqrt(non_m / df_pe_per_component);
    out.nonsystematic_rms_rad = std::sqrt(non_rad / df_pe_per_component);
    double lof_w = 0.0;
    for (int c = 0; c < kLofComponents; ++c) {
      const double var = ss_pe[c] / df_pe_per_component;
      if (var > 0.0) lof_w += ss_lof[c] / var;
    }
    LackOfFit& l = out.lack_of_fit;
    l.trajectories_with_repetitions = num_traj;
    l.df_pe = kLofComponents * df_pe_per_component;
    l.df_lof =
        std::max(1.0, static_cast<double>(kLofComponents * num_traj - num_fitted_parameters));
    // lof_w ~ chi^2(df_lof) when the residual is noise; F = (lof_w / df_lof) / 1 with the
    // variances estimated on df_pe degrees of freedom.
    l.f = lof_w / l.df_lof;
    l.p_value = stats::FUpperTail(l.f, l.df_lof, l.df_pe);
    l.available = true;
  }

  // Group statistics.
  std::map<std::string, GroupStat> groups;
  for (std::size_t i = 0; i < n; ++i) {
    const RunFeatures& f = out.runs[i];
    const Pose2d& e = out.final_start_frame[i];
    const double v[3] = {e.x, e.y, e.theta};
    Accumulate(groups, "family", f.family, v);
    char bin[32];
    const double alpha_deg = std::fmod(RadToDeg(f.alpha_rad) + 360.0 + 15.0, 360.0) - 15.0;
    std::snprintf(bin, sizeof bin, "%+04.0f", 30.0 * std::round(alpha_deg / 30.0) + 0.0);
    Accumulate(groups, "alpha_deg", bin, v);
    Accumulate(groups, "rotation",
               f.rotation_sign > 0 ? "ccw" : (f.rotation_sign < 0 ? "cw" : "none"), v);
    std::snprintf(bin, sizeof bin, "%.2f", 0.05 * std::round(f.speed_m_s / 0.05));
    Accumulate(groups, "speed_m_s", bin, v);
    // Error growth rate between consecutive ground-truth samples, robot frame.
    const TrackErrors& t = out.track[i];
    const TrackRun& run = runs[i];
    for (std::size_t j = 1; j < t.t_s.size(); ++j) {
      const double dt = t.t_s[j] - t.t_s[j - 1];
      if (!(dt > 0.0)) continue;
      const Pose2d de{t.error[j].x - t.error[j - 1].x, t.error[j].y - t.error[j - 1].y,
                      t.error[j].theta - t.error[j - 1].theta};
      const Pose2d r = ToFrame(de, t.ground_truth[j - 1].theta);
      const double rate[3] = {r.x / dt, r.y / dt, r.theta / dt};
      const double mid = 0.5 * (t.t_s[j] + t.t_s[j - 1]) - run.aligned.t_start_s;
      // Phase from the sample context at mid.
      std::size_t k = 0;
      while (k + 1 < run.contexts.size() && run.contexts[k + 1].t_s <= mid) ++k;
      const auto& c = run.contexts[k];
      double accel = 0.0, dir = 0.0;
      for (int w = 0; w < 3; ++w) {
        if (std::abs(c.accel_rad_s2[w]) > std::abs(accel)) {
          accel = c.accel_rad_s2[w];
          dir = run.aligned.samples[k].rate_rad_s[w];
        }
      }
      const char* phase = !c.moving ? "rest"
                          : std::abs(accel) < kAccelerationPhaseRadS2
                              ? "cruise"
                              : (accel * dir > 0.0 ? "accelerate" : "decelerate");
      Accumulate(groups, "phase", phase, rate);
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
  for (auto& [key, g] : groups) {
    for (int c = 0; c < 3; ++c) {
      g.mean[c] /= g.count;
      g.rms[c] = std::sqrt(g.rms[c] / g.count);
    }
    out.groups.push_back(g);
  }
  return out;
}

std::string FormatResidualAnalysis(const ResidualAnalysis& a) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line,
                "final-pose residual (start frame): systematic %.4f m / %.3f deg, "
                "non-systematic (noise floor) %.4f m / %.3f deg\n",
                a.systematic_rms_m, RadToDeg(a.systematic_rms_rad), a.nonsystematic_rms_m,
                RadToDeg(a.nonsystematic_rms_rad));
  out += line;
  if (a.lack_of_fit.available) {
    std::snprintf(line, sizeof line,
                  "lack of fit vs pure error (%d trajectories with repetitions): F = %.2f on "
                  "(%.0f, %.0f) df, p = %.2g\n",
                  a.lack_of_fit.trajectories_with_repetitions, a.lack_of_fit.f,
                  a.lack_of_fit.df_lof, a.lack_of_fit.df_pe, a.lack_of_fit.p_value);
    out += line;
  } else {
    out += "lack of fit: not available (no trajectory has two repetitions)\n";
  }
  out +=
      "\n| by | bin | n | mean x | mean y | mean theta [deg] | rms x | rms y | rms theta [deg] |\n";
  out += "|---|---|---|---|---|---|---|---|---|\n";
  for (const GroupStat& g : a.groups) {
    const bool rate = g.by == "phase" || g.by == "time_in_run";
    std::snprintf(line, sizeof line,
                  "| %s%s | %s | %d | %+.4f | %+.4f | %+.3f | %.4f | %.4f | %.3f |\n", g.by.c_str(),
                  rate ? " (rate /s)" : "", g.bin.c_str(), g.count, g.mean[0], g.mean[1],
                  RadToDeg(g.mean[2]), g.rms[0], g.rms[1], RadToDeg(g.rms[2]));
    out += line;
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
