#include "validation/fleet_statistics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>

#include "fit/statistics.h"
#include "io/input_error.h"

namespace fitcal {
namespace {

// A calibration further than this many robust sigmas from the robot's median is an outlier
// (a Gaussian value lies beyond 5 sigma once in 1.7 million).
constexpr double kOutlierRobustZ = 5.0;
constexpr std::size_t kMinForOutlier = 5;
// A slope this many standard errors from zero is a trend (|t| > 3: p < 0.01 for n >= 6).
constexpr double kTrendT = 3.0;
constexpr std::size_t kMinForTrend = 4;

// Days since 1970-01-01 of a proleptic Gregorian YYYY-MM-DD (Howard Hinnant's days_from_civil).
long DaysFromCivil(int y, int m, int d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const long yoe = y - era * 400;
  const long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

long Days(const std::string& date) {
  return DaysFromCivil(std::stoi(date.substr(0, 4)), std::stoi(date.substr(5, 2)),
                       std::stoi(date.substr(8, 2)));
}

void FlagOutliers(FleetSeries* s) {
  if (s->values.size() < kMinForOutlier) return;
  const double median = s->median;
  std::vector<double> deviation;
  for (double v : s->values) deviation.push_back(std::abs(v - median));
  const double sigma = 1.4826 * stats::Median(deviation);
  if (!(sigma > 0.0)) return;
  for (std::size_t i = 0; i < s->values.size(); ++i) {
    if (std::abs(s->values[i] - median) > kOutlierRobustZ * sigma) {
      s->outliers.push_back(s->dates[i]);
    }
  }
}

// Ordinary least squares of value on days, outliers left out (one bad night is not a trend).
void FlagTrend(FleetSeries* s) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < s->values.size(); ++i) {
    if (std::find(s->outliers.begin(), s->outliers.end(), s->dates[i]) != s->outliers.end()) {
      continue;
    }
    x.push_back(static_cast<double>(Days(s->dates[i])));
    y.push_back(s->values[i]);
  }
  const std::size_t n = x.size();
  if (n < kMinForTrend) return;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) mx += x[i] / n, my += y[i] / n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i)
    sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  if (!(sxx > 0)) return;
  const double slope = sxy / sxx;
  double rss = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = y[i] - my - slope * (x[i] - mx);
    rss += r * r;
  }
  const double scatter = std::sqrt(rss / static_cast<double>(n - 2));
  const double standard_error = scatter / std::sqrt(sxx);
  const double span_days =
      *std::max_element(x.begin(), x.end()) - *std::min_element(x.begin(), x.end());
  s->slope_per_30_days = 30.0 * slope;
  s->has_slope = true;
  s->trend = std::abs(slope) > kTrendT * standard_error &&
             std::abs(slope) * span_days > scatter;
}

// The parameter names of a calibration, in its order, without the held-out CF's row.
std::string ParameterNames(const FleetCalibration& c) {
  std::string out;
  for (const FleetValue& v : c.values) {
    if (v.name != kFleetCfRow) out += (out.empty() ? "" : ", ") + v.name;
  }
  return out;
}

// A robot is its name: two calibrations of one name and different models, or of one model with
// other parameters (a mecanum robot of four wheels and an omni robot of three, both `omni`), are
// two robots (a renamed copy, a rebuilt robot), whose parameters must not be merged into one
// series.
void RefuseOneNameForTwoModels(const std::vector<FleetCalibration>& all) {
  std::map<std::string, const FleetCalibration*> first_of;
  for (const FleetCalibration& c : all) {
    if (c.model.empty()) continue;
    const auto [it, inserted] = first_of.emplace(c.robot, &c);
    if (inserted) continue;
    const FleetCalibration& first = *it->second;
    std::string differs;
    if (first.model != c.model) {
      differs = "is a " + c.model + " here and a " + first.model;
    } else if (ParameterNames(first) != ParameterNames(c)) {
      differs = "has parameters " + ParameterNames(c) + " here and " + ParameterNames(first);
    }
    if (differs.empty()) continue;
    throw io::InputError(io::InputErrorKind::kBadValue, c.file, 0,
                         "robot '" + c.robot + "' " + differs + " in " + first.file +
                             "; fleet keeps one series per robot name: give the robots "
                             "different names");
  }
}

// A second file of the robot and date (its report, the same file found twice) must hold the
// value the first did: two calibrations of one date with different values are two results of
// which the series could keep only one, and the other would vanish unsaid. The report's CF is
// not compared: `report` may judge the calibration on other runs (a free run) than fit did.
void RequireOneResultPerDate(const FleetSeries& s, const FleetValue& v, const FleetCalibration& c) {
  if (v.name == kFleetCfRow) return;
  // The YAML writes 10 significant digits, metrics.json more: equal to the YAML's last digit.
  constexpr double kWrittenDigits = 1e-9;
  const double kept = s.values.back();
  if (std::abs(v.value - kept) <= kWrittenDigits * std::max(std::abs(v.value), std::abs(kept))) {
    return;
  }
  std::ostringstream why;
  why.precision(10);
  why << "robot '" << c.robot << "' has two results dated " << c.date << ": " << v.name << " "
      << v.value * v.display_scale << " here and " << kept * s.display_scale << " in "
      << s.files.back() << "; fleet keeps one result per robot and date (a calibration and its "
      << "report count once): keep one, or date them apart";
  throw io::InputError(io::InputErrorKind::kBadValue, c.file, 0, why.str());
}

}  // namespace

std::vector<FleetSeries> FleetSeriesOf(std::vector<FleetCalibration> all) {
  RefuseOneNameForTwoModels(all);
  std::stable_sort(all.begin(), all.end(),
                   [](const FleetCalibration& a, const FleetCalibration& b) {
                     return std::tie(a.robot, a.date) < std::tie(b.robot, b.date);
                   });
  std::vector<FleetSeries> out;
  std::map<std::pair<std::string, std::string>, std::size_t> index;
  for (const FleetCalibration& c : all) {
    for (const FleetValue& v : c.values) {
      const auto key = std::make_pair(c.robot, v.name);
      auto it = index.find(key);
      if (it == index.end()) {
        it = index.emplace(key, out.size()).first;
        FleetSeries s;
        s.robot = c.robot;
        s.parameter = v.name;
        s.unit = v.unit;
        s.display_scale = v.display_scale;
        out.push_back(std::move(s));
      }
      FleetSeries& s = out[it->second];
      // A calibration and its report (metrics.json) on the same date are one result.
      if (!s.dates.empty() && s.dates.back() == c.date) {
        RequireOneResultPerDate(s, v, c);
        continue;
      }
      s.dates.push_back(c.date);
      s.values.push_back(v.value);
      s.sigmas.push_back(v.sigma);
      s.files.push_back(c.file);
      if (v.name == kFleetCfRow) s.judged_on.push_back(c.judged_on);
    }
  }
  for (FleetSeries& s : out) {
    s.median = stats::Median(s.values);
    for (const std::string& j : s.judged_on) {
      const auto& d = s.distinct_judges;
      if (std::find(d.begin(), d.end(), j) == d.end()) s.distinct_judges.push_back(j);
    }
    FlagOutliers(&s);
    FlagTrend(&s);
  }
  return out;
}

}  // namespace fitcal
