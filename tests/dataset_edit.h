#pragma once
// Small data sets made and edited through the command line for CLI tests: a simulated
// differential drive, its runs' files from dataset.yaml, and CSVs read and written whole (shared
// by corpus_classes_test and cli_flags_test).

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <sstream>
#include <string>
#include <vector>

#include "tests/test_files.h"

namespace fitcal::testing {

// An argument for the shell, whatever it holds.
inline std::string Shell(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// A simulated differential drive (closed squares and circles, 10 Hz ground truth, 4 m loops):
// the data set's directory.
inline std::string SimulateDiffDrive(const TempDir& dir, const std::string& name,
                                     int repetitions = 2) {
  const std::string out = dir.Path(name);
  const FitcalRun r = RunFitcal(dir, "simulate --model diff_drive --repetitions " +
                                         std::to_string(repetitions) + " --seed 3 --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return out;
}

// The CSV's header and rows.
struct Csv {
  std::string header;
  std::vector<std::vector<double>> rows;
};

inline Csv ReadCsv(const std::string& path) {
  std::istringstream in(ReadFileBytes(path));
  Csv csv;
  std::getline(in, csv.header);
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) row.push_back(std::stod(f));
    csv.rows.push_back(row);
  }
  return csv;
}

inline void WriteCsv(const std::string& path, const Csv& csv) {
  std::ostringstream out;
  out.precision(17);
  out << csv.header << "\n";
  for (const std::vector<double>& row : csv.rows) {
    for (std::size_t k = 0; k < row.size(); ++k) out << (k ? "," : "") << row[k];
    out << "\n";
  }
  WriteFileBytes(path, out.str());
}

// Each run's files, from dataset.yaml: id, repetition, encoders, ground truth (absolute paths).
struct RunFiles {
  std::string id;
  int repetition;
  std::string encoders, ground_truth;
};

inline std::vector<RunFiles> Runs(const std::string& data) {
  std::vector<RunFiles> out;
  for (const YAML::Node& r : YAML::LoadFile(data + "/dataset.yaml")["runs"]) {
    out.push_back({r["id"].as<std::string>(), r["repetition"].as<int>(),
                   data + "/" + r["encoders"].as<std::string>(),
                   data + "/" + r["ground_truth"].as<std::string>()});
  }
  return out;
}

}  // namespace fitcal::testing
