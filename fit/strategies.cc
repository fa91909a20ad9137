#include "fit/strategies.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <stdexcept>

#include "io/text_file.h"

namespace fitcal {

namespace {

std::vector<std::string> Range(const std::string& prefix, int first, int last) {
  std::vector<std::string> out;
  for (int i = first; i <= last; ++i) out.push_back(prefix + std::to_string(i));
  return out;
}

std::vector<std::string> Concat(std::initializer_list<std::vector<std::string>> parts) {
  std::vector<std::string> out;
  for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

// Splits "B12" into ("B", 12); false when the label does not end in a number after a prefix.
bool SplitLabel(const std::string& label, std::string* prefix, int* number) {
  std::size_t digits = label.size();
  while (digits > 0 && std::isdigit(static_cast<unsigned char>(label[digits - 1]))) --digits;
  if (digits == 0 || digits == label.size() || label.size() - digits > 6) return false;
  *prefix = label.substr(0, digits);
  *number = std::stoi(label.substr(digits));
  return true;
}

}  // namespace

const std::vector<TrajectoryStrategy>& PalacinStrategies() {
  // Palacin Sec. 3.2 and Table 4.
  static const std::vector<TrajectoryStrategy> kStrategies = {
      {"STA", {"R1", "R5", "R9"}},
      {"STB", {"B2", "B6", "B10", "G12", "G4", "G8"}},
      {"STC", Range("R", 1, 12)},
      {"STD", Concat({Range("B", 1, 12), Range("G", 1, 12)})},
      {"STE", Concat({Range("R", 1, 12), Range("G", 1, 12), Range("B", 1, 12)})},
  };
  return kStrategies;
}

TrajectoryStrategy ParseStrategy(const std::string& text) {
  std::string upper(io::Trim(text));
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (const TrajectoryStrategy& s : PalacinStrategies()) {
    if (upper == s.name) return s;
  }
  TrajectoryStrategy out;
  out.name = io::Trim(text);
  std::set<std::string> seen;
  for (const std::string& item : io::SplitCsvFields(text)) {
    if (item.empty()) {
      throw std::invalid_argument("strategy '" + text + "': empty trajectory label");
    }
    std::vector<std::string> labels;
    const std::size_t dash = item.find('-');
    if (dash == std::string::npos) {
      labels.push_back(item);
    } else {
      std::string p0, p1;
      int n0 = 0, n1 = 0;
      if (!SplitLabel(std::string(io::Trim(item.substr(0, dash))), &p0, &n0) ||
          !SplitLabel(std::string(io::Trim(item.substr(dash + 1))), &p1, &n1) || p0 != p1 ||
          n0 > n1) {
        throw std::invalid_argument("strategy '" + text + "': '" + item +
                                    "' is not a range like B1-B12 (same prefix, increasing)");
      }
      labels = Range(p0, n0, n1);
    }
    for (const std::string& label : labels) {
      if (!seen.insert(label).second) {
        throw std::invalid_argument("strategy '" + text + "': trajectory " + label +
                                    " is listed twice");
      }
      out.labels.push_back(label);
    }
  }
  return out;
}

std::vector<std::string> MissingTrajectories(const std::vector<AlignedRun>& runs,
                                             const TrajectoryStrategy& strategy) {
  std::set<std::string> present;
  for (const AlignedRun& run : runs) present.insert(run.trajectory);
  std::vector<std::string> missing;
  for (const std::string& label : strategy.labels) {
    if (!present.count(label)) missing.push_back(label);
  }
  return missing;
}

std::vector<AlignedRun> SelectRuns(const std::vector<AlignedRun>& runs,
                                   const TrajectoryStrategy& strategy,
                                   const std::vector<int>& repetitions) {
  const std::set<std::string> labels(strategy.labels.begin(), strategy.labels.end());
  const std::set<int> reps(repetitions.begin(), repetitions.end());
  std::vector<AlignedRun> out;
  for (const AlignedRun& run : runs) {
    if (labels.count(run.trajectory) && reps.count(run.repetition)) out.push_back(run);
  }
  return out;
}

}  // namespace fitcal
