#include "models/model_extras.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "odometry/text_format.h"

namespace fitcal {

double MeanValue(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

void NoteSpread(const std::vector<double>& v, const std::string& what, const std::string& key,
                double scale, const char* unit, std::vector<std::string>* notes) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  if (*hi - *lo <= 1e-12 * std::abs(*hi)) return;
  notes->push_back(StrFormat(
      "%s takes one %s: the calibrated %.6g..%.6g %s are written as their mean %.6g %s",
      key.c_str(), what.c_str(), *lo * scale, *hi * scale, unit, MeanValue(v) * scale, unit));
}

}  // namespace fitcal
