#pragma once
// What `diagnose` computes, in one call: the ground-truth clocks re-stamped when asked, the
// channel-order check, the split, the diagnosis (diagnosis/diagnose.h), the calibration decided
// on it (diagnosis_calibration.h), the report's text, the written calibration's YAML and the page's
// data (diagnose_page_builder.h). The command loads the runs, calls it, prints and writes; no
// files and no printing here.

#include <string>
#include <vector>

#include "calibrate/diagnosis_calibration.h"
#include "pages/diagnose_page.h"

namespace fitcal {

struct DiagnoseDatasetRequest {
  std::string dataset;     // --logs: named in the report, the refusals and the record
  std::string robot_path;  // the robot YAML, named when it already declares effects
  std::string train_reps = "auto";
  std::string train_trajectories;
  std::string clock_offsets = "none";  // fit/clock_alignment.h
  bool clock_map = false;              // diagnosis/clock_choice.h
  bool check_channel_order = true;
  bool csv_written = false;  // the page says whether the residual CSVs were written
  int threads = 0;
  int max_effects = 3;
  double alpha = 0.01;
};

// A refusal stops the computation; what was computed before it stays (printed before the
// refusal): the clock notes; from the diagnosis on, the report; from the gate on, the calibration.
struct DiagnoseDatasetOutcome {
  Refusal refusal;
  std::vector<std::string> clock_notes;  // what re-stamping the clocks did, a line each
  DiagnosisSplit split;
  DiagnoseResult result;
  std::string report;  // diagnose.md up to the written calibration; empty before the diagnosis
  DiagnosisCalibration calibration;  // its gate is empty before the gate ran
  std::string written_text;          // "## Written calibration": the parameters with sigmas
  std::string yaml;                  // calibrated.yaml
  io::DiagnosePageData page;
  // The mount's x and y were freed (calibrate/mount_freed.h): why, and the model diagnosed.
  std::string mount_freed_line;
  RobotModelPtr mount_freed_model;
};

DiagnoseDatasetOutcome DiagnoseDataset(const DiagnoseDatasetRequest& request,
                                       const RobotModelInterface& model, std::vector<RunLog> runs);

}  // namespace fitcal
