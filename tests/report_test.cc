// The report files (pages/report_*.h, pages/svg_plot.h): index.html is well formed, embeds
// every figure, and references nothing outside itself; the CSV and JSON carry the numbers.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pages/diagnose_page.h"
#include "pages/report_csv.h"
#include "pages/report_figures.h"
#include "pages/report_html.h"
#include "pages/report_json.h"
#include "pages/report_markdown.h"
#include "pages/report_model.h"
#include "pages/report_tum.h"
#include "pages/svg_plot.h"
#include "validation/trajectory_family.h"

namespace fitcal::io {
namespace {

// Checks that every element opened is closed in order (HTML void elements and "/>" excepted) and
// that no raw '<' or '&' without an entity appears in text. Returns "" or the first problem.
std::string CheckWellFormed(const std::string& html) {
  static const std::set<std::string> kVoid = {"meta", "br", "img", "input", "hr", "link"};
  std::vector<std::string> stack;
  std::size_t i = 0;
  if (html.rfind("<!DOCTYPE html>", 0) != 0) return "no doctype";
  i = html.find('>') + 1;
  bool in_script = false;
  while (i < html.size()) {
    if (html[i] == '&') {
      const std::size_t semi = html.find(';', i);
      if (semi == std::string::npos || semi - i > 10) return "bare & at " + std::to_string(i);
      ++i;
      continue;
    }
    if (html[i] != '<') {
      ++i;
      continue;
    }
    const std::size_t end = html.find('>', i);
    if (end == std::string::npos) return "unterminated tag";
    std::string tag = html.substr(i + 1, end - i - 1);
    i = end + 1;
    if (in_script && tag != "/script") continue;
    if (tag.empty()) return "empty tag";
    const bool closing = tag[0] == '/';
    const bool self_closing = tag.back() == '/';
    std::string name = tag.substr(closing ? 1 : 0);
    name = name.substr(0, name.find_first_of(" /\n"));
    if (!std::regex_match(name, std::regex("[a-zA-Z][a-zA-Z0-9]*"))) return "bad tag <" + tag + ">";
    if (closing) {
      if (stack.empty() || stack.back() != name) {
        return "</" + name + "> closes <" + (stack.empty() ? "" : stack.back()) + ">";
      }
      stack.pop_back();
      in_script = false;
    } else if (!self_closing && !kVoid.count(name)) {
      stack.push_back(name);
      in_script = name == "script";
    }
  }
  return stack.empty() ? "" : "<" + stack.back() + "> never closed";
}

ReportData SmallReport() {
  ReportData d;
  d.tool_version = "test";
  d.dataset = "data<&>";  // must come out escaped
  d.calibration = "cal.yaml";
  d.robot_name = "apr02";
  d.sampling = "nearest";
  d.training_repetitions = "1-5";
  d.validation_repetitions = "6";
  d.training_runs = 3;
  for (int k = 0; k < 3; ++k) {
    ReportRun r;
    r.trajectory = std::string(1, "RGB"[k]) + "1";
    r.id = r.trajectory + "-rep06";
    r.repetition = 6;
    for (int i = 0; i <= 4; ++i) {
      const double t = 0.25 * i;
      r.t_s.push_back(t);
      r.along_m.push_back(t);
      r.ground_truth_xy.push_back({t, 0.1 * k * t * t});
      r.before_xy.push_back({t, 0.1 * k * t * t + 0.02 * t});
      r.after_xy.push_back({t, 0.1 * k * t * t + 0.002 * t});
      r.before_distance_m.push_back(0.02 * t);
      r.after_distance_m.push_back(0.002 * t);
      r.before_angle_rad.push_back(0.01 * t);
      r.after_angle_rad.push_back(0.001 * t);
    }
    r.before_final_error = {0.02, 0.01};
    r.after_final_error = {0.002, -0.001};
    r.before.cf = 0.05 + 0.01 * k;
    r.after.cf = 0.005;
    r.before.final_angle_rad = 0.01;
    r.after.final_angle_rad = 0.001;
    r.before.final_distance_m = 0.02 + 0.01 * k;
    r.after.final_distance_m = 0.002;
    d.runs.push_back(r);
  }
  ReportSummaryRow all;
  all.group = "all validation runs";
  all.runs = 3;
  all.before.cf = 0.06;
  all.after.cf = 0.005;
  all.before.final_angle_rad = 0.01;
  all.after.final_angle_rad = 0.001;
  d.summary.push_back(all);
  d.statistics.push_back(ReportStatisticsRow{
      "cf", false, {0.06, 0.06, 0.06, 0.01, 0.05, 0.07}, {0.005, 0.005, 0.005, 0, 0.005, 0.005}});
  const char* names[] = {"R_a", "R_b", "R_c", "r_a", "r_b", "r_c", "delta_a", "delta_b", "delta_c"};
  d.has_correlation = true;
  d.correlation.assign(9, std::vector<double>(9, 0.0));
  for (int k = 0; k < 9; ++k) {
    ReportParameter p;
    p.name = names[k];
    p.is_angle = k >= 6;
    p.unit = p.is_angle ? "deg" : "m";
    p.nominal = p.is_angle ? 1.0 : 0.195;
    p.calibrated = p.nominal * 1.01;
    p.has_sigma = true;
    p.sigma = 1e-4;
    d.parameters.push_back(p);
    d.correlation[k][k] = 1.0;
  }
  d.correlation[0][3] = d.correlation[3][0] = -0.995;
  d.identifiable = false;
  d.identifiability_lines = {"warning: the training runs cannot determine all nine parameters",
                             "  correlation(R_a, r_a) = -0.9950"};
  d.parameters[0].at_bound = true;
  d.verdict = "WARN";
  d.verdict_reasons = {{"WARN", "bounds", "parameters", "R_a rests on a bound"},
                       {"PASS", "improvement", "summary", "held-out CF 0.06 -> 0.005"}};
  d.training_source = "3 runs of this data set, recorded by id";
  d.trajectories = {all};
  d.drift.resize(1);
  d.drift[0].length_m = 1.0;
  d.drift[0].windows = 12;
  d.drift[0].before_translation_percent = 2.0;
  d.drift[0].after_translation_percent = 0.2;
  d.drift[0].before_rotation_rad_per_m = 0.01;
  d.drift[0].after_rotation_rad_per_m = 0.001;
  d.drift[0].before_translation_percent_windows = {1.0, 2.0, 3.0};
  d.drift[0].after_translation_percent_windows = {0.1, 0.2, 0.3};
  d.drift[0].before_rotation_rad_per_m_windows = {0.01, 0.01, 0.01};
  d.drift[0].after_rotation_rad_per_m_windows = {0.001, 0.001, 0.001};
  d.effects = {{"time_offset", {"latency_s"}, {0.08}, {0.002}}};
  d.cf_parameters_only = 0.007;
  return d;
}

// Cells of a GitHub-flavoured Markdown table row: the '|' not escaped by a backslash, minus one.
int MarkdownCells(const std::string& row) {
  int pipes = 0;
  for (std::size_t i = 0; i < row.size(); ++i)
    pipes += row[i] == '|' && (i == 0 || row[i - 1] != '\\');
  return pipes - 1;
}

TEST(ReportTest, HtmlIsWellFormedAndEmbedsEveryFigure) {
  const ReportData d = SmallReport();
  const std::string html = ReportHtml(d);
  EXPECT_EQ(CheckWellFormed(html), "");
  const ReportFigures f = MakeReportFigures(d);
  std::vector<std::string> figures = {f.flower, f.end_points, f.final_distance_bars,
                                      f.final_angle_bars, f.correlation};
  figures.insert(figures.end(), f.error_along_time.begin(), f.error_along_time.end());
  ASSERT_EQ(f.error_along_time.size(), d.runs.size());
  for (const std::string& fig : figures) {
    ASSERT_FALSE(fig.empty());
    EXPECT_EQ(CheckWellFormed("<!DOCTYPE html>" + fig), "");
    EXPECT_NE(html.find(fig), std::string::npos) << fig.substr(0, 200);
  }
  ASSERT_FALSE(f.residual_histogram.empty());
  EXPECT_NE(html.find(f.residual_histogram), std::string::npos);
  // The distance pictures: error against distance (position, heading; nominal beside
  // calibrated), drift boxes (translation, rotation), every run coloured by its error.
  for (const std::string* fig : {&f.position_error_along_distance, &f.heading_error_along_distance,
                                 &f.drift_translation_boxes, &f.drift_rotation_boxes}) {
    ASSERT_FALSE(fig->empty());
    EXPECT_EQ(CheckWellFormed("<!DOCTYPE html>" + *fig), "");
    EXPECT_NE(html.find(*fig), std::string::npos);
  }
  ASSERT_EQ(f.coloured_tracks.size(), d.runs.size());
  for (const std::string& fig : f.coloured_tracks) EXPECT_NE(html.find(fig), std::string::npos);
  // One <svg> per figure: 6 single figures, two (distance, heading) per run drawn (all three
  // here: fewer than worst_runs_drawn), 2 x 2 error-against-distance panels, 2 drift box plots,
  // two coloured tracks per run and their colour bar.
  std::size_t svgs = 0;
  for (std::size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1))
    ++svgs;
  EXPECT_EQ(svgs, 6 + 2 * d.runs.size() + 4 + 2 + 2 * d.runs.size() + 1);
  // Clip-path ids must be unique within the document.
  std::set<std::string> ids;
  const std::regex id_re("id=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), id_re);
       it != std::sregex_iterator(); ++it) {
    EXPECT_TRUE(ids.insert((*it)[1]).second) << "duplicate id " << (*it)[1];
  }
  // Escaping and the identifiability warning.
  EXPECT_NE(html.find("data&lt;&amp;&gt;"), std::string::npos);
  EXPECT_NE(html.find("correlation(R_a, r_a) = -0.9950"), std::string::npos);
}

TEST(ReportTest, HtmlReferencesNothingOutsideItself) {
  const std::string html = ReportHtml(SmallReport());
  for (const char* bad : {"src=", "@import", "http:", "https:", "xlink", "<link", "<iframe",
                          "<object", "<embed", "<img", "<script"}) {
    EXPECT_EQ(html.find(bad), std::string::npos) << bad;
  }
  // Links only to the document's own sections (the verdict's reasons), each of which exists.
  int links = 0;
  for (std::size_t p = html.find("href="); p != std::string::npos; p = html.find("href=", p + 1)) {
    ASSERT_EQ(html.substr(p, 7), "href=\"#") << html.substr(p, 40);
    const std::string id = html.substr(p + 7, html.find('"', p + 7) - p - 7);
    EXPECT_NE(html.find("id=\"" + id + "\""), std::string::npos) << id;
    ++links;
  }
  EXPECT_EQ(links, 2);
  // Only in-document url(#...) references.
  for (std::size_t p = html.find("url("); p != std::string::npos; p = html.find("url(", p + 1)) {
    EXPECT_EQ(html[p + 4], '#') << html.substr(p, 40);
  }
}

// The page is usable on a phone (viewport meta; figures and tables scale or scroll), needs no
// JavaScript, and stays small on a large data set: 120 runs of 3000 samples each (a 100 Hz
// recording of 30 s) come out under the 2 MB budget of the issue, because tracks are thinned for
// drawing and only the worst runs get their error-along-time figures.
TEST(ReportTest, HtmlIsResponsiveAndWithinItsSizeBudget) {
  ReportData d = SmallReport();
  const ReportRun model = d.runs[0];
  d.runs.clear();
  for (int k = 0; k < 120; ++k) {
    ReportRun r = model;
    r.id = "run" + std::to_string(k);
    r.trajectory = "T" + std::to_string(k % 12);
    r.t_s.clear();
    r.ground_truth_xy.clear();
    r.before_xy.clear();
    r.after_xy.clear();
    r.before_distance_m.clear();
    r.after_distance_m.clear();
    r.before_angle_rad.clear();
    r.after_angle_rad.clear();
    for (int i = 0; i < 3000; ++i) {
      const double t = 0.01 * i, a = 0.002 * i + 0.01 * k;
      r.t_s.push_back(t);
      r.ground_truth_xy.push_back({std::cos(a), std::sin(a)});
      r.before_xy.push_back({1.02 * std::cos(a), std::sin(a)});
      r.after_xy.push_back({1.002 * std::cos(a), std::sin(a)});
      r.before_distance_m.push_back(0.02 * t);
      r.after_distance_m.push_back(0.002 * t);
      r.before_angle_rad.push_back(0.01 * t);
      r.after_angle_rad.push_back(0.001 * t);
    }
    r.after.cf = 0.001 * k;
    d.runs.push_back(r);
  }
  const std::string html = ReportHtml(d);
  EXPECT_EQ(CheckWellFormed(html), "");
  EXPECT_LT(html.size(), 2u << 20) << html.size();
  EXPECT_NE(html.find("<meta name=\"viewport\" content=\"width=device-width"), std::string::npos);
  EXPECT_NE(html.find("svg{max-width:100%;height:auto}"), std::string::npos);
  EXPECT_NE(html.find("<div class=\"scroll\">\n<table>"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  // The worst runs drawn (largest calibrated CF first), not one run behind a selector.
  const ReportFigures f = MakeReportFigures(d);
  ASSERT_EQ(f.error_along_time_runs.size(), static_cast<std::size_t>(d.worst_runs_drawn));
  EXPECT_EQ(f.error_along_time_runs[0], 119u);
  EXPECT_EQ(f.error_along_time_runs[1], 118u);
  // Generic labels: nothing of the flower's R/G/B naming on other data.
  EXPECT_EQ(html.find("R straight"), std::string::npos);
}

// summary.md renders as tables: in every table, every row has as many cells as the header
// (the "|angle|" column labels are escaped, not cell separators).
TEST(ReportTest, MarkdownTablesHaveConsistentCellCounts) {
  const std::string md = ReportMarkdown(SmallReport());
  std::istringstream lines(md);
  std::string line;
  int header = -1, tables = 0, rows = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] != '|') {
      header = -1;
      continue;
    }
    if (header < 0) {
      header = MarkdownCells(line);
      ++tables;
      continue;
    }
    ++rows;
    EXPECT_EQ(MarkdownCells(line), header) << line;
  }
  EXPECT_GE(tables, 6);
  EXPECT_GT(rows, 20);
  EXPECT_NE(md.find("RMS \\|angle\\| error"), std::string::npos);
  EXPECT_NE(md.find("## Verdict: WARN"), std::string::npos);
  EXPECT_NE(md.find("| R_a | m |"), std::string::npos);
  EXPECT_NE(md.find("AT BOUND"), std::string::npos);
}

TEST(ReportTest, CsvAndJsonCarryTheNumbers) {
  const ReportData d = SmallReport();
  const std::string csv = MetricsCsv(d);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + static_cast<long>(d.runs.size()));
  EXPECT_EQ(csv.rfind("run,trajectory,repetition,before_rms_distance_m,", 0), 0u);
  EXPECT_NE(csv.find("before_final_angle_deg"), std::string::npos);
  // JSON is valid YAML 1.2 flow: parse it back and read numbers (angles in degrees).
  const YAML::Node j = YAML::Load(MetricsJson(d));
  EXPECT_EQ(j["summary"][0]["group"].as<std::string>(), "all validation runs");
  EXPECT_NEAR(j["summary"][0]["before"]["cf"].as<double>(), 0.06, 1e-12);
  EXPECT_NEAR(j["summary"][0]["improvement_percent"]["cf"].as<double>(),
              100.0 * (0.06 - 0.005) / 0.06, 1e-6);
  EXPECT_NEAR(j["summary"][0]["before"]["final_angle_deg"].as<double>(), 0.01 * 180.0 / M_PI, 1e-9);
  EXPECT_EQ(j["runs"].size(), d.runs.size());
  EXPECT_NEAR(j["correlation"][0][3].as<double>(), -0.995, 1e-12);
  EXPECT_FALSE(j["identifiability"]["identifiable"].as<bool>());
  // The verdict and the effects are structured, not strings.
  EXPECT_EQ(j["verdict"]["level"].as<std::string>(), "WARN");
  EXPECT_EQ(j["verdict"]["reasons"][0]["check"].as<std::string>(), "bounds");
  EXPECT_EQ(j["verdict"]["reasons"][0]["section"].as<std::string>(), "parameters");
  EXPECT_NEAR(j["effects"]["list"][0]["parameters"][0]["value"].as<double>(), 0.08, 1e-12);
  EXPECT_NEAR(j["effects"]["list"][0]["parameters"][0]["sigma"].as<double>(), 0.002, 1e-12);
  EXPECT_NEAR(j["effects"]["cf_parameters_only"].as<double>(), 0.007, 1e-12);
  EXPECT_TRUE(j["parameters"][0]["at_bound"].as<bool>());
  EXPECT_NEAR(j["drift"][0]["translation_percent"]["after"].as<double>(), 0.2, 1e-12);
  for (const char* stat : {"rmse", "mean", "median", "std", "min", "max"}) {
    EXPECT_TRUE(j["statistics"]["cf"]["before"][stat]) << stat;
  }
}

TEST(SvgPlotTest, TicksEscapingAndLabels) {
  const std::vector<double> expected = {0.0, 0.2, 0.4, 0.6, 0.8, 1.0};
  const auto ticks = NiceTicks(0.0, 1.0, 6);
  ASSERT_EQ(ticks.size(), expected.size());
  for (std::size_t i = 0; i < ticks.size(); ++i) EXPECT_NEAR(ticks[i], expected[i], 1e-12);
  const auto t = NiceTicks(-0.013, 0.047, 7);
  ASSERT_FALSE(t.empty());
  EXPECT_GE(t.front(), -0.013);
  EXPECT_LE(t.back(), 0.047 + 1e-12);
  EXPECT_EQ(EscapeXml("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
  SvgSeries s;
  s.name = "gt <truth>";
  s.lines = {{{0.0, 0.0}, {1.0, 2.0}}};
  XYPlotOptions o;
  o.title = "T";
  o.x_label = "x [m]";
  o.y_label = "y [m]";
  const std::string svg = XYPlotSvg(o, {s});
  EXPECT_NE(svg.find(">x [m]<"), std::string::npos);
  EXPECT_NE(svg.find(">y [m]<"), std::string::npos);
  EXPECT_NE(svg.find(">gt &lt;truth&gt;<"), std::string::npos);  // legend
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  EXPECT_EQ(CheckWellFormed("<!DOCTYPE html>" + svg), "");
  // Equal aspect: the plotted x and y spans per pixel agree, so a unit square stays square.
  o.equal_aspect = true;
  o.width = 600;
  o.height = 300;
  const std::string eq = XYPlotSvg(o, {s});
  const std::regex pts("points=\"([0-9.]+),([0-9.]+) ([0-9.]+),([0-9.]+) \"");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(eq, m, pts));
  const double dx = std::stod(m[3]) - std::stod(m[1]);
  const double dy = std::stod(m[2]) - std::stod(m[4]);
  EXPECT_NEAR(dy / dx, 2.0, 0.01);  // the segment (1, 2) keeps its slope on screen
}

// Category labels under a bar chart: the horizontal extent of each (level: its estimated width;
// upright: one line height) must not reach into its neighbour's. Returns "" or the first overlap.
std::string LabelOverlap(const std::string& svg, const std::vector<std::string>& labels) {
  std::vector<std::pair<double, double>> spans;
  for (const std::string& label : labels) {
    const std::string needle = ">" + label + "</text>";
    const std::size_t end = svg.find(needle);
    if (end == std::string::npos) return "label " + label + " missing";
    const std::size_t start = svg.rfind("<text", end);
    const std::string tag = svg.substr(start, end - start);
    std::smatch m;
    if (!std::regex_search(tag, m, std::regex("x=\"([-0-9.]+)\".*font-size=\"([0-9]+)\""))) {
      return "unparsed " + tag;
    }
    const double x = std::stod(m[1]), font = std::stod(m[2]);
    const bool upright = tag.find("rotate(-90") != std::string::npos;
    const double half = upright ? 0.5 * font : 0.5 * TextWidthPx(label, font);
    spans.push_back({x - half, x + half});
  }
  for (std::size_t i = 1; i < spans.size(); ++i) {
    if (spans[i].first < spans[i - 1].second) return labels[i - 1] + " overlaps " + labels[i];
  }
  return "";
}

// The defect seen on the differential drive: 21 session-stamped trajectory labels under 1100 px
// of bars were written level and overlapped. Short labels stay level.
TEST(SvgPlotTest, BarLabelsNeverOverlap) {
  std::vector<std::string> labels;
  BarSeries a{"nominal", "#d55e00", {}}, b{"calibrated", "#0072b2", {}};
  for (int k = 0; k < 21; ++k) {
    labels.push_back("circular_2306202021" + std::to_string(10 + k));
    a.values.push_back(1.0 + k);
    b.values.push_back(0.5 + k);
  }
  BarChartOptions o;
  o.title = "T";
  const std::string svg = BarChartSvg(o, labels, {a, b});
  EXPECT_EQ(LabelOverlap(svg, labels), "");
  EXPECT_EQ(CheckWellFormed("<!DOCTYPE html>" + svg), "");
  const std::vector<std::string> few = {"R1", "G1", "B1"};
  const std::string level = BarChartSvg(o, few, {a, b});
  EXPECT_EQ(LabelOverlap(level, few), "");
  EXPECT_EQ(level.find("rotate(-90 "), level.rfind("rotate(-90 "));  // only the y-axis title
  // Box plots share the layout.
  const std::string boxes = BoxPlotSvg(o, labels, {{"n", "#d55e00", {{1, 2, 3, 10}}}});
  EXPECT_EQ(LabelOverlap(boxes, labels), "");
}

// The defect seen on three-parameter robots: the heat map was narrower than its title (clipped),
// and the diff drive's correlations of 0.9993-0.9999 read 1.00 like the diagonal.
TEST(SvgPlotTest, ThreeParameterHeatMapIsWholeAndReadable) {
  const std::string title = "Correlation of the fitted parameters (-1 blue, +1 red)";
  const std::vector<std::vector<double>> c = {{1.0, 0.9999, -0.9991}, {0.9999, 1.0, 0.5},
                                              {-0.9991, 0.5, 1.0}};
  const std::string svg = HeatMapSvg(title, {"r_R", "r_L", "b"}, c);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(svg, m, std::regex("viewBox=\"0 0 ([0-9]+) ")));
  EXPECT_GE(std::stod(m[1]), TextWidthPx(title, 15));
  // Row labels start inside the figure; column labels do not overlap (the diff drive's
  // "wheel_separation" was cut on the left and ran into "r_left" below).
  const std::vector<std::string> labels = {"r_right", "r_left", "wheel_separation"};
  const std::string named = HeatMapSvg(title, labels, c);
  std::smatch row;
  ASSERT_TRUE(std::regex_search(named, row,
                                std::regex("<text x=\"([0-9.]+)\"[^>]*text-anchor=\"end\""
                                           "[^>]*>wheel_separation<")));
  EXPECT_GE(std::stod(row[1]), TextWidthPx("wheel_separation", 12));
  const std::string columns_only =
      std::regex_replace(named, std::regex("<text [^>]*text-anchor=\"end\">[^<]*</text>"), "");
  EXPECT_EQ(LabelOverlap(columns_only, labels), "");
  EXPECT_NE(svg.find(">0.9999<"), std::string::npos);  // the recorded 4 digits, not 1.00
  EXPECT_NE(svg.find(">-0.9991<"), std::string::npos);
  EXPECT_NE(svg.find(">1.00<"), std::string::npos);  // the diagonal
  EXPECT_NE(svg.find(">0.50<"), std::string::npos);
}

// Parameters a robot YAML holds at nominal (omni4's) say so on the page and in metrics.json.
TEST(ReportTest, HeldParametersAreMarkedHeld) {
  ReportData d = SmallReport();
  d.parameters[8].held = true;
  d.parameters[8].has_sigma = false;
  d.parameters[8].calibrated = d.parameters[8].nominal;
  const std::string html = ReportHtml(d);
  EXPECT_NE(html.find("<td class=\"held\">held at nominal</td>"), std::string::npos);
  EXPECT_NE(ReportMarkdown(d).find("held at nominal"), std::string::npos);
  EXPECT_NE(MakeReportFigures(d).correlation.find(">delta_c (held)<"), std::string::npos);
  const YAML::Node j = YAML::Load(MetricsJson(d));
  EXPECT_TRUE(j["parameters"][8]["held"].as<bool>());
  EXPECT_TRUE(j["parameters"][8]["sigma"].IsNull());
  EXPECT_FALSE(j["parameters"][0]["held"].as<bool>());
  EXPECT_NEAR(j["parameters"][0]["value"].as<double>(), 0.195 * 1.01, 1e-12);
  EXPECT_NEAR(j["parameters"][0]["sigma"].as<double>(), 1e-4, 1e-15);
}

// An angle's generic value and sigma are radians, as its unit says; degrees only under _deg keys
// (version 2 wrote degrees under "value": 57.9 here for 1.01 rad).
TEST(ReportTest, AngleParametersAreRadiansUnlessTheKeySaysDeg) {
  const YAML::Node angle = YAML::Load(MetricsJson(SmallReport()))["parameters"][6];
  EXPECT_EQ(angle["unit"].as<std::string>(), "rad");
  EXPECT_NEAR(angle["value"].as<double>(), 1.01, 1e-12);
  EXPECT_NEAR(angle["sigma"].as<double>(), 1e-4, 1e-15);
  EXPECT_NEAR(angle["calibrated_deg"].as<double>(), 1.01 * 180.0 / M_PI, 1e-7);  // %.10g
  EXPECT_NEAR(angle["sigma_deg"].as<double>(), 1e-4 * 180.0 / M_PI, 1e-12);
}

// A held-out run whose error rose is flagged by name on the page, counted in the key numbers and
// marked in metrics.json; with none, the page says none.
TEST(ReportTest, HeldOutRunsThatGotWorseAreFlagged) {
  ReportData d = SmallReport();
  EXPECT_NE(ReportHtml(d).find("None: every one of the 3 held-out runs"), std::string::npos);
  d.runs[1].after.cf = 0.2;  // worse than its 0.06
  d.runs[1].after.rms_distance_m = 0.05;
  d.runs[1].before.rms_distance_m = 0.01;
  const std::string html = ReportHtml(d);
  EXPECT_NE(html.find("1 of 3 held-out runs got worse"), std::string::npos);
  EXPECT_NE(html.find("held-out runs that got worse: 1 of 3"), std::string::npos);
  EXPECT_NE(ReportMarkdown(d).find("held-out runs that got worse: 1 of 3 (" + d.runs[1].id + ")"),
            std::string::npos);
  const std::size_t section = html.find("id=\"worse\"");
  ASSERT_NE(section, std::string::npos);
  EXPECT_NE(html.find("<td>" + d.runs[1].id + "</td>", section), std::string::npos);
  EXPECT_NE(html.find(": got worse</h3>"), std::string::npos);  // above its coloured track
  EXPECT_EQ(CheckWellFormed(html), "");
  const YAML::Node j = YAML::Load(MetricsJson(d));
  EXPECT_EQ(j["held_out_runs_worse"].as<int>(), 1);
  EXPECT_TRUE(j["runs"][1]["got_worse"].as<bool>());
  EXPECT_FALSE(j["runs"][0]["got_worse"].as<bool>());
  EXPECT_NEAR(j["runs"][1]["ate_rmse_m"]["after"].as<double>(), 0.05, 1e-12);
}

// Issue 42: "validation: 1 runs"; and a drift that rose inside the runs' scatter went unsaid. The
// count agrees with its noun, and fit's judgement of a rise (the row's note, the lines) is shown
// on the page and in summary.md as given.
TEST(ReportTest, RunCountsAndRisesInsideTheScatterAreSaid) {
  ReportData d = SmallReport();
  EXPECT_NE(ReportMarkdown(d).find("- validation: 3 runs (repetitions"), std::string::npos);
  d.runs.resize(1);
  EXPECT_NE(ReportMarkdown(d).find("- validation: 1 run (repetitions"), std::string::npos);
  EXPECT_NE(ReportHtml(d).find("Validation: 1 run (repetitions"), std::string::npos);
  d.drift[0].after_translation_percent = 2.2;  // rose from 2.0
  d.drift[0].never_worse_note = "worse, within the scatter: margin 0.5";
  d.never_worse_lines = {"'the calibration' is worse than the nominal on the held-out runs (1), "
                         "within the runs' scatter: drift 1 m [%] 2 -> 2.2 (+10.0 %)"};
  const std::string md = ReportMarkdown(d);
  EXPECT_NE(md.find("| 2.20 (worse, within the scatter: margin 0.5) |"), std::string::npos) << md;
  EXPECT_NE(md.find("- **worse:** " + d.never_worse_lines[0] + "\n"), std::string::npos) << md;
  const std::string html = ReportHtml(d);
  EXPECT_NE(html.find("(worse, within the scatter: margin 0.5)</li>"), std::string::npos);
  EXPECT_NE(html.find("<li class=\"worse\">&#39;the calibration&#39; is worse"), std::string::npos)
      << html.substr(html.find("id=\"key\""), 2000);
  EXPECT_EQ(CheckWellFormed(html), "");
}

// Every % change of the page has one sign (after - before): the CF that fell from 0.06 to 0.005
// reads -91.7 % in the summary of the page and of summary.md, and a parameter that grew by 1 %
// reads +1.00 %.
TEST(ReportTest, PercentChangesHaveOneSign) {
  const ReportData d = SmallReport();
  const std::string html = ReportHtml(d);
  EXPECT_NE(html.find("<td class=\"better\">-91.7 %</td>"), std::string::npos);
  EXPECT_EQ(html.find("+91.7 %"), std::string::npos);
  EXPECT_NE(html.find("+1.00 %"), std::string::npos);
  const std::string md = ReportMarkdown(d);
  EXPECT_NE(md.find("| -91.7 % |"), std::string::npos);
  EXPECT_EQ(md.find("+91.7 %"), std::string::npos);
}

// metrics.json is a contract (docs/metrics_json.md): its version, the ATE and the drift.
TEST(ReportTest, MetricsJsonCarriesTheContract) {
  ReportData d = SmallReport();
  d.summary.back().before.rms_distance_m = 0.03;
  d.summary.back().after.rms_distance_m = 0.004;
  d.drift[0].windows_worse = 1;
  const YAML::Node j = YAML::Load(MetricsJson(d));
  EXPECT_EQ(j["version"].as<int>(), kMetricsJsonVersion);
  EXPECT_EQ(j["kind"].as<std::string>(), "report");
  EXPECT_NEAR(j["ate_rmse_m"]["before"].as<double>(), 0.03, 1e-12);
  EXPECT_NEAR(j["ate_rmse_m"]["after"].as<double>(), 0.004, 1e-12);
  EXPECT_NEAR(j["drift"][0]["length_m"].as<double>(), 1.0, 1e-12);
  EXPECT_EQ(j["drift"][0]["windows"].as<int>(), 12);
  EXPECT_EQ(j["drift"][0]["windows_worse"].as<int>(), 1);
  EXPECT_NEAR(j["drift"][0]["rotation_deg_per_m"]["before"].as<double>(), 0.01 * 180 / M_PI, 1e-9);
  EXPECT_EQ(j["verdict"]["level"].as<std::string>(), "WARN");
}

// The diagnose page: well formed, every section and picture there, metrics.json with the same
// held-out CF the page prints (computed the report's way) and the gate's own CF beside it.
TEST(DiagnosePageTest, PageAndMetricsJson) {
  DiagnosePageData d;
  d.level = "PARTIAL";
  d.conclusion = "Effects accepted <but> structure remains.";
  d.dataset = "data";
  d.structure = {{"lack of fit, declared fit", "F = 3 on (9, 40) dof", 1e-5, true, "structure"},
                 {"lack of fit, final model", "F = 1.1 on (9, 40) dof", 0.4, false, "structure"}};
  d.candidates = {{1, "yaw_rate_slip", 0.4, true, true, 0.01, 1e-6, 0.001, -12, true, true, "ok"},
                  {1, "time_offset", 0.01, false, false, 0, 1, 0.001, 0, false, false, "no"}};
  d.gate = {{"nominal", 0.05, false}, {"track fit + effects", 0.011, true}};
  d.selected = "track fit + effects";
  d.held_out = {{"run1", 0.04, 0.01, 0.02, 0.004, {0.01, 0.02}, {0.001, 0.002}},
                {"run2", 0.06, 0.07, 0.03, 0.005, {0.01, 0.02}, {0.001, 0.002}}};
  d.unexplained = {"the residual drifts with run order"};
  ReportParameter held;
  held.name = "L2";
  held.unit = "m";
  held.held = true;
  d.parameters = {held};
  const std::string html = DiagnoseHtml(d);
  EXPECT_EQ(CheckWellFormed(html), "");
  for (const char* id : {"id=\"structure\"", "id=\"effects\"", "id=\"heldout\"",
                         "id=\"unexplained\"", "held at nominal", "&lt;but&gt;",
                         "held-out runs that got worse (CF or ATE rose): 1 of 2"}) {
    EXPECT_NE(html.find(id), std::string::npos) << id;
  }
  std::size_t svgs = 0;
  for (std::size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1))
    ++svgs;
  EXPECT_EQ(svgs, 3u);  // residual, evidence, before/after
  const YAML::Node j = YAML::Load(DiagnoseMetricsJson(d));
  EXPECT_EQ(j["version"].as<int>(), kMetricsJsonVersion);
  EXPECT_EQ(j["kind"].as<std::string>(), "diagnose");
  EXPECT_EQ(j["verdict"]["level"].as<std::string>(), "PARTIAL");
  EXPECT_NEAR(j["cf"]["before"].as<double>(), 0.05, 1e-12);
  EXPECT_NEAR(j["cf"]["after"].as<double>(), 0.04, 1e-12);
  EXPECT_NEAR(j["ate_rmse_m"]["after"].as<double>(), 0.0045, 1e-12);
  EXPECT_NEAR(j["gate_cf"][1]["cf"].as<double>(), 0.011, 1e-12);
  EXPECT_TRUE(j["parameters"][0]["held"].as<bool>());
  EXPECT_TRUE(j["parameters"][0]["sigma"].IsNull());
}

// The family the report's summary rows and the residual statistics group runs by: the flower's
// R/G/B, OptiOdom's path types without their session stamps, ASOC's hold runs together.
TEST(TrajectoryFamilyTest, LeadingLettersOfTheLabel) {
  EXPECT_EQ(TrajectoryFamily("R12"), "R");
  EXPECT_EQ(TrajectoryFamily("G3"), "G");
  EXPECT_EQ(TrajectoryFamily("circular_221220201643"), "circular");
  EXPECT_EQ(TrajectoryFamily("square_2"), "square");
  EXPECT_EQ(TrajectoryFamily("hold_1_cw"), "hold");
  EXPECT_EQ(TrajectoryFamily("CCW"), "CCW");
  EXPECT_EQ(TrajectoryFamily("7b"), "7b");
  EXPECT_EQ(TrajectoryFamily(""), "-");
}

}  // namespace
}  // namespace fitcal::io
