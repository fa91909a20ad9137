#pragma once
// What a calibration is asked to do, as the commands resolve it from their flags: the data set's
// runs and how they split, the method and its settings (auto not yet resolved: that takes the
// training runs' tracks, Calibrate resolves it), the effects to fit, and what the record says.

#include <string>
#include <vector>

#include "calibrate/fit_methods.h"
#include "fit/effect_fit.h"
#include "fit/run_split.h"
#include "io/dataset.h"

namespace fitcal {

struct CalibrationRequest {
  std::string dataset;  // the data set as the user named it (--logs): messages and the record
  const FitMethod* method = nullptr;  // never null
  FitMethodSettings settings;
  // The effects refitted on the training tracks beside the parameters: the robot's and --effects.
  EffectModel effects_to_fit;
  std::vector<RunLog> runs;  // every run of the data set
  std::string train_reps = "1-5";
  std::string train_trajectories;  // non-empty: replaces train_reps (fit/trajectory_split.h)
  // Non-empty: exactly these runs train and the others judge, replacing both (generalise's
  // splits, calibrate/generalise.h).
  std::vector<std::string> training_ids;
  int threads = 0;
  int time_blocks = 4;  // with nothing held out: the time blocks of validation/held_out_halves.h
  // The sigmas as given (settings.weights holds them in SI units): the record's objective and
  // the channel-order check use them as the user wrote them.
  double position_sigma_m = 1.0;
  double heading_sigma_deg = 180.0 / 3.14159265358979323846;
  bool check_channel_order = true;
  bool will_write = true;  // a record is made (and an uncertainty must exist) only then
  bool bounds_widened = false;  // a parameter on its bound is written, with a warning
  // The model's closed forms alone against the nominal (--closed-form-only): no method fit, no
  // choice by transfer, no halves; the same gate, never-worse rule, bound check and record.
  bool closed_forms_only = false;
};

// How the training runs were chosen, for messages: "trajectories matching '...'" or
// "repetitions 1-5".
std::string TrainingSelection(const CalibrationRequest& request);

// The request's runs split into training and validation (training_ids, else SplitForFit).
RunSplit SplitOfRequest(const CalibrationRequest& request);

// Why a repetition --train-reps names on its own (not in a range: "1-99" spans what there is) is
// no run's, or "": "1,11" on repetitions 1-10 trained on 1 alone without a word.
std::string AbsentRepetitionRefusal(const CalibrationRequest& request);

}  // namespace fitcal
