#pragma once
// One calibration from a request (calibrate/calibration_request.h), every decision of it in one
// call: the training runs checked, --residuals auto resolved and the tracks built, the residual
// kind and the track objective chosen by transfer, the candidates fitted (the method's fit, the
// closed forms, the track fits with the effects), the result gate (fit/result_gate.h) with the
// effects' paired test, the held-out judgements (halves or time blocks when nothing is held out,
// never worse than the nominal per measure and family), the bound contacts, and the record to
// write. A command loads, calls Calibrate, prints the outcome and writes its record.

#include <optional>
#include <string>
#include <vector>

#include "calibrate/calibration_request.h"
#include "calibrate/candidates.h"
#include "calibrate/selected_fit.h"
#include "io/calibration_block.h"
#include "models/model_interface.h"
#include "validation/held_out_halves.h"

namespace fitcal {

// A refusal: the exit code (README "Exit codes") and its reasons, one line each (printed as
// "fitcal: <reason>"); exit_code 0: none.
struct Refusal {
  int exit_code = 0;
  std::vector<std::string> reasons;
};

// How far the calibration went; a refusal stops it at the stage that refused. What a command
// prints of each stage is printed only when the stage was reached.
enum class CalibrationStage {
  kChecks,      // the data, the tracks, the choices, the degrees of freedom, the uncertainty
  kGate,        // the candidates fitted and judged by the gate
  kHalves,      // with nothing held out: the fits of halves judged on the other halves
  kNeverWorse,  // never worse than the nominal per measure and family of held-out runs
  kAtBound,     // no parameter of the selected calibration on its bound (or widened on purpose)
  kDone,        // selected; the record made when the request writes
};

struct CalibrationOutcome {
  CalibrationStage reached = CalibrationStage::kChecks;
  Refusal refusal;
  std::vector<std::string> data_warnings;  // what the data cannot determine (before the fit)
  RunSplit split;
  // The settings fitted with: --residuals auto resolved, the track objective chosen (no track
  // pointer: the tracks are track_data).
  FitMethodSettings settings;
  std::vector<std::string> choice_lines;  // the residual-kind and track-objective choices
  std::optional<TrackFitData> track_data;
  ModelFitMethodOutcome fit;  // the method's fit of all the training runs
  std::vector<CalibrationCandidate> candidates;  // [0] the nominal
  std::optional<TrackFits> track_fits;            // with effects to fit
  GateDecision gate;                              // judged_on: what the record says
  std::string gate_judged_on;                     // what the gate's table says
  std::string effects_line;                       // the effects' paired test, or empty
  std::string gave_way_line;  // the gate's pick on a bound gave way to the next best, or empty
  SelectedFit selected_fit;
  HalvesJudgement halves;
  std::vector<std::string> never_worse_warnings;
  std::string at_bound_warning;  // written anyway under bounds_widened
  std::string effects_note;      // the selected calibration's effects and a plain controller
  std::optional<io::CalibrationBlock> record;  // when the request writes and nothing refused
  std::string stopped_early;  // the written calibration is the solver's last point (exit 6)
  // The mount's x and y fitted, not held at a guess the wheel distances could not take up
  // (calibrate.cc, FitAMountTheWheelsCannotAbsorb): what was compared, or empty.
  std::string mount_freed_line;
  RobotModelPtr mount_freed_model;  // with mount_freed_line: the model the outcome is of

  // The model the outcome is of: `requested` (the one Calibrate was given), or its mount freed.
  const RobotModelInterface& CalibratedModel(const RobotModelInterface& requested) const {
    return mount_freed_model ? *mount_freed_model : requested;
  }

  const CalibrationCandidate& selected() const { return candidates[gate.selected]; }
  int exit_code() const;
};

CalibrationOutcome Calibrate(const CalibrationRequest& request, const RobotModelInterface& model);

}  // namespace fitcal
