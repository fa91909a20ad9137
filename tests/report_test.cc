// The report files (io/report_writer.h, io/svg_plot.h): index.html is well formed, embeds every
// figure, and references nothing outside itself; the CSV and JSON carry the numbers.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "io/report_writer.h"
#include "io/svg_plot.h"
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
  d.drift = {{1.0, 12, 2.0, 0.2, 0.01, 0.001}};
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
  // One <svg> per figure: 6 single figures and two (distance, heading) per run drawn (all three
  // here: fewer than worst_runs_drawn).
  std::size_t svgs = 0;
  for (std::size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1))
    ++svgs;
  EXPECT_EQ(svgs, 6 + 2 * d.runs.size());
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
