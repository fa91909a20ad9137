#pragma once
// The files `fitcal compare` writes from the comparison's rows (method_comparison.h): the table
// as CSV and Markdown, each fit's convergence trace as CSV, and a row's parameters as the model
// shows them (ModelExtras::display: omni3 as the M^-1 of Palacin Eq. 6; else the parameters in
// display units, m and deg). Strings only: the command writes them.

#include <string>
#include <vector>

#include "calibrate/method_comparison.h"
#include "models/model_extras.h"

namespace fitcal {

// How each file starts, whatever the model: how a later run recognises them as its own previous
// output (io/output_guard.h, rule 1).
constexpr char kComparisonCsvStart[] = "strategy,method,repetitions,";
constexpr char kComparisonMarkdownStart[] = "| Strategy | Method | Reps | ";
constexpr char kComparisonTraceStart[] =
    "strategy,method,repetitions,evaluation,best_cf,elapsed_s";

ParameterDisplay ComparisonColumns(const Robot& robot);

std::string ComparisonCsv(const std::vector<ComparisonRow>& rows, const ParameterDisplay& columns);
std::string ComparisonMarkdown(const std::vector<ComparisonRow>& rows,
                               const ParameterDisplay& columns);
std::string ComparisonTraceCsv(const std::vector<ComparisonRow>& rows);

}  // namespace fitcal
