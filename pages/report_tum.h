#pragma once
// The TUM renderer of the report (`report --tum`, docs/tum.md): tum/<run>.{ground_truth,nominal,
// calibrated}.tum of every judged run, the world poses at the ground-truth times on which the
// report's ATE (Eq. 12) and drift are computed (the model's world_tracks).

#include <string>
#include <vector>

#include "pages/report_model.h"

namespace fitcal::io {

// One file: its path relative to the report's directory, and its text.
struct ReportFile {
  std::string relative_path;
  std::string text;
};

std::vector<ReportFile> ReportTumFiles(const ReportData& data);

}  // namespace fitcal::io
