#pragma once
// The data of diagnose's page (pages/diagnose_page.h: index.html and metrics.json) from a diagnosis
// (diagnosis/diagnose.h) and the calibration decided on it (calibrate/diagnosis_calibration.h):
// the conclusion, the structure tests, the effect candidates, the gate, the held-out runs as
// `report` computes them, and the written parameters. No decision is made here.

#include <string>
#include <vector>

#include "calibrate/diagnosis_calibration.h"
#include "pages/diagnose_page.h"

namespace fitcal {

// What the page says of where the runs came from.
struct DiagnosePageSource {
  std::string dataset;  // --logs
  std::string split;    // the split in words
  bool csv_written = false;
};

// `held_out`: the runs the gate judged on; `report`: the text report, shown on the page.
io::DiagnosePageData MakeDiagnosePage(const DiagnosePageSource& source,
                                      const RobotModelInterface& model,
                                      const std::vector<TrackRun>& held_out,
                                      const DiagnoseResult& result,
                                      const DiagnosisCalibration& calibration,
                                      const std::string& report);

}  // namespace fitcal
