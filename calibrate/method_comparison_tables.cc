#include "calibrate/method_comparison_tables.h"

#include <cmath>
#include <sstream>

#include "models/model_registry.h"
#include "odometry/text_format.h"

namespace fitcal {
namespace {

std::string Fixed(double v, int digits) {
  if (std::isnan(v)) return "-";
  return StrFormat("%.*f", digits, v);
}

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

ParameterDisplay ComparisonColumns(const Robot& robot) {
  ParameterDisplay c;
  if (const auto& display = ExtrasOf(robot.model).display) return display(robot);
  c.markdown_header = "Parameters";
  for (const ParameterInfo& info : robot.parameters) {
    c.csv_names.push_back(info.KeyName());
  }
  c.csv_values = [robot](const std::vector<double>& p) {
    std::vector<double> out;
    for (int k = 0; k < robot.NumParameters(); ++k) {
      out.push_back(p[k] * robot.parameters[k].DisplayScale());
    }
    return out;
  };
  c.markdown = [robot](const std::vector<double>& p) {
    std::string out;
    for (int k = 0; k < robot.NumParameters(); ++k) {
      const ParameterInfo& info = robot.parameters[k];
      out += StrFormat("%s%s %.6g%s", out.empty() ? "" : ", ", info.name.c_str(),
                       p[k] * info.DisplayScale(),
                       info.unit == ParameterUnit::kAngle ? " deg" : "");
    }
    return out;
  };
  return c;
}

std::string ComparisonCsv(const std::vector<ComparisonRow>& rows, const ParameterDisplay& columns) {
  std::ostringstream o;
  o << "strategy,method,repetitions";
  for (const std::string& name : columns.csv_names) o << "," << name;
  o << ",cf_calibration,cf_validation,improvement_percent,evaluations,wall_s,termination,usable\n";
  for (const ComparisonRow& row : rows) {
    o << CsvField(row.strategy) << "," << row.method << "," << row.repetitions;
    const std::vector<double> values =
        row.parameters.empty() ? std::vector<double>() : columns.csv_values(row.parameters);
    for (std::size_t c = 0; c < columns.csv_names.size(); ++c) {
      o << "," << (values.empty() ? "" : Fixed(values[c], 8));
    }
    o << "," << (std::isnan(row.cf_calibration) ? "" : Fixed(row.cf_calibration, 8)) << ","
      << (std::isnan(row.cf_validation) ? "" : Fixed(row.cf_validation, 8)) << ","
      << (std::isnan(row.improvement_percent) ? "" : Fixed(row.improvement_percent, 3)) << ","
      << row.evaluations << "," << Fixed(row.wall_s, 4) << "," << CsvField(row.termination) << ","
      << (row.usable ? "yes" : "no") << "\n";
  }
  return o.str();
}

std::string ComparisonMarkdown(const std::vector<ComparisonRow>& rows,
                               const ParameterDisplay& columns) {
  std::ostringstream o;
  o << kComparisonMarkdownStart << columns.markdown_header
    << " | CF calibration | CF validation | Improvement | Evaluations | Wall [s] | Termination |\n"
    << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ComparisonRow& row : rows) {
    o << "| " << row.strategy << " | " << row.method << " | "
      << (row.repetitions ? std::to_string(row.repetitions) : "-") << " | "
      << (row.parameters.empty() ? "-" : columns.markdown(row.parameters)) << " | "
      << Fixed(row.cf_calibration, 4) << " | " << Fixed(row.cf_validation, 4) << " | "
      << (std::isnan(row.improvement_percent) ? "-" : Fixed(row.improvement_percent, 1) + "%")
      << " | " << (row.repetitions ? std::to_string(row.evaluations) : "-") << " | "
      << (row.repetitions ? Fixed(row.wall_s, 2) : "-") << " | " << row.termination
      << (row.usable ? "" : " (not usable)") << " |\n";
  }
  return o.str();
}

std::string ComparisonTraceCsv(const std::vector<ComparisonRow>& rows) {
  std::ostringstream o;
  o << kComparisonTraceStart << "\n";
  for (const ComparisonRow& row : rows) {
    for (const ConvergencePoint& p : row.trace) {
      o << CsvField(row.strategy) << "," << row.method << "," << row.repetitions << ","
        << p.evaluations << "," << Fixed(p.best_cf, 10) << "," << Fixed(p.elapsed_s, 4) << "\n";
    }
  }
  return o.str();
}

}  // namespace fitcal
