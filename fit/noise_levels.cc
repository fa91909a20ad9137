#include "fit/noise_levels.h"

#include <ceres/cost_function.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "fit/statistics.h"
#include "odometry/pose2.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

// Weighted sums of squares of one component pair (position, heading) and the runs behind them.
struct ComponentSums {
  double position = 0.0;
  double heading = 0.0;
  int runs = 0;
  double inverse_checkpoints = 0.0;  // sum over the runs of 1 / K
};

// Adds the residuals of `cost` at `parameters` to `sums` and to the run's session's; false when
// the replay fails.
bool AddResiduals(const ceres::CostFunction& cost, const double* const* parameters,
                  ComponentSums* sums, ComponentSums* session) {
  std::vector<double> r(cost.num_residuals());
  if (!cost.Evaluate(parameters, r.data(), nullptr)) return false;
  for (ComponentSums* to : {sums, session}) {
    for (std::size_t i = 0; i + 2 < r.size(); i += 3) {
      to->position += r[i] * r[i] + r[i + 1] * r[i + 1];
      to->heading += r[i + 2] * r[i + 2];
    }
    ++to->runs;
    to->inverse_checkpoints += 3.0 / static_cast<double>(std::max<std::size_t>(3, r.size()));
  }
  return true;
}

// A sigma that stays usable as a weight on noise-free data.
constexpr double kSmallestSigma = 1e-9;

double SigmaOf(double sum, double count) {
  return std::max(kSmallestSigma, std::sqrt(sum / count));
}

double Ratio(double a, double b) { return a / std::max(b, kSmallestSigma); }

// One session's residuals of one component: the weighted sum of squares, the count the estimate
// divides it by, and the degrees of freedom of its variance (header).
struct SessionSum {
  double squares = 0.0;
  double count = 0.0;
  double degrees = 0.0;
  double Variance() const { return squares / count; }
};

SessionSum SumOf(const ComponentSums& sums, bool heading, double redundancy) {
  const double dimension = heading ? 1.0 : 2.0;
  const double runs = sums.runs;
  return {heading ? sums.heading : sums.position, dimension * runs * redundancy,
          dimension * runs * runs / std::max(sums.inverse_checkpoints, 1e-300) * redundancy};
}

// The sessions in `pool` together: N = sum nu_s and v_p = sum nu_s v_s / N (header).
struct Pool {
  double degrees = 0.0;
  double variance = 0.0;
};
Pool PoolOf(const std::vector<SessionSum>& s, const std::vector<int>& pool) {
  double n = 0.0, weighted = 0.0;
  for (int i : pool) n += s[i].degrees, weighted += s[i].degrees * s[i].Variance();
  return {n, weighted / n};
}

// Bartlett's test that the sessions in `pool` share one variance (header): its p.
double BartlettP(const std::vector<SessionSum>& s, const std::vector<int>& pool) {
  const Pool pooled = PoolOf(s, pool);
  const double n = pooled.degrees;
  double logs = 0.0, inverse = 0.0;
  for (int i : pool) {
    logs += s[i].degrees * std::log(std::max(s[i].Variance(), 1e-300));
    inverse += 1.0 / s[i].degrees;
  }
  const double k = static_cast<double>(pool.size());
  const double t = n * std::log(std::max(pooled.variance, 1e-300)) - logs;
  const double correction = 1.0 + (inverse - 1.0 / n) / (3.0 * (k - 1.0));
  return stats::ChiSquareUpperTail(t / correction, k - 1.0);
}

// The session in `pool` farthest from the pool's variance: the largest nu_s (ln v_s - ln v_p)^2.
std::size_t Farthest(const std::vector<SessionSum>& s, const std::vector<int>& pool) {
  const double pooled_variance = PoolOf(s, pool).variance;
  std::size_t out = 0;
  double largest = -1.0;
  for (std::size_t j = 0; j < pool.size(); ++j) {
    const double d = std::log(std::max(s[pool[j]].Variance(), 1e-300) / pooled_variance);
    if (s[pool[j]].degrees * d * d > largest) largest = s[pool[j]].degrees * d * d, out = j;
  }
  return out;
}

// One component's levels per session (header): the sessions that differ split off one by one;
// the rest share their pooled level, `data_set_sigma` when none split.
void SplitSessions(const std::vector<SessionSum>& s, double data_set_sigma, double alpha,
                   std::vector<double>* sigma, std::vector<double>* split_p) {
  sigma->assign(s.size(), data_set_sigma);
  split_p->assign(s.size(), -1.0);
  std::vector<int> pool;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i].degrees >= kMinSessionDegrees) pool.push_back(static_cast<int>(i));
  }
  bool split = false;
  while (pool.size() >= 2) {
    const double p = BartlettP(s, pool);
    if (!(p < alpha)) break;
    const std::size_t j = Farthest(s, pool);
    (*split_p)[pool[j]] = p;
    (*sigma)[pool[j]] = SigmaOf(s[pool[j]].squares, s[pool[j]].count);
    pool.erase(pool.begin() + static_cast<std::ptrdiff_t>(j));
    split = true;
  }
  if (!split) return;
  double squares = 0.0, count = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if ((*split_p)[i] < 0.0) squares += s[i].squares, count += s[i].count;
  }
  for (std::size_t i = 0; i < s.size(); ++i) {
    if ((*split_p)[i] < 0.0) (*sigma)[i] = SigmaOf(squares, count);
  }
}

// The sessions' levels of every component from their sums (header).
SessionNoise SessionLevels(const NoiseLevels& data_set, const std::vector<ComponentSums>& tracks,
                           const std::vector<ComponentSums>& finals, double redundancy) {
  SessionNoise out;
  const double data_set_sigma[] = {data_set.track_position_m, data_set.track_heading_rad,
                                   data_set.final_position_m, data_set.final_heading_rad};
  const int components = data_set.with_final_poses ? 4 : 2;
  for (int c = 0; c < kNumNoiseComponents; ++c) {
    const std::vector<ComponentSums>& sums = c < 2 ? tracks : finals;
    std::vector<SessionSum> s;
    for (const ComponentSums& session : sums) s.push_back(SumOf(session, c % 2 == 1, redundancy));
    if (c >= components) s.assign(sums.size(), SessionSum{});  // not a component of this fit
    SplitSessions(s, data_set_sigma[c], kSessionAlpha / components, &out.sigma[c],
                  &out.split_p[c]);
  }
  return out;
}

}  // namespace

bool SessionNoise::Differs(int component) const {
  const std::vector<double>& p = split_p[component];
  return std::any_of(p.begin(), p.end(), [](double split) { return split >= 0.0; });
}

bool SessionNoise::AnyDiffers() const {
  for (int c = 0; c < kNumNoiseComponents; ++c) {
    if (Differs(c)) return true;
  }
  return false;
}

NoiseLevels EstimateNoiseLevels(const std::vector<AlignedRun>& training,
                                const RobotModelInterface& model, const std::vector<double>& p,
                                const std::vector<double>& clock_offsets_s,
                                const TrackFitData& track, bool final_poses, int num_estimated,
                                bool per_session) {
  NoiseLevels out;
  SessionNoise& sessions = out.sessions;
  RunGroups groups = GroupRuns(training, ClockGrouping::kPerSession);
  sessions.names = std::move(groups.names);
  sessions.of_run = std::move(groups.of_run);
  std::vector<ComponentSums> session_tracks(sessions.names.size());
  std::vector<ComponentSums> session_finals(sessions.names.size());
  out.with_final_poses = final_poses;
  // Unit weights and no Huber: the residuals in metres and radians, each run's checkpoints
  // weighed 1/sqrt(K) as in the fit.
  TrackResidualOptions plain = track.options;
  plain.huber_scale = std::sqrt(std::numeric_limits<double>::max());
  ComponentSums tracks, finals;
  int residuals = 0;
  for (std::size_t i = 0; i < training.size() && i < track.runs.size(); ++i) {
    const TrackCheckpoints& run = track.runs[i];
    if (!run.segments.empty()) {
      const std::unique_ptr<ceres::CostFunction> cost(
          TrackResidual::Create(run, model, ResidualWeights{}, plain));
      const double* parameters[] = {p.data(), &clock_offsets_s[run.clock_group]};
      if (!AddResiduals(*cost, parameters, &tracks, &session_tracks[sessions.of_run[i]]))
        return out;
      residuals += cost->num_residuals();
    }
    if (!final_poses) continue;
    const std::unique_ptr<ceres::CostFunction> cost(
        model.FinalPoseCost(training[i], ResidualWeights{}));
    const double* parameters[] = {p.data()};
    if (!AddResiduals(*cost, parameters, &finals, &session_finals[sessions.of_run[i]]))
      return out;
    residuals += cost->num_residuals();
  }
  const double redundancy = 1.0 - static_cast<double>(num_estimated) / std::max(1, residuals);
  if (tracks.runs == 0 || !(redundancy > 0.0)) return out;
  out.track_position_m = SigmaOf(tracks.position, 2.0 * tracks.runs * redundancy);
  out.track_heading_rad = SigmaOf(tracks.heading, tracks.runs * redundancy);
  if (final_poses && finals.runs > 0) {
    out.final_position_m = SigmaOf(finals.position, 2.0 * finals.runs * redundancy);
    out.final_heading_rad = SigmaOf(finals.heading, finals.runs * redundancy);
  }
  out.estimated = true;
  if (per_session) {
    SessionNoise levels = SessionLevels(out, session_tracks, session_finals, redundancy);
    levels.names = std::move(sessions.names);
    levels.of_run = std::move(sessions.of_run);
    sessions = std::move(levels);
  }
  return out;
}

FitWeights WeightsFromNoiseLevels(const NoiseLevels& levels) {
  FitWeights w;
  if (!levels.estimated) return w;
  const double reference = levels.track_position_m;
  w.track = {1.0, Ratio(levels.track_heading_rad, reference)};
  if (levels.with_final_poses) {
    w.final_pose = {Ratio(levels.final_position_m, reference),
                    Ratio(levels.final_heading_rad, reference)};
  }
  return w;
}

std::vector<FitWeights> WeightsPerRun(const NoiseLevels& levels) {
  const SessionNoise& s = levels.sessions;
  if (!levels.estimated || !s.AnyDiffers()) return {};
  std::vector<FitWeights> out;
  const double reference = levels.track_position_m;
  for (int session : s.of_run) {
    FitWeights w;
    w.track = {Ratio(s.sigma[kTrackPosition][session], reference),
               Ratio(s.sigma[kTrackHeading][session], reference)};
    if (levels.with_final_poses) {
      w.final_pose = {Ratio(s.sigma[kFinalPosition][session], reference),
                      Ratio(s.sigma[kFinalHeading][session], reference)};
    }
    out.push_back(w);
  }
  return out;
}

bool NoiseLevelsAgree(const NoiseLevels& a, const NoiseLevels& b) {
  if (!a.estimated || !b.estimated) return false;
  const FitWeights wa = WeightsFromNoiseLevels(a), wb = WeightsFromNoiseLevels(b);
  const auto close = [](double x, double y) {
    return std::abs(x - y) <= kNoiseLevelTolerance * std::max(std::abs(x), std::abs(y));
  };
  const std::vector<FitWeights> ra = WeightsPerRun(a), rb = WeightsPerRun(b);
  if (ra.size() != rb.size()) return false;
  for (std::size_t i = 0; i < ra.size(); ++i) {
    if (!close(ra[i].track.position_sigma_m, rb[i].track.position_sigma_m) ||
        !close(ra[i].track.heading_sigma_rad, rb[i].track.heading_sigma_rad) ||
        !close(ra[i].final_pose.position_sigma_m, rb[i].final_pose.position_sigma_m) ||
        !close(ra[i].final_pose.heading_sigma_rad, rb[i].final_pose.heading_sigma_rad))
      return false;
  }
  return close(wa.track.heading_sigma_rad, wb.track.heading_sigma_rad) &&
         close(wa.final_pose.position_sigma_m, wb.final_pose.position_sigma_m) &&
         close(wa.final_pose.heading_sigma_rad, wb.final_pose.heading_sigma_rad);
}

namespace {

// One component's levels by session: "0.012 m (sessions A, B), 0.031 m (session C: differs,
// Bartlett p = 2e-06)".
std::string SessionLevelsText(const SessionNoise& s, int component, double unit_scale,
                              const char* unit) {
  std::string pooled_names, out;
  int pooled_count = 0;
  for (std::size_t i = 0; i < s.names.size(); ++i) {
    if (s.split_p[component][i] < 0.0) pooled_names += (pooled_count++ ? ", " : "") + s.names[i];
  }
  bool pooled_said = false;
  for (std::size_t i = 0; i < s.names.size(); ++i) {
    const double sigma = s.sigma[component][i] * unit_scale;
    if (s.split_p[component][i] >= 0.0) {
      out += (out.empty() ? "" : ", ") +
             StrFormat("%.3g %s (session %s: differs, Bartlett p = %.2g)", sigma, unit,
                       s.names[i].c_str(), s.split_p[component][i]);
    } else if (!pooled_said) {
      pooled_said = true;
      out += (out.empty() ? "" : ", ") + StrFormat("%.3g %s (session%s %s)", sigma, unit,
                                                   pooled_count > 1 ? "s" : "",
                                                   pooled_names.c_str());
    }
  }
  return out;
}

std::string PerSessionText(const NoiseLevels& levels, const std::string& separator) {
  const SessionNoise& s = levels.sessions;
  std::string out = "track position " + SessionLevelsText(s, kTrackPosition, 1.0, "m") +
                    separator + "track heading " +
                    SessionLevelsText(s, kTrackHeading, RadToDeg(1.0), "deg") + " per checkpoint";
  if (levels.with_final_poses) {
    out += separator + "final pose position " + SessionLevelsText(s, kFinalPosition, 1.0, "m") +
           separator + "final pose heading " +
           SessionLevelsText(s, kFinalHeading, RadToDeg(1.0), "deg");
  }
  return out;
}

// The data set's levels, one per component.
std::string DataSetText(const NoiseLevels& levels) {
  std::string out = StrFormat("track position %.3g m, heading %.3g deg per checkpoint",
                              levels.track_position_m, RadToDeg(levels.track_heading_rad));
  if (levels.with_final_poses) {
    out += StrFormat("; final pose position %.3g m, heading %.3g deg", levels.final_position_m,
                     RadToDeg(levels.final_heading_rad));
  }
  return out;
}

}  // namespace

std::string NoiseLevelsText(const NoiseLevels& levels, const std::string& separator) {
  const std::string text = levels.sessions.AnyDiffers() ? PerSessionText(levels, separator)
                                                        : DataSetText(levels);
  return text + StrFormat(" (%d fits, %s)", levels.iterations,
                          levels.settled ? "settled" : "not settled");
}

}  // namespace fitcal
