// The pages of `report` and `diagnose` rendered by headless Chromium at a phone's width (390 px)
// and a desktop's (1400 px): body text at least 12 CSS px, nothing but figures and tables wider
// than the screen (they scroll in their own box), every SVG laid out and its text at least 10 px
// as drawn. Skipped when no chromium is
// installed (apt-get install chromium). A probe script is added to a copy of the page (the pages
// themselves carry none); it writes what it measured into the DOM that --dump-dom prints. One
// Chromium renders every page of a test at both widths, each in a frame of its own.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "pages/diagnose_page.h"
#include "pages/report_csv.h"
#include "pages/report_figures.h"
#include "pages/report_html.h"
#include "pages/report_json.h"
#include "pages/report_markdown.h"
#include "pages/report_model.h"
#include "pages/report_tum.h"
#include "tests/test_files.h"

namespace fitcal::io {
namespace {

using fitcal::testing::ReadFileBytes;
using fitcal::testing::TempDir;

std::string Chromium() {
  for (const char* c : {"/usr/bin/chromium", "/usr/bin/chromium-browser"}) {
    if (std::filesystem::exists(c)) return c;
  }
  return "";
}

// Smallest font of visible body text, the page's scroll width against the window, the number of
// SVGs with a zero-size box, and the smallest SVG text as drawn (its font size times the figure's
// scale on the screen).
const char* const kProbe = R"(<script>
window.addEventListener('load', function () {
  var min = 1e9, zero = 0;
  document.querySelectorAll('p, li, td, th, figcaption, summary, code').forEach(function (e) {
    if (e.offsetParent === null || !e.textContent.trim()) return;
    min = Math.min(min, parseFloat(getComputedStyle(e).fontSize));
  });
  var svg_min = 1e9;
  document.querySelectorAll('svg').forEach(function (s) {
    var r = s.getBoundingClientRect();
    if (s.closest('details') && !s.closest('details').open) return;  // not shown
    if (r.width < 1 || r.height < 1) { zero++; return; }
    var scale = r.width / s.viewBox.baseVal.width;  // a figure shrunk to the screen shrinks its text
    s.querySelectorAll('text').forEach(function (t) {
      svg_min = Math.min(svg_min, parseFloat(t.getAttribute('font-size')) * scale);
    });
  });
  // Cells that carry a verdict (class v: a run's "after", a test's result, an effect's decision)
  // must be on the screen without scrolling: a cell beyond the right edge is cut.
  var verdicts = 0, cut = 0;
  document.querySelectorAll('td.v').forEach(function (c) {
    verdicts++;
    var r = c.getBoundingClientRect();
    if (r.width < 1 || r.right > window.innerWidth + 0.5) cut++;
  });
  var out = document.createElement('pre');
  out.id = 'probe';
  out.textContent = 'PROBE frame=' + window.frameElement.id + ' min_font=' + min + ' scroll_width=' +
      document.documentElement.scrollWidth + ' window=' + window.innerWidth + ' zero_svgs=' + zero +
      ' svg_font=' + svg_min + ' verdict_cells=' + verdicts + ' cut=' + cut;
  window.parent.document.body.appendChild(out);  // the host page's DOM is the one printed
});
</script>)";

// Each frame's height: the pages scroll inside it.
constexpr int kFrameHeight = 2000;

struct Probe {
  double min_font = 0, scroll_width = 0, window = 0, zero_svgs = -1, svg_font = 0;
  double verdict_cells = 0, cut = -1;
};

// One page at one width: what the probe measures, rendered in its own iframe.
struct Frame {
  std::string what;  // names the page in a failure
  std::string html;
  int width = 0;
};

std::string EscapedForAttribute(const std::string& page) {
  std::string escaped;
  for (char c : page) {
    if (c == '&') {
      escaped += "&amp;";
    } else if (c == '"') {
      escaped += "&quot;";
    } else {
      escaped += c;
    }
  }
  return escaped;
}

// Headless Chromium lays a window out at least 500 px wide whatever --window-size says, so each
// page is rendered in an iframe of exactly its width in px (srcdoc: same origin as its host,
// whose DOM --dump-dom prints). The frames stand one below the other in a window tall enough to
// show them all, so that every page is laid out on the screen as if it were the only one; the
// host's load event waits for every frame's, so every probe has written before the dump.
std::string HostPage(const std::vector<Frame>& frames) {
  std::string host = "<!DOCTYPE html><html><body style=\"margin:0\">";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    std::string page = frames[i].html;
    page.insert(page.rfind("</body>"), kProbe);
    host += "<iframe id=\"f" + std::to_string(i) + "\" style=\"border:0;display:block;width:" +
            std::to_string(frames[i].width) + "px;height:" + std::to_string(kFrameHeight) +
            "px\" srcdoc=\"" + EscapedForAttribute(page) + "\"></iframe>";
  }
  return host + "</body></html>";
}

// Every frame rendered by one Chromium (a launch costs ~2 s of CPU; docs/tests.md), each frame's
// probe read by its iframe's id. A frame that printed no probe keeps window = 0.
std::vector<Probe> Render(const TempDir& dir, const std::vector<Frame>& frames) {
  int widest = 0;
  for (const Frame& f : frames) widest = std::max(widest, f.width);
  const std::string path = dir.Write("page.html", HostPage(frames));
  const std::string out = dir.Path("dom.txt");
  const std::string cmd =
      Chromium() +
      " --headless --no-sandbox --disable-gpu --disable-background-networking"
      " --disable-component-update --disable-sync --no-first-run"
      " --user-data-dir=" +
      dir.Path("profile") + " --window-size=" + std::to_string(widest + 40) + "," +
      std::to_string(kFrameHeight * static_cast<int>(frames.size()) + 100) +
      " --virtual-time-budget=5000 --dump-dom"
      " file://" +
      path + " > " + out + " 2>/dev/null";
  std::vector<Probe> probes(frames.size());
  if (std::system(cmd.c_str()) != 0) return probes;
  const std::string dom = ReadFileBytes(out);
  const std::regex probe_line(
      "PROBE frame=f([0-9]+) min_font=([0-9.e+]+) scroll_width=([0-9.]+) "
      "window=([0-9.]+) zero_svgs=([0-9]+) svg_font=([0-9.e+]+) "
      "verdict_cells=([0-9]+) cut=([0-9]+)");
  for (std::sregex_iterator m(dom.begin(), dom.end(), probe_line), end; m != end; ++m) {
    const std::size_t i = std::stoul((*m)[1]);
    if (i >= probes.size()) continue;
    probes[i] = {std::stod((*m)[2]), std::stod((*m)[3]), std::stod((*m)[4]),
                 std::stod((*m)[5]), std::stod((*m)[6]), std::stod((*m)[7]),
                 std::stod((*m)[8])};
  }
  return probes;
}

ReportData SmallReport() {
  ReportData d;
  d.tool_version = "test";
  d.dataset = "data/some/long/path/of/a/data/set/that/must/wrap/on/a/phone";
  d.calibration = "calibrated.yaml";
  // A path in prose, one long word (the real report's "trained on data set /tmp/...", which
  // pushed a phone's page to 628 px).
  d.calibration_note = "method ceres, trained on data set "
                       "/tmp/fitcal_RealDiffDriveReportReadableOnPhoneAndDesktop_1234567890/D";
  d.robot_name = "robot";
  d.sampling = "nearest";
  d.verdict = "PASS";
  for (int k = 0; k < 12; ++k) {
    ReportRun r;
    r.trajectory = "circular_2306202021" + std::to_string(10 + k);
    r.id = r.trajectory + "-run01";
    for (int i = 0; i <= 40; ++i) {
      const double t = 0.25 * i, a = 0.2 * t;
      r.t_s.push_back(t);
      r.along_m.push_back(0.2 * t);
      r.ground_truth_xy.push_back({std::sin(a), 1 - std::cos(a)});
      r.before_xy.push_back({1.02 * std::sin(a), 1 - std::cos(a)});
      r.after_xy.push_back({1.002 * std::sin(a), 1 - std::cos(a)});
      r.before_distance_m.push_back(0.02 * t);
      r.after_distance_m.push_back(0.002 * t);
      r.before_angle_rad.push_back(0.01 * t);
      r.after_angle_rad.push_back(0.001 * t);
    }
    r.before.cf = 0.05;
    r.after.cf = 0.01;
    d.runs.push_back(r);
  }
  // Two runs that got worse, with the long ids of real sessions: the "after" columns that explain
  // the flag are the ones a phone cut (issue 42).
  for (int k : {3, 7}) {
    d.runs[k].id = "square_231220200029_calibration_session-run" + std::to_string(k);
    d.runs[k].after.cf = 0.06;
    d.runs[k].after.rms_distance_m = 0.4;
  }
  // One run whose error runs far above the others (the nominal's 277 mm peak of the issue): beyond
  // the figure's 95 % scale, it must be marked, not clipped unsaid.
  for (std::size_t i = 0; i < d.runs[0].before_distance_m.size(); ++i) {
    d.runs[0].before_distance_m[i] = 0.0277 * static_cast<double>(i);  // peak 1108 mm
  }
  ReportSummaryRow all{"all validation runs", 12, {}, {}};
  all.before.cf = 0.05;
  all.after.cf = 0.01;
  d.summary = {all};
  d.trajectories = {all};
  d.drift = {{1.0, 12, 2.0, 0.2, 0.01, 0.001, {1, 2, 3}, {0.1, 0.2, 0.3}, {0.01}, {0.001}, 0}};
  return d;
}

// Every page at a phone's width and a desktop's, all in one Chromium.
void ExpectReadable(const TempDir& dir, const std::vector<std::pair<std::string, std::string>>&
                                            pages) {  // (what, html)
  std::vector<Frame> frames;
  for (const auto& [what, html] : pages) {
    for (int width : {390, 1400}) frames.push_back({what, html, width});
  }
  const std::vector<Probe> probes = Render(dir, frames);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Probe& p = probes[i];
    const int width = frames[i].width;
    SCOPED_TRACE(frames[i].what + " at " + std::to_string(width) + " px");
    EXPECT_GT(p.window, 0) << "chromium printed no probe";
    if (p.window <= 0) continue;
    EXPECT_GE(p.min_font, 12.0);
    EXPECT_EQ(p.window, width);
    EXPECT_LE(p.scroll_width, p.window);  // the page never scrolls sideways as a whole
    EXPECT_EQ(p.zero_svgs, 0);
    // Figure text as drawn on the screen: the tick labels (11 px) never shrink with their figure
    // (the defect: 1100 px charts scaled to a phone's 358 px printed 4-6 px text).
    EXPECT_GE(p.svg_font, 10.0);
    // Every cell that carries a verdict is on the screen, none cut at the right edge.
    EXPECT_GT(p.verdict_cells, 0);
    EXPECT_EQ(p.cut, 0);
  }
}

// The error-against-distance figure's scale holds 95 % of the samples; a run beyond its top is
// marked there and named in the legend with its peak, never clipped unsaid (issue 42: the
// nominal's 277 mm peak drawn at ~229 mm).
TEST(PageRender, AnExtremeBeyondTheScaleIsMarked) {
  const std::string html = ReportHtml(SmallReport());
  // The peak: 0.0277 m x 40 samples = 1108 mm.
  EXPECT_NE(html.find("beyond the top: 1 run(s), peak 1108 mm"), std::string::npos);
  // Without the extreme the scale is the other runs', and the marker says their own peak.
  ReportData calm = SmallReport();
  calm.runs[0].before_distance_m = calm.runs[1].before_distance_m;
  EXPECT_EQ(ReportHtml(calm).find("peak 1108 mm"), std::string::npos);
}

TEST(PageRender, ReportAndDiagnoseReadableOnPhoneAndDesktop) {
  if (Chromium().empty()) GTEST_SKIP() << "no chromium";
  TempDir dir;
  DiagnosePageData d;
  d.level = "EFFECTS_NAMED";
  d.conclusion = "One effect.";
  d.dataset = "data";
  d.structure = {{"lack of fit, declared fit", "F = 3 on (9, 40) dof", 1e-5, true, "structure"}};
  d.candidates = {{1, "yaw_rate_slip", 0.4, true, true, 0.01, 1e-6, 0.001, -12, true, true,
                   "significant (p 1e-06 < 0.001) but explains only 12 % of the lack of fit"}};
  d.gate = {{"nominal", 0.05, false}, {"track fit + effects", 0.01, true}};
  d.held_out = {{"run1", 0.05, 0.01, 0.02, 0.004, {0.01, 0.02}, {0.001, 0.002}}};
  d.text_report = std::string(300, 'x');
  ExpectReadable(dir, {{"report", ReportHtml(SmallReport())}, {"diagnose", DiagnoseHtml(d)}});
}

// The report of the worked example on the real differential drive (README: 20 held-out runs, 4
// worse, 1.1 MB), as a newcomer opens it: readable at both widths, the worse runs' "after" cells
// on the screen, and the nominal's extremes beyond the error figure's top marked. Skipped without
// chromium or ../shared.
TEST(PageRender, RealDiffDriveReportReadableOnPhoneAndDesktop) {
  const std::string diff = FITCAL_SHARED_DIR + "/data/optiodom/diff";
  if (Chromium().empty() || !std::filesystem::is_directory(diff)) {
    GTEST_SKIP() << "no chromium or no " << diff;
  }
  TempDir dir;
  const std::string data = dir.Path("D"), cal = dir.Path("cal.yaml"), rep = dir.Path("rep");
  using fitcal::testing::RunFitcal;
  ASSERT_EQ(
      RunFitcal(dir, "import optiodom " + diff + "/circular/* " + diff + "/square/* --out " + data)
          .exit_code,
      0);
  ASSERT_EQ(RunFitcal(dir, "fit --logs " + data + " --out " + cal).exit_code, 0);
  ASSERT_EQ(
      RunFitcal(dir, "report --logs " + data + " --calibration " + cal + " --out " + rep).exit_code,
      0);
  const std::string html = ReadFileBytes(rep + "/index.html");
  EXPECT_NE(html.find("beyond the top: "), std::string::npos);
  ExpectReadable(dir, {{"real report", html}});
}

}  // namespace
}  // namespace fitcal::io
