// Approval of `fitcal report` on data/flower (issue 30 item 1): the report's outputs are pinned
// two ways, so that a refactoring that moves a byte is caught and a change that moves a number is
// explained.
//  1. Independently: the summary row of all validation runs, the evo statistics and the bias are
//     recomputed here from the per-run numbers of metrics.csv (printed to 10 significant digits)
//     and compared with metrics.json (relative 1e-8: two roundings of %.10g) and with the text of
//     summary.md (as it prints them, %.4f / %.3f).
//  2. Byte for byte: a 64-bit FNV-1a hash of each output (index.html, summary.md, metrics.csv,
//     metrics.json), with the tool version and the temporary paths replaced by placeholders,
//     against tests/approvals/report_flower.txt. After a change that moves an output on purpose,
//     regenerate it with
//       FITCAL_UPDATE_APPROVALS=1 build/tests/report_approval_test
//     and say in the commit why the output moved. The hashes hold for one platform's arithmetic
//     (x86-64, SSE2, the Release build); the test therefore runs without the sanitizers.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_files.h"

namespace fitcal {
namespace {

using fitcal::testing::ReadFileBytes;
using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;

const char* const kOutputs[] = {"index.html", "summary.md", "metrics.csv", "metrics.json"};

std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string Fnv1a64(const std::string& bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char out[17];
  std::snprintf(out, sizeof out, "%016" PRIx64, h);
  return out;
}

// metrics.csv as columns by header name, one value per run.
std::map<std::string, std::vector<double>> ReadCsvColumns(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::istringstream h(line); std::getline(h, line, ',');) names.push_back(line);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string cell;
    for (std::size_t k = 0; std::getline(row, cell, ','); ++k) {
      if (k >= 3) columns[names[k]].push_back(std::strtod(cell.c_str(), nullptr));
    }
  }
  return columns;
}

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

// `scale`: the size of the values averaged (a mean near zero of larger values carries their
// rounding, 5e-11 of each).
void ExpectRelativelyNear(double mine, double theirs, const std::string& what, double scale = 0.0) {
  EXPECT_NEAR(mine, theirs, 1e-8 * std::max({std::abs(theirs), scale, 1e-12})) << what;
}

double LargestMagnitude(const std::vector<double>& v) {
  double out = 0.0;
  for (double x : v) out = std::max(out, std::abs(x));
  return out;
}

std::string Printed(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

class ReportApproval : public ::testing::Test {
 protected:
  // A calibration: the flower's robot with wheel a's distance at the simulated truth (Table 5);
  // the report on repetitions 6-10 of data/flower.
  void SetUp() override {
    data_ = std::string(FITCAL_SOURCE_DIR) + "/data/flower";
    std::string robot = ReadFileBytes(data_ + "/robot.yaml");
    const std::string from = "{name: a, distance_m: 0.195";
    ASSERT_NE(robot.find(from), std::string::npos);
    robot.replace(robot.find(from), from.size(), "{name: a, distance_m: 0.2186");
    calibration_ = dir_.Write("cal.yaml", robot);
    out_ = dir_.Path("rep");
    const auto r = RunFitcal(dir_, "report --logs " + data_ + " --calibration " + calibration_ +
                                       " --train-reps 1-5 --out " + out_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    json_ = YAML::LoadFile(out_ + "/metrics.json");
  }

  // An output with what changes from run to run (temporary paths, the tool's version) replaced.
  std::string Normalised(const std::string& name) const {
    std::string text = ReadFileBytes(out_ + "/" + name);
    text = ReplaceAll(text, calibration_, "<calibration>");
    text = ReplaceAll(text, data_, "<data>");
    return ReplaceAll(text, json_["tool_version"].as<std::string>(), "<version>");
  }

  TempDir dir_;
  std::string data_, calibration_, out_;
  YAML::Node json_;
};

TEST_F(ReportApproval, SummaryStatisticsAndBiasRecomputedFromThePerRunNumbers) {
  const auto csv = ReadCsvColumns(ReadFileBytes(out_ + "/metrics.csv"));
  const std::size_t runs = json_["runs"].size();
  ASSERT_EQ(runs, 180u);  // 36 trajectories x repetitions 6-10
  ASSERT_EQ(csv.at("after_cf").size(), runs);
  const YAML::Node& all = json_["summary"][json_["summary"].size() - 1];
  ASSERT_EQ(all["group"].as<std::string>(), "all validation runs");
  const std::string md = ReadFileBytes(out_ + "/summary.md");
  for (const char* key : {"rms_distance_m", "rms_angle_deg", "max_distance_m", "max_angle_deg",
                          "final_distance_m", "final_angle_deg", "cf"}) {
    for (const char* when : {"before", "after"}) {
      const double mean = Mean(csv.at(std::string(when) + "_" + key));
      ExpectRelativelyNear(mean, all[when][key].as<double>(), std::string(when) + " " + key);
    }
  }
  // summary.md prints the all-runs CF as the markdown table's last column.
  const double cf_before = Mean(csv.at("before_cf")), cf_after = Mean(csv.at("after_cf"));
  EXPECT_NE(md.find("| all validation runs | 180 | before |"), std::string::npos);
  EXPECT_NE(md.find(" " + Printed("%.4f", cf_before) + " |\n|  |  | after |"), std::string::npos);
  EXPECT_NE(md.find(" " + Printed("%.4f", cf_after) + " |\n|  |  | change |"), std::string::npos);
  EXPECT_LT(cf_after, cf_before);  // the calibration moved something
  // evo statistics of the CF: mean, min, max and the RMSE over runs.
  for (const char* when : {"before", "after"}) {
    std::vector<double> cf = csv.at(std::string(when) + "_cf");
    double squares = 0.0;
    for (double x : cf) squares += x * x;
    const YAML::Node& s = json_["statistics"]["cf"][when];
    ExpectRelativelyNear(Mean(cf), s["mean"].as<double>(), "cf mean");
    ExpectRelativelyNear(std::sqrt(squares / cf.size()), s["rmse"].as<double>(), "cf rmse");
    ExpectRelativelyNear(*std::min_element(cf.begin(), cf.end()), s["min"].as<double>(), "min");
    ExpectRelativelyNear(*std::max_element(cf.begin(), cf.end()), s["max"].as<double>(), "max");
  }
  // The bias: the mean signed final error in the start frame.
  for (const char* when : {"before", "after"}) {
    const YAML::Node& b = json_["bias"][when];
    for (const char* axis : {"x_m", "y_m"}) {
      const std::vector<double>& e = csv.at(std::string(when) + "_final_" + axis);
      ExpectRelativelyNear(Mean(e), b[axis].as<double>(), std::string("bias ") + axis,
                           LargestMagnitude(e));
    }
  }
}

TEST_F(ReportApproval, OutputsMatchTheApprovedHashes) {
  const std::string approved =
      std::string(FITCAL_SOURCE_DIR) + "/tests/approvals/report_flower.txt";
  std::string hashes;
  for (const char* name : kOutputs)
    hashes += std::string(name) + " " + Fnv1a64(Normalised(name)) + "\n";
  if (std::getenv("FITCAL_UPDATE_APPROVALS") != nullptr) {
    std::ofstream(approved, std::ios::binary) << hashes;
    GTEST_SKIP() << "wrote " << approved;
  }
  EXPECT_EQ(hashes, ReadFileBytes(approved))
      << "an output of `fitcal report` on data/flower changed; if on purpose, regenerate "
         "tests/approvals/report_flower.txt (see the head of this file) and say why in the commit";
}

}  // namespace
}  // namespace fitcal
