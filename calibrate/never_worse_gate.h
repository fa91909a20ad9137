#pragma once
// The never-worse judgement (validation/never_worse.h) as every command that writes a
// calibration applies it after the gate: the chosen calibration against the nominal on the
// held-out runs, per measure and per family, said as warnings (rose within the scatter) and
// refusals (worse beyond it: nothing is written).

#include <string>
#include <vector>

#include "fit/result_gate.h"

namespace fitcal {

struct NeverWorseVerdict {
  std::vector<std::string> warnings;
  std::vector<std::string> refusals;  // each ends "; nothing written"
};

// tracks[i] is runs[i]'s ground truth.
NeverWorseVerdict JudgeNeverWorseThanNominal(const RobotModelInterface& model,
                                             const CalibrationCandidate& nominal,
                                             const CalibrationCandidate& chosen,
                                             const std::vector<AlignedRun>& runs,
                                             const std::vector<const GroundTruthTrack*>& tracks,
                                             int threads);

}  // namespace fitcal
