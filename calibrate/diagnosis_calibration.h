#pragma once
// The calibration `diagnose` writes, decided from its diagnosis (diagnosis/diagnose.h): the
// candidates judged like the fit's result gate on the held-out runs by the track replay's
// final-pose CF (the nominal, the declared final-pose fit, the track fit, and the track fit with
// its effects when they were named; none with a parameter on its bound, as fit's bounds' rule),
// the never-worse judgement against the nominal, the uncertainty (the fit's, or propagated
// through the training runs' final poses), and the record.
// A track fit with effects that were not named is not a candidate: the file would claim a CF its
// parameters reach only together with effects it does not carry.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "calibrate/calibrate.h"
#include "calibrate/never_worse_gate.h"
#include "diagnosis/diagnose.h"
#include "fit/run_split.h"
#include "io/calibration_block.h"

namespace fitcal {

struct DiagnoseChoice {
  std::string name;
  std::vector<double> parameters;
  EffectModel effects;
  double cf_before = 0.0;  // nominal, held-out
  double cf_after = 0.0;
  double cf_training_before = 0.0;  // nominal, training runs (the same track-replay CF)
  double cf_training_after = 0.0;
  // The covariance of the fit that made these parameters, with its effects: empty for the
  // nominal or when the fit had none.
  std::vector<double> sigma = {};
  Eigen::MatrixXd correlation = Eigen::MatrixXd();
};

// What the record says of the data set and the split beside the diagnosis.
struct DiagnosisCalibrationRequest {
  std::string dataset;             // --logs
  std::string train_trajectories;  // as given
  const std::vector<RunLog>* runs = nullptr;  // every run (the training fingerprint)
  int threads = 0;
};

struct DiagnosisCalibration {
  // kGate: refused there (no candidate beats the nominal); kNeverWorse: refused there or, with no
  // refusal, an uncertainty could not be had (exit 1); kDone: written.
  CalibrationStage reached = CalibrationStage::kGate;
  Refusal refusal;
  std::vector<DiagnoseChoice> gate;  // the candidates, [0] the nominal
  DiagnoseChoice choice;             // the selected one, with its uncertainty when kDone
  std::vector<std::string> never_worse_warnings;
  // The lowest held-out CF had a parameter on its bound and gave way to `choice`; or empty.
  std::string gave_way_line;
  // The declared final-pose fit did not converge and is no candidate; or empty.
  std::string left_out_line;
  bool uncertainty_propagated = false;  // the fit that made `choice` had none of its own
  // What the sigmas hold beyond the fit's covariance, one line each (the angle channels'
  // resolution, as fit's SelectedFit::sigma_notes).
  std::vector<std::string> sigma_notes;
  io::CalibrationBlock record;          // when kDone
};

// The track runs on each side (fit/run_split.h: by train_trajectories, else by train_reps, "auto"
// the first half of the repetitions present), with the split in words for the report and page.
struct DiagnosisSplit : SplitOf<TrackRun> {
  std::string text;
};
DiagnosisSplit SplitForDiagnosis(const std::vector<RunLog>& runs, const Robot& robot,
                                 const std::string& train_reps,
                                 const std::string& train_trajectories);

// What diagnose refuses, each with exit 2 before any fit or exit 3 after, and the reason: a robot
// YAML that already declares effects (the diagnosis adds them to a robot without); a split
// without training or held-out runs (the effects are judged on held-out runs); a track fit (the
// diagnosis' base and final fit) that did not converge, or a declared fit without a finite point
// (nothing they say could be trusted). A declared fit that stopped short of converging is only
// left out of the gate (DiagnosisCalibration::left_out_line): the tracks are the diagnosis.
Refusal RefusalOfDeclaredEffects(const Robot& robot, const std::string& robot_path);
Refusal RefusalOfSplit(const DiagnosisSplit& split);
Refusal RefusalOfUnconvergedFits(const DiagnoseResult& result);

DiagnosisCalibration CalibrateOnDiagnosis(const DiagnosisCalibrationRequest& request,
                                          const RobotModelInterface& model,
                                          const SplitOf<TrackRun>& split,
                                          const DiagnoseResult& result);

}  // namespace fitcal
