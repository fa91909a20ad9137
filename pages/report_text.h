#pragma once
// What the report's renderers share (pages/report_html.cc, report_markdown.cc, report_json.cc,
// report_csv.cc, report_figures.cc): number formats, the Table 6 columns, the colours and names
// of nominal and calibrated, and the display choices derived from the model (which runs to
// draw, each coloured track's scale). Internal to
// those renderers: include it from nowhere else.

#include <cmath>
#include <string>
#include <vector>

#include "pages/report_model.h"

namespace fitcal::io::report_text {

constexpr double kDeg = 180.0 / M_PI;
extern const char* const kGroundTruthColour;  // light grey: drawn under the odometry
extern const char* const kBeforeColour;       // vermillion: nominal parameters
extern const char* const kAfterColour;        // blue: calibrated parameters
extern const char* const kBeforeName;         // "odometry, nominal parameters"
extern const char* const kAfterName;          // "odometry, calibrated parameters"

// printf of one number; "-" when it is not finite.
std::string Fmt(const char* format, double v);

// Palacin Table 6's improvement, 100 (before - after) / before (positive = better); 0 when
// before is not positive.
double Improvement(double before, double after);

// Every % change on the page and in summary.md has one sign: 100 (after - before) / before, so
// an error that shrank is negative (and green), a parameter that grew positive. metrics.json's
// improvement_percent keeps Palacin Table 6's sign (positive = better) and says so in its name.
// "-" when nothing was there before (before <= 0).
std::string ChangePercentText(double before, double after);

// "1 run", "3 runs" (issue 42: "validation: 1 runs").
std::string RunsText(std::size_t n);

// Table 6 columns: (label, unit, getter, is angle).
struct Column {
  const char* key;    // machine name, SI
  const char* label;  // for people
  bool is_angle;
  double ReportMetrics::*field;
};
extern const Column kColumns[7];

// Key with the unit suffix of the output: angles are degrees at the edge.
std::string KeyOf(const Column& c);
double ValueOf(const Column& c, const ReportMetrics& m);
const char* FormatOf(const Column& c);

// How a parameter's change from its nominal is said, in fit's printout and on the pages alike:
// angles by degrees (a percentage of an angle means nothing), a frame's position and a zero
// nominal by metres (a percentage of where a mount sits depends on the origin: guessed at x 0.05 m
// and found at 0.35 m is +0.3 m, not +600 %), sizes by percent.
enum class ChangeTerms { kDegrees, kMetres, kPercent };
ChangeTerms ChangeTermsOf(bool is_angle, bool is_position, double nominal);

// A parameter's display scale (deg for angles) and its change in those terms.
double ParamScale(const ReportParameter& p);
std::string ParameterChangeText(const ReportParameter& p);

// The runs the error-along-time figures show: largest calibrated CF first, at most `most`.
std::vector<std::size_t> WorstRuns(const ReportData& data, std::size_t most);

// The held-out runs whose odometry is drawn coloured by its error: every run up to this many,
// else the worst by calibrated CF (the size budget of the page).
constexpr std::size_t kMostColouredTracks = 30;

// The colour scale of one run's pair of coloured-track panels: 0 to its largest position error,
// nominal or calibrated (so the two panels compare, and a good run is not all dark beside a bad
// one).
double ColouredTrackScale(const ReportRun& r);

}  // namespace fitcal::io::report_text
