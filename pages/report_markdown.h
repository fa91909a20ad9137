#pragma once
// The Markdown renderer of the report: summary.md, the page's tables in GitHub-flavoured Markdown.

#include <string>

#include "pages/report_model.h"

namespace fitcal::io {

std::string ReportMarkdown(const ReportData& data);

}  // namespace fitcal::io
