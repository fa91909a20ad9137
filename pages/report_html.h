#pragma once
// The HTML renderer of the report: index.html, one self-contained file with inline SVG figures
// (pages/report_figures.h), no network; every number is the model's (pages/report_model.h).

#include <sstream>
#include <string>

#include "pages/report_model.h"

namespace fitcal::io {

std::string ReportHtml(const ReportData& data);

// Shared by the pages of `report` and `diagnose` (pages/diagnose_page.h): one style sheet (readable
// from a 390 px phone to a 1400 px desktop).
// An HTML page's head (the report's style sheet, `title`) and its <body> up to <h1>heading</h1>.
std::string PageHead(const std::string& title, const std::string& heading);

// A table inside a horizontally scrolling box (both pages): wide tables scroll on a phone instead
// of pushing the page wider than the screen; `stacked` tables become one card per row there.
void OpenTable(std::ostringstream& h, const std::string& id = "", bool stacked = false);
void CloseTable(std::ostringstream& h);

}  // namespace fitcal::io
