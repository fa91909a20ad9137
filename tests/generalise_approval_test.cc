// `fitcal generalise` pinned: the flower's figures (omni3, through the same generic path as every
// model since the omni3 twin was retired) and the everyday-driving measures on a simulated robot
// with a known common scale error.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/approval_lines.h"
#include "tests/test_files.h"
#include "tests/test_paths.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;
using fitcal::testing::Has;

using fitcal::testing::MissingFromBlock;
using fitcal::testing::Tokens;

// Every expected block is printed, each line with the same words and numbers
// (tests/approval_lines.h: whole numbers exactly, others to one unit in their last printed digit).
// Tolerance: the figures are sums over runs evaluated in parallel and fits that stop on Ceres'
// tolerances (function 1e-6 relative and below); the last bits may differ between builds and thread
// counts, never the fourth decimal of a CF by more than the rounding of the print, which one unit
// in the last printed place covers.
void ExpectBlocks(const std::string& out, const std::vector<std::vector<std::string>>& expected) {
  for (const std::vector<std::string>& block : expected) {
    for (const std::string& line : MissingFromBlock(out, block)) {
      ADD_FAILURE() << "missing from its block (first line: " << block.front() << "): " << line
                    << "\nprinted:\n"
                    << out;
    }
  }
}

// data/flower (360 runs of the 36 flower paths, 10 repetitions), the radial paths R1-R12 against
// the rest, both ways, and repetitions 1-5 against 6-10. Recorded at the retirement of the omni3
// twin; '^R' -> others holds three directions that pure translations do not determine, and the
// held fit transfers worse than the fit without holds (the table shows both).
TEST(GeneraliseApproval, FlowerFigures) {
  TempDir dir;
  const std::string data = std::string(FITCAL_SOURCE_DIR) + "/data/flower";
  const auto r =
      RunFitcal(dir, "generalise --logs " + data + " --train-trajectories '^R' --no-loso");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ExpectBlocks(
      r.out,
      {
          {"| '^R' -> others | nominal | 120 | 240 | 0.0420 | 0.0880 | 0.053 | 3.98 | - | - |",
           "| '^R' -> others | fit | 120 | 240 | 0.0075 | 0.1155 | 0.050 | 5.95 | 3 | 0 |",
           "| '^R' -> others | fit without holds | 120 | 240 | 0.0075 | 0.0176 | 0.010 | 0.81 | - "
           "| "
           "- |",
           "| others -> '^R' | nominal | 240 | 120 | 0.0880 | 0.0420 | 0.039 | 0.80 | - | - |",
           "| others -> '^R' | fit | 240 | 120 | 0.0077 | 0.0076 | 0.005 | 0.27 | 0 | 0 |",
           "| every path type, reps 1-5 -> the other reps | nominal | 180 | 180 | 0.0728 | 0.0726 "
           "| "
           "0.048 | 2.92 | - | - |",
           "| every path type, reps 1-5 -> the other reps | fit | 180 | 180 | 0.0076 | 0.0078 | "
           "0.005 "
           "| 0.28 | 0 | 0 |"},
          {"  others -> '^R': fit               nominal calibrated    change",
           "  ATE RMSE [m] (mean of runs)        0.0269     0.0048    -82.0%",
           "  drift 1 m [%] (342 windows)         3.834      0.535    -86.0%",
           "  drift 1 m [deg/m]                   0.772      0.278    -64.0%"},
      });
}

// The drift row of `name` (e.g. "drift 1 m [%]") in the everyday-driving block titled `title`:
// {nominal, calibrated}.
std::vector<double> EverydayRow(const std::string& out, const std::string& title,
                                const std::string& name) {
  const std::size_t block = out.find("  " + title + " ");
  if (block == std::string::npos) return {};
  const std::size_t row = out.find("  " + name, block);
  if (row == std::string::npos) return {};
  std::string line = out.substr(row, out.find('\n', row) - row);
  line = line.substr(0, line.find("  worse"));  // the never-worse note after the change
  const std::vector<std::string> t = Tokens(line);
  if (t.size() < 3) return {};
  return {std::stod(t[t.size() - 3]), std::stod(t[t.size() - 2])};
}

// A diff drive whose true wheels and track are 2 % larger than the nominal (radii 0.04284 against
// 0.042 m, track 0.204 against 0.2 m): the yaw rate is the nominal's, the distance 2 % longer - a
// common scale, which closed loops judged at their ends cannot see. Trained on the closed squares,
// tested on the circles: the held-out drift per 1 m shows the scale for the nominal, still for the
// final-pose fit, and no more for the track fit.
TEST(GeneraliseApproval, EverydayDrivingShowsACommonScaleError) {
  TempDir dir;
  const std::string truth = dir.Path("truth.yaml"), data = dir.Path("scaled");
  std::ofstream(truth) << "model: diff_drive\nname: example_diff_drive\nwheels:\n"
                          "  - {name: right, radius_m: 0.04284}\n"
                          "  - {name: left, radius_m: 0.04284}\n"
                          "wheel_separation_m: 0.204\nbounds:\n  radius_m: [0.038, 0.046]\n"
                          "  wheel_separation_m: [0.18, 0.22]\n";
  const auto sim = RunFitcal(dir, "simulate --model diff_drive --truth " + truth + " --out " +
                                      data + " --repetitions 2 --seed 7");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const auto r =
      RunFitcal(dir, "generalise --logs " + data + " --train-trajectories '^square' --no-loso");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<double> fit = EverydayRow(r.out, "'^square' -> others: fit", "drift 1 m [%]");
  const std::vector<double> track =
      EverydayRow(r.out, "'^square' -> others: fit (track)", "drift 1 m [%]");
  ASSERT_EQ(fit.size(), 2u) << r.out;
  ASSERT_EQ(track.size(), 2u) << r.out;
  // Nominal: 2 % of each window's displacement. On the circles a 1 m window's chord is shorter
  // than its path (the % is of the path): 1.9 % on the 0.5 and 1 m circles (the chord of 1 m of
  // a 0.5 m circle is 0.96 m). The ground truth's noise (2 mm per axis and 0.2 deg at each end,
  // ~5 mm per window) adds its bias sigma^2 / (2 * 19 mm) ~ 0.07 % to the mean norm; over ~1000
  // windows the mean scatters by < 0.02 %. Hence [1.6, 2.1].
  EXPECT_GT(fit[0], 1.6);
  EXPECT_LT(fit[0], 2.1);
  // The final-pose fit on closed squares leaves the scale where it was (within 0.2 %: the fit's
  // other parameters move the windows by the noise only).
  EXPECT_NEAR(fit[1], fit[0], 0.2);
  // The track fit sees it: what remains is the noise floor of the measure, the mean norm of a
  // ~5 mm error per 1 m window (Rayleigh mean 1.25 sigma ~ 0.5 %); 0.8 % leaves margin for the
  // fit's own scatter and stays far below the 1.9 % of the nominal.
  EXPECT_LT(track[1], 0.8);
}

// The candidate fit's result gate selected, as generalise names it ("ceres ..." -> "fit ..."),
// and its held-out CF, from fit's printout; the nominal's CF beside it.
struct GateChoice {
  std::string name, cf, nominal_cf;
};
GateChoice SelectedByFit(const std::string& fit_out) {
  std::istringstream gate(fit_out.substr(fit_out.find("result gate, CF on held-out runs")));
  GateChoice choice;
  std::string line;
  while (std::getline(gate, line) && !Has(line, "<- selected")) {
    if (Has(line, "  nominal ")) choice.nominal_cf = Tokens(line)[1];
  }
  const std::vector<std::string> words = Tokens(line);  // name words, CF, change, <-, selected
  choice.name = words[0] == "ceres" ? "fit" : words[0];
  for (std::size_t k = 1; k + 4 < words.size(); ++k) choice.name += " " + words[k];
  choice.cf = words[words.size() - 4];
  return choice;
}

// generalise judges a split as `fit --residuals final-pose` judges the same runs
// (calibrate/generalise.h: one Calibrate): `fit --train-trajectories X` trains on X and
// validates on every other run, which is generalise's "'X' -> others" split. The expected line is
// built from fit's own printout (its gate's table, or its refusal on stderr), so it fails when
// generalise's fit, gate, never-worse rule or bound check departs from fit's. '^R': fit writes its
// fit without holds; '^B1': fit refuses (exit 5) because that candidate ends on a bound, although
// it beats the nominal. (On the flower's final poses `--residuals auto` is final-pose.)
TEST(GeneraliseApproval, DecisionOnASplitIsFits) {
  TempDir dir;
  const std::string data = std::string(FITCAL_SOURCE_DIR) + "/data/flower";
  for (const std::string selection : {"^R", "^B1"}) {
    const std::string quoted = "'" + selection + "'";
    const auto fit = RunFitcal(dir, "fit --logs " + data + " --residuals final-pose " +
                                        "--train-trajectories " + quoted + " --no-output");
    std::string expected = quoted + " -> others: ";
    if (fit.exit_code == 0) {
      const GateChoice choice = SelectedByFit(fit.out);
      const std::string runs = fit.out.substr(fit.out.find("held-out runs (") + 15);
      expected += "writes " + choice.name + " (held-out runs (" + runs.substr(0, runs.find(')')) +
                  "): CF " + choice.nominal_cf + " -> " + choice.cf + ")";
    } else {
      ASSERT_EQ(fit.exit_code, 5) << fit.err;
      expected += "refuses (exit 5): " + fit.err.substr(8, fit.err.find('\n') - 8);
    }
    const auto generalise = RunFitcal(
        dir, "generalise --logs " + data + " --train-trajectories " + quoted + " --no-loso");
    ASSERT_EQ(generalise.exit_code, 0) << generalise.err;
    EXPECT_TRUE(Has(generalise.out, "\n  " + expected + "\n"))
        << "expected: " << expected << "\nfit printed:\n" << fit.out << fit.err
        << "\ngeneralise printed:\n" << generalise.out;
  }
}

// Leave-one-session-out's closing line counts fit's decisions on the folds. On the real OptiOdom
// tricycle (circles and squares; each path and direction one session label: four folds), the fold
// holding out label L is `fit --residuals final-pose --train-trajectories <the other labels>`,
// run here four times; the line built from those runs must be generalise's. On dense tracks
// `fit`'s default fits the track, which is not the table's "fit": hence --residuals final-pose.
// Needs ../shared/data/optiodom (skipped without it).
TEST(GeneraliseApproval, FoldDecisionsAreFitsOnTheRealTricycle) {
  const fs::path root = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / "tricyc";
  if (!fs::is_directory(root)) GTEST_SKIP() << "no " << root;
  TempDir dir;
  std::string sessions;
  for (const char* path : {"circular", "square"}) {
    for (const auto& entry : fs::directory_iterator(root / path)) {
      sessions += " " + entry.path().string();
    }
  }
  const std::string data = dir.Path("tricyc");
  ASSERT_EQ(RunFitcal(dir, "import optiodom" + sessions + " --out " + data).exit_code, 0);
  const auto generalise = RunFitcal(dir, "generalise --logs " + data);
  ASSERT_EQ(generalise.exit_code, 0) << generalise.err;
  std::map<std::string, int> count;
  const std::vector<std::string> labels = {"circular_ccw", "circular_cw", "square_ccw",
                                           "square_cw"};
  for (const std::string& label : labels) {
    EXPECT_TRUE(Has(generalise.out, "\n| " + label + " | ")) << generalise.out;
    std::string others;
    for (const std::string& other : labels) {
      if (other != label) others += (others.empty() ? "" : ",") + other;
    }
    const auto fit = RunFitcal(dir, "fit --logs " + data + " --residuals final-pose " +
                                        "--train-trajectories " + others + " --no-output");
    ++count[fit.exit_code == 0 ? "writes " + SelectedByFit(fit.out).name
                               : "refuses (exit " + std::to_string(fit.exit_code) + ")"];
  }
  std::string expected = "fit --residuals final-pose on the 4 folds:";
  for (const auto& [decision, n] : count) {
    expected += " " + decision + " " + std::to_string(n) + ",";
  }
  expected.pop_back();
  EXPECT_TRUE(Has(generalise.out, "\n" + expected + "\n"))
      << "expected: " << expected << "\ngeneralise printed:\n" << generalise.out;
}

}  // namespace
}  // namespace fitcal
