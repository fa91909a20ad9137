#include "diagnosis/degenerate_data.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include "fit/statistics.h"
#include "io/text_file.h"

namespace fitcal {

namespace {

// How far a run's ground truth spreads about its median pose: the 90th percentile of the
// distances and of the heading differences, so that a motion capture's noise (a few of its
// samples far out) does not count as motion, and a run that moves for a tenth of its time does.
std::pair<double, double> GroundTruthSpread(const GroundTruthTrack& track) {
  const std::vector<Pose2d>& poses = track.world_T_robot;
  std::vector<double> x, y, heading;
  for (const Pose2d& pose : poses) {
    x.push_back(pose.x);
    y.push_back(pose.y);
    heading.push_back(std::remainder(pose.theta - poses.front().theta, 2.0 * M_PI));
  }
  const double mx = stats::Median(x), my = stats::Median(y), mh = stats::Median(heading);
  std::vector<double> distance_m, turn_rad;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    distance_m.push_back(std::hypot(x[k] - mx, y[k] - my));
    turn_rad.push_back(std::abs(std::remainder(heading[k] - mh, 2.0 * M_PI)));
  }
  const auto p90 = [](std::vector<double> v) {
    const std::size_t at = v.size() * 9 / 10;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(at), v.end());
    return v[at];
  };
  return {p90(distance_m), p90(turn_rad)};
}

// The most any wheel turned over the run (rad): each wheel-rate channel's |rate| dt summed.
double MostWheelTurnRad(const RunLog& run, const Robot& robot) {
  double most_rad = 0.0;
  for (int c = 0; c < robot.NumChannels(); ++c) {
    if (robot.channels[c].kind != ChannelKind::kWheelRate) continue;
    double turned_rad = 0.0;
    for (const auto& s : run.encoders.samples) turned_rad += std::abs(s.value[c]) * s.dt_s;
    most_rad = std::max(most_rad, turned_rad);
  }
  return most_rad;
}

}  // namespace

std::string StillRunsRefusal(const std::vector<const RunLog*>& runs, const Robot& robot) {
  double most_m = 0.0, most_rad = 0.0;
  for (const RunLog* run_pointer : runs) {
    const RunLog& run = *run_pointer;
    if (run.ground_truth.world_T_robot.empty()) continue;
    // Ground truth of the start and end poses only cannot show a run standing still: a closed
    // loop (UMBmark's squares) ends where it started. Its wheels say whether it moved.
    if (run.ground_truth.world_T_robot.size() <= 2 &&
        MostWheelTurnRad(run, robot) > kStillWheelTurnRad) {
      return "";
    }
    const auto [spread_m, spread_rad] = GroundTruthSpread(run.ground_truth);
    most_m = std::max(most_m, spread_m);
    most_rad = std::max(most_rad, spread_rad);
  }
  if (runs.empty() || most_m > kStillPositionM || most_rad > kStillHeadingRad) return "";
  std::ostringstream line;
  line.precision(3);
  line << "the training runs stand still: no run's ground truth moves more than "
       << kStillPositionM << " m or turns more than " << RadToDeg(kStillHeadingRad)
       << " deg from where it mostly is (at most " << most_m << " m, " << RadToDeg(most_rad)
       << " deg, 90th percentile, over " << runs.size()
       << " runs); without motion no parameter is determined; drive the robot; nothing fitted";
  return line.str();
}

double ChiSquare1Quantile(double p) {
  // chi^2_1 = Z^2: P(chi^2_1 <= x) = erf(sqrt(x / 2)); bisection on sqrt(x) in [0, 40].
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erf(mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  const double z = 0.5 * (lo + hi);
  return z * z;
}

std::vector<std::string> FindDegenerateData(const std::vector<AlignedRun>& runs,
                                            const Robot& robot) {
  std::vector<std::string> problems;
  // A wheel that never turns: every rate exactly zero (an encoder that counts nothing). Angle
  // channels (steering) may rest at zero on straight runs.
  for (std::size_t i = 0; i < robot.channels.size(); ++i) {
    if (robot.channels[i].kind != ChannelKind::kWheelRate) continue;
    bool turns = false;
    for (const AlignedRun& run : runs) {
      for (const auto& s : run.samples) turns = turns || s.value[i] != 0.0;
    }
    if (!turns && !runs.empty()) {
      problems.push_back("wheel " + robot.channels[i].name +
                         " never turns in any run (disconnected encoder or stuck wheel?): what "
                         "only it measures (its radius) is not determined by the data and stays "
                         "at the nominal");
    }
  }
  // Copies: group runs with bitwise-identical encoder samples.
  std::vector<bool> seen(runs.size(), false);
  std::size_t distinct = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (seen[i]) continue;
    ++distinct;
    std::vector<std::string> copies;
    for (std::size_t j = i + 1; j < runs.size(); ++j) {
      if (!seen[j] && runs[i].samples == runs[j].samples) {
        seen[j] = true;
        copies.push_back(runs[j].id);
      }
    }
    if (!copies.empty() && copies.size() + 1 < runs.size()) {
      problems.push_back("runs " + runs[i].id + " and " + io::Joined(copies, ", ") +
                         " have identical encoder logs (a copied file?): they count as one run");
    }
  }
  if (runs.size() > 1 && distinct == 1) {
    problems.push_back("all " + std::to_string(runs.size()) +
                       " runs have identical encoder logs: one run's 3 final-pose residuals "
                       "cannot determine the " +
                       std::to_string(robot.NumFree()) +
                       " free parameters; the fit is underdetermined");
  }
  return problems;
}

std::vector<OutlierRun> FindOutlierRuns(const std::vector<std::string>& run_ids,
                                        const std::vector<double>& per_run_norm, double alpha) {
  std::vector<OutlierRun> out;
  const std::size_t n = per_run_norm.size();
  if (n < 3 || run_ids.size() != n) return out;  // no robust scale from fewer runs
  std::vector<double> squared(n);
  for (std::size_t i = 0; i < n; ++i) squared[i] = per_run_norm[i] * per_run_norm[i];
  const double median_squared = stats::Median(squared);
  if (!(median_squared > 0.0)) return out;
  const double s2 = median_squared / ChiSquare1Quantile(0.5);
  const double limit = ChiSquare1Quantile(1.0 - alpha / static_cast<double>(n));
  const double median_norm = std::sqrt(median_squared);
  for (std::size_t i = 0; i < n; ++i) {
    if (squared[i] / s2 > limit) out.push_back({run_ids[i], per_run_norm[i] / median_norm});
  }
  return out;
}

}  // namespace fitcal
