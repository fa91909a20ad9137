#pragma once
// The page of `fitcal diagnose` (index.html) and its metrics.json: the residual structure tested,
// each effect tried with its evidence and decision, the before and after on the held-out runs
// (computed as `report` computes them, so both commands give one CF for one calibration on the
// same runs), what stays unexplained, one picture each. Pure formatting: the command fills
// DiagnosePageData with plain values (SI and radians); nothing here knows a solver.

#include <string>
#include <vector>

#include "pages/report_model.h"

namespace fitcal::io {

// One statistical test of the residual's structure.
struct DiagnoseStructureTest {
  std::string name;    // "lack of fit, declared fit"
  std::string detail;  // "F = 3.2 on (9, 40) dof"
  double p_value = 1.0;
  bool significant = false;
  std::string meaning;  // what a significant result says
};

// One candidate effect of one round of the tracing.
struct DiagnoseCandidate {
  int round = 1;
  std::string effect;
  double separable_fraction = 0.0;
  bool resolvable = false;
  bool fitted = false;
  double mean_improvement = 0.0;  // mean over held-out runs of the objective's fall
  double p_value = 1.0;           // one-sided paired t test
  double threshold = 0.0;         // alpha / candidates fitted in the round (Bonferroni)
  double delta_bic = 0.0;
  bool explains = false;
  bool accepted = false;
  std::string decision;  // the diagnosis' own words
};

// One candidate of the result gate (what diagnose may write).
struct DiagnoseGateRow {
  std::string name;
  double cf_held_out = 0.0;  // the gate's track-replay CF
  bool selected = false;
};

// A held-out run, nominal and the written calibration, computed as `report` does.
struct DiagnoseHeldOutRun {
  std::string id;
  double cf_before = 0.0, cf_after = 0.0;            // Eq. 14
  double ate_before_m = 0.0, ate_after_m = 0.0;      // Eq. 12, no alignment
  Point2 final_error_before_m, final_error_after_m;  // in the run's start frame
};

struct DiagnosePageData {
  std::string tool_version, dataset, split, robot_name, model;
  // EFFECTS_NAMED, PARTIAL (effects accepted, structure remains), UNEXPLAINED, NOTHING_FOUND.
  std::string level;
  std::string conclusion;  // one sentence
  std::vector<DiagnoseStructureTest> structure;
  std::vector<DiagnoseCandidate> candidates;
  std::vector<DiagnoseGateRow> gate;
  std::string selected;  // the gate's choice, written to calibrated.yaml
  std::vector<DiagnoseHeldOutRun> held_out;
  std::vector<std::string> unexplained;  // what stays unexplained, one line each
  std::vector<ReportParameter> parameters;
  std::vector<ReportEffect> effects;
  std::string text_report;  // the diagnosis as printed (Markdown), kept whole at the end
  bool csv_written = false;
};

// The mean of one field over the held-out runs (0 for none): the page's and metrics.json's figure.
double HeldOutMean(const std::vector<DiagnoseHeldOutRun>& runs, double DiagnoseHeldOutRun::*field);

std::string DiagnoseHtml(const DiagnosePageData& data);
std::string DiagnoseMetricsJson(const DiagnosePageData& data);

}  // namespace fitcal::io
