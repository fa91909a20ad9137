// Simulated encoder CSVs rewritten as a robot's recorder writes them (issue 39): every wheel
// rate column `w_<name>` as a 32-bit running total of ticks (`ticks_<name>`, 4096 a revolution,
// starting near 2^32 so that it wraps early), every angle column named in `angle_columns` as
// counts of an absolute encoder (`ticks_<name>`, kSteeringTicks a turn, zero at kSteeringZero),
// and optionally three glitches of the first wheel's counter in moving stretches. The robot YAML
// declares them with kCountsEncoderYaml (+ `<name>_encoder:` per angle column).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_files.h"

namespace fitcal::testing {

inline constexpr double kCounterStart = 4294967296.0 - 30000.0;  // a 32-bit total that wraps
inline constexpr double kSteeringTicks = 8192.0, kSteeringZero = 5000.0;
inline constexpr const char* kCountsEncoderYaml =
    "encoder: {ticks_per_rev: 4096, cumulative: true, counter_bits: 32}\n";

struct Glitches {
  std::vector<int> lines;  // the file lines the three glitches are on
};

inline std::vector<std::string> CsvFields(const std::string& row) {
  std::vector<std::string> out;
  std::istringstream in(row);
  for (std::string field; std::getline(in, field, ',');) out.push_back(field);
  return out;
}

// Three glitches of one running total (`counts`: ticks from the start) at rows inside forward
// motion (every one of the 6 intervals either side counts > 5 ticks), spread over the run: a
// torn 32-bit read, a stale read then 400 ticks short, and a jump back of 1000 ticks that stays.
// A run whose wheel drives forward for fewer than 100 such rows gets none (glitches->lines empty).
inline void AddThreeGlitches(std::vector<double>* counts, Glitches* glitches) {
  const std::vector<double> total = *counts;
  std::vector<std::size_t> moving;
  for (std::size_t k = 8; k + 8 < total.size(); ++k) {
    bool ok = true;
    for (std::size_t i = k - 6; i <= k + 6; ++i) ok = ok && total[i + 1] - total[i] > 5.0;
    if (ok) moving.push_back(k);
  }
  if (moving.size() <= 100u) return;
  const std::size_t a = moving[moving.size() / 5], b = moving[moving.size() / 2],
                    c = moving[4 * moving.size() / 5];
  (*counts)[a] = 0x5A5A5A5A - kCounterStart;  // a torn read of the 32-bit counter
  (*counts)[b] = (*counts)[b - 1];            // a stale read, then 400 ticks short
  (*counts)[b + 1] -= 400;
  for (std::size_t k = c; k < counts->size(); ++k) (*counts)[k] -= 1000;  // a jump back, kept
  glitches->lines = {static_cast<int>(a) + 2, static_cast<int>(b) + 3, static_cast<int>(c) + 2};
}

// Rewrites one simulated encoder CSV (t then rate columns w_<name>, quantised to 4096 ticks per
// revolution by the simulator, and angle columns at the row times) as counts; with `glitches`,
// three glitches on the first wheel.
inline std::string AsCounts(const std::string& rates_csv, const std::set<std::string>& angle_columns,
                            Glitches* glitches) {
  std::istringstream in(rates_csv);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = CsvFields(line);
  std::vector<std::vector<double>> columns(header.size());
  std::vector<double> sum(header.size(), 0.0);
  while (std::getline(in, line)) {
    const std::vector<double> v = CsvNumbers(line, header.size());
    for (std::size_t j = 1; j < header.size(); ++j) {
      if (angle_columns.count(header[j]) != 0) {
        columns[j].push_back(v[j]);
        continue;
      }
      if (!columns[0].empty()) sum[j] += std::round(v[j] * (v[0] - columns[0].back()) * 4096.0 / (2.0 * M_PI));
      columns[j].push_back(sum[j]);
    }
    columns[0].push_back(v[0]);
  }
  if (glitches != nullptr) AddThreeGlitches(&columns[1], glitches);
  std::ostringstream out;
  out.precision(10);
  out << "t";
  for (std::size_t j = 1; j < header.size(); ++j) {
    const bool angle = angle_columns.count(header[j]) != 0;
    out << ",ticks_" << (angle ? header[j] : header[j].substr(2));
  }
  out << "\n";
  for (std::size_t k = 0; k < columns[0].size(); ++k) {
    out << columns[0][k];
    for (std::size_t j = 1; j < header.size(); ++j) {
      const double c = columns[j][k];
      if (angle_columns.count(header[j]) != 0) {
        out << "," << std::fmod(kSteeringZero + std::round(c * kSteeringTicks / (2.0 * M_PI)) +
                                    kSteeringTicks, kSteeringTicks);
      } else {
        out << "," << std::fmod(kCounterStart + c + 4294967296.0, 4294967296.0);
      }
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace fitcal::testing
