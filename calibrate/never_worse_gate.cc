#include "calibrate/never_worse_gate.h"

#include "validation/never_worse.h"

namespace fitcal {

NeverWorseVerdict JudgeNeverWorseThanNominal(const RobotModelInterface& model,
                                             const CalibrationCandidate& nominal,
                                             const CalibrationCandidate& chosen,
                                             const std::vector<AlignedRun>& runs,
                                             const std::vector<const GroundTruthTrack*>& tracks,
                                             int threads) {
  const std::vector<NeverWorseJudgement> judged =
      CompareEverydayDriving(model, nominal, chosen, runs, tracks, threads).judgements;
  const NeverWorseSaid said = SayNeverWorse(chosen.name, judged);
  NeverWorseVerdict out{said.warnings, said.refusals};
  for (std::string& line : out.refusals) line += "; nothing written";
  return out;
}

}  // namespace fitcal
