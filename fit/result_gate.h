#pragma once
// The result gate: a written calibration is never worse than what it replaces. Every command
// that writes a calibration hands its candidates here - the nominal robot first, then closed
// forms (UMBmark, ASOC's geometry), each fit, fits with effects - and writes the one with the
// lowest CF (Palacin Eq. 14) on the held-out runs; on the training runs, said so, when there are
// none. The nominal wins ties: a calibration must earn its place.

#include <functional>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"

namespace fitcal {

struct CalibrationCandidate {
  std::string name;  // "nominal", "ceres", "umbmark", ...
  std::vector<double> parameters;
  bool usable = true;  // a fit that did not converge to a usable point competes not
  // Effects (odometry/effects.h) the candidate's odometry applies on top of the parameters.
  std::vector<effects::EffectValue> effects = {};
  // The candidate's own 1-sigma per parameter, when it carries one (a closed form's,
  // ClosedFormCalibration::sigma); empty otherwise.
  std::vector<double> sigma = {};
  // Why an unusable candidate does not compete, as the gate's table says it.
  std::string not_usable_because = "did not converge";
};

// The CF (Eq. 14, mean over `runs`) of a candidate that carries effects: their replay needs each
// run's ground-truth track (validation/trajectory_metrics.h), which the gate does not hold.
using EffectCandidateCf =
    std::function<double(const CalibrationCandidate&, const std::vector<AlignedRun>& runs)>;

struct GateDecision {
  int selected = 0;        // index into the candidates (0 = nominal)
  std::vector<double> cf;  // per candidate, on the judging runs (NaN when not usable)
  bool judged_on_held_out = true;
  std::string judged_on;  // "held-out runs (N)" or "training runs (N; no held-out runs)"
  bool improves_on_nominal() const { return selected != 0; }
};

// candidates[0] must be the nominal. Candidates without effects are replayed here; those with
// effects are scored by effect_cf, the same Eq. 14 at the same final poses. Throws
// std::invalid_argument for no candidates, no runs, or a candidate with effects and no effect_cf.
GateDecision SelectCalibration(const RobotModelInterface& model,
                               const std::vector<CalibrationCandidate>& candidates,
                               const std::vector<AlignedRun>& training,
                               const std::vector<AlignedRun>& validation, int num_threads = 0,
                               const EffectCandidateCf& effect_cf = {});

// A calibration with a parameter on a bound of the robot's box (at_bound, robot().parameters
// order) is not written unless the user says the bounds were widened on purpose (`fit
// --bounds-widened`): the data pushed the value as far as the box allows, so the model absorbs an
// effect it lacks or the box is too tight (issue 39: a traction radius and a steering offset on
// their bounds, written with exit 0, drifted 3 % per metre worse). Empty when no parameter is on a
// bound; else the reason, naming each parameter with its value and bounds.
std::string AtBoundRefusal(const Robot& robot, const std::string& name,
                           const std::vector<double>& parameters,
                           const std::vector<bool>& at_bound);

// The gate's pick when its selected candidate is on a bound (AtBoundRefusal) and the bounds were
// not widened: the best other candidate without effects that beats the nominal with no parameter
// on its bound (`at_bound(i)`, robot().parameters order); 0 when none does.
int BestCandidateInsideTheBounds(const std::vector<CalibrationCandidate>& candidates,
                                 const GateDecision& decision,
                                 const std::function<std::vector<bool>(int)>& at_bound);

// One line per candidate for the terminal: name, CF, change against nominal, and which won.
std::vector<std::string> GateLines(const std::vector<CalibrationCandidate>& candidates,
                                   const GateDecision& decision);

}  // namespace fitcal
