#include "validation/held_out_families.h"

#include <map>
#include <utility>

#include "validation/trajectory_family.h"

namespace fitcal {

std::vector<FamilyComparison> CompareHeldOutFamiliesWithNominal(
    const std::vector<CalibrationCandidate>& candidates, const GateDecision& gate,
    const RunSplit& split, const EffectCandidateCf& cf) {
  std::vector<FamilyComparison> comparisons;
  if (!gate.judged_on_held_out || gate.selected == 0) return comparisons;
  const std::map<std::string, std::vector<AlignedRun>> by_family = RunsByFamily(split.validation);
  if (by_family.size() < 2) return comparisons;  // the gate judged this one family already
  for (const auto& [family, runs] : by_family) {
    FamilyComparison c;
    c.family = family;
    c.runs = runs.size();
    c.nominal_cf = cf(candidates[0], runs);
    c.selected_cf = cf(candidates[gate.selected], runs);
    comparisons.push_back(std::move(c));
  }
  return comparisons;
}

}  // namespace fitcal
