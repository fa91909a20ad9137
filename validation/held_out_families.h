#pragma once
// A calibration better than the nominal on the held-out runs as a whole may still be worse on one
// kind of run (circles, squares, free driving: the trajectory family, the label's leading letters,
// validation/trajectory_family.h, as the report groups runs). The result gate (fit/result_gate.h)
// judges the held-out runs as a whole; this compares its choice with the nominal kind by kind, so
// that the caller writes no calibration that makes one kind of driving worse.

#include <cstddef>
#include <string>
#include <vector>

#include "fit/result_gate.h"
#include "fit/run_split.h"

namespace fitcal {

// The nominal's CF and the selected candidate's (Palacin Eq. 14, mean over the family's runs) on
// one trajectory family of the held-out runs.
struct FamilyComparison {
  std::string family;
  std::size_t runs = 0;
  double nominal_cf = 0.0;
  double selected_cf = 0.0;
  bool SelectedIsWorse() const { return selected_cf > nominal_cf; }
};

// One comparison per family of split.validation, in the families' sorted order. None when the gate
// did not judge on held-out runs, kept the nominal (candidates[0]), or the held-out runs are of one
// family (the gate judged that one already). `cf` scores any candidate, with effects or without.
std::vector<FamilyComparison> CompareHeldOutFamiliesWithNominal(
    const std::vector<CalibrationCandidate>& candidates, const GateDecision& gate,
    const RunSplit& split, const EffectCandidateCf& cf);

}  // namespace fitcal
