#include "fit/result_gate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fit/final_pose_errors.h"
#include "odometry/text_format.h"

namespace fitcal {

GateDecision SelectCalibration(const RobotModelInterface& model,
                               const std::vector<CalibrationCandidate>& candidates,
                               const std::vector<AlignedRun>& training,
                               const std::vector<AlignedRun>& validation, int num_threads,
                               const EffectCandidateCf& effect_cf) {
  if (candidates.empty()) throw std::invalid_argument("SelectCalibration: no candidates");
  GateDecision decision;
  decision.judged_on_held_out = !validation.empty();
  const std::vector<AlignedRun>& runs = decision.judged_on_held_out ? validation : training;
  if (runs.empty()) throw std::invalid_argument("SelectCalibration: no runs");
  decision.judged_on =
      decision.judged_on_held_out
          ? "held-out runs (" + std::to_string(runs.size()) + ")"
          : "training runs (" + std::to_string(runs.size()) + "; no held-out runs: not validated)";
  decision.cf.assign(candidates.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!candidates[i].usable) continue;
    if (!candidates[i].effects.empty()) {
      if (!effect_cf) {
        throw std::invalid_argument("SelectCalibration: candidate '" + candidates[i].name +
                                    "' carries effects and no effect_cf scores it");
      }
      decision.cf[i] = effect_cf(candidates[i], runs);
    } else {
      decision.cf[i] =
          EvaluateFinalPoseErrors(model, candidates[i].parameters, runs, num_threads).cf;
    }
    // Strictly better than the best so far: the earlier candidate (nominal first) wins ties.
    if (std::isfinite(decision.cf[i]) && decision.cf[i] < decision.cf[decision.selected]) {
      decision.selected = static_cast<int>(i);
    }
  }
  return decision;
}

std::string AtBoundRefusal(const Robot& robot, const std::string& name,
                           const std::vector<double>& parameters,
                           const std::vector<bool>& at_bound) {
  std::string which;
  for (int k = 0; k < robot.NumParameters() && k < static_cast<int>(at_bound.size()); ++k) {
    if (!at_bound[k]) continue;
    const ParameterInfo& info = robot.parameters[k];
    const double s = info.DisplayScale();
    which += StrFormat("%s%s %.6g %s in [%.6g, %.6g]", which.empty() ? "" : ", ", info.name.c_str(),
                       s * parameters[k], info.DisplayUnit(), s * robot.bounds[k].lo,
                       s * robot.bounds[k].hi);
  }
  if (which.empty()) return "";
  // A parameter held at the robot file's value (one no run can see, an omni robot's gauge) that
  // is off there moves the others along with it: a mecanum robot's rear distance guessed 0.30 m
  // for 0.25 pushed a front one onto its bound at the noise floor.
  std::string held;
  for (const HeldParameter& h : robot.held) {
    const ParameterInfo& info = robot.parameters[h.index];
    held += StrFormat("%s%s %.6g %s", held.empty() ? "" : ", ", info.name.c_str(),
                      info.DisplayScale() * parameters[h.index], info.DisplayUnit());
  }
  if (!held.empty()) {
    held = ", a value held where the robot YAML puts it (" + held +
           ") may be off and the others have moved with it,";
  }
  return "'" + name + "' leaves a parameter on its bound (" + which +
         "): the model may be absorbing an effect it does not contain" + held +
         " or the bounds are too tight; widen them under `bounds:` in the robot YAML and fit "
         "again (--bounds-widened writes a calibration that still ends on a widened bound)";
}

int BestCandidateInsideTheBounds(const std::vector<CalibrationCandidate>& candidates,
                                 const GateDecision& decision,
                                 const std::function<std::vector<bool>(int)>& at_bound) {
  int best = 0;
  for (int i = 1; i < static_cast<int>(candidates.size()); ++i) {
    const CalibrationCandidate& c = candidates[i];
    if (i == decision.selected || !c.usable || !c.effects.empty()) continue;
    if (!(decision.cf[i] < decision.cf[best])) continue;  // the nominal and earlier win ties
    const std::vector<bool> on = at_bound(i);
    if (std::find(on.begin(), on.end(), true) == on.end()) best = i;
  }
  return best;
}

std::vector<std::string> GateLines(const std::vector<CalibrationCandidate>& candidates,
                                   const GateDecision& decision) {
  std::vector<std::string> out;
  const double nominal = decision.cf[0];
  int width = 22;  // the names' column, wider for a long name ("track fit + <effects>")
  for (const CalibrationCandidate& c : candidates) {
    width = std::max(width, static_cast<int>(c.name.size()));
  }
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!candidates[i].usable) {
      out.push_back(StrFormat("  %-*s %10s   (not usable: %s)", width, candidates[i].name.c_str(),
                              "-", candidates[i].not_usable_because.c_str()));
      continue;
    }
    const double change = nominal > 0.0 ? 100.0 * (decision.cf[i] - nominal) / nominal : 0.0;
    out.push_back(StrFormat("  %-*s %10.4f %+8.1f%%%s", width, candidates[i].name.c_str(),
                            decision.cf[i], change,
                            static_cast<int>(i) == decision.selected ? "   <- selected" : ""));
  }
  return out;
}

}  // namespace fitcal
