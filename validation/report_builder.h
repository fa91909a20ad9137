#pragma once
// The builder of the validation report (`fitcal report`): from the loaded data set and
// calibrations, the model every renderer formats (pages/report_model.h), built once. Every number
// is computed here (with fit/, validation/ and diagnosis/): each validation run replayed with the
// nominal and the calibrated model (Palacin Eq. 8-14), Table 6 per family and trajectory, drift
// per distance, uncertainty and identifiability of the parameters, effects, optional
// leave-one-repetition-out cross-validation, the verdict (validation/verdict.h), and the same for
// every further calibration compared on the same runs.

#include <optional>
#include <string>
#include <vector>

#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "pages/report_model.h"
#include "models/model_registry.h"
#include "odometry/effects.h"
#include "odometry/robot.h"
#include "validation/cross_validation.h"
#include "validation/training_runs.h"
#include "validation/trajectory_metrics.h"

namespace fitcal {

// One calibration to judge: the calibrated robot and what its YAML records.
struct CalibrationInput {
  std::string path;
  Robot calibrated;  // its nominal values are the calibrated parameters
  std::optional<io::CalibrationProvenance> provenance;
};

// The calibration at `path`, read for a data set of `dataset_robot`: refused (io::InputError,
// the file named) when it is another model or has another number of parameters.
CalibrationInput ReadCalibrationFor(const std::string& path, const Robot& dataset_robot);

// Everything the report reads, loaded and checked before anything is computed
// (cli/report_command.cc loads it).
struct ReportInputs {
  io::DatasetIndex index;
  std::vector<std::string> inputs;  // files the output must not overwrite
  io::Dataset dataset;
  RobotModelPtr model;  // the data set's robot (nominal parameters, absolute bounds), any model
  std::vector<CalibrationInput> calibrations;  // the first is the report's; others compared
};

struct ReportBuildOptions {
  std::string dataset;     // the data set as the user named it (--logs): the report's label
  std::string train_reps;  // training repetitions; empty = as recorded in the calibration YAML
  OdometrySampling sampling = OdometrySampling::kNearestTime;
  bool cross_validate = false;
  int threads = 0;     // 0 = all cores
  int worst_runs = 8;  // error-along-time figures drawn for this many of the worst runs
};

// Each calibration's split, the validation runs restricted to those every calibration left out:
// several calibrations are compared on the same runs, the ones none of them trained on.
std::vector<TrainingSplit> CommonSplits(const std::string& train_reps, const ReportInputs& in);

// Why there is nothing to report on `dataset` (--logs) with these splits, or "": every run
// trained the calibration (or at least one of several).
std::string NothingToValidateRefusal(const std::vector<TrainingSplit>& splits,
                                     const std::string& dataset);

// The report of in.calibrations[0] on its validation runs, with the others compared
// (ReportData::comparison); `splits` from CommonSplits, the first with validation runs.
io::ReportData BuildReport(const ReportInputs& in, std::vector<TrainingSplit> splits,
                           const ReportBuildOptions& options);

// Parameter k of `robot` and an effect, as the report and diagnose pages show them (the page
// fields a calibration fills; at-bound flags and cross-validation are the report's own).
io::ReportParameter ReportParameterOf(const Robot& robot, int k, double calibrated, bool has_sigma,
                                      double sigma);
io::ReportEffect ReportEffectOf(const effects::EffectValue& value);

}  // namespace fitcal
