#pragma once
// The validation report (`fitcal report`): its model (pages/report_model.h, built by
// validation/report_builder.h) and one renderer per output: index.html (report_html.h, figures in
// report_figures.h), summary.md (report_markdown.h), metrics.csv (report_csv.h), metrics.json
// (report_json.h) and tum/ (report_tum.h). Include the one you need; this header includes all.

#include "pages/report_csv.h"
#include "pages/report_figures.h"
#include "pages/report_html.h"
#include "pages/report_json.h"
#include "pages/report_markdown.h"
#include "pages/report_model.h"
#include "pages/report_tum.h"
