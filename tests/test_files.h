#pragma once
// A temporary directory per test, removed afterwards, helpers to read and write whole files, and
// the fitcal binary run as a user runs it.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_paths.h"

namespace fitcal::testing {

// The whole file as bytes ("" when it cannot be read).
inline std::string ReadFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Replaces the file's contents with `bytes`.
inline void WriteFileBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// How many lines `text` holds (its newlines): a refusal is one line.
inline int Lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

inline bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The first `count` comma-separated numbers of a CSV row (std::invalid_argument when it has fewer).
inline std::vector<double> CsvNumbers(const std::string& row, std::size_t count) {
  std::vector<double> numbers(count);
  std::istringstream fields(row);
  std::string field;
  for (double& x : numbers) {
    std::getline(fields, field, ',');
    x = std::stod(field);
  }
  return numbers;
}

// Every path below `root`, files and directories: what a refused command must not add to.
inline std::set<std::string> ListFiles(const std::filesystem::path& root) {
  std::set<std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(root)) {
    out.insert(e.path().string());
  }
  return out;
}

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("fitcal_" + std::string(info ? info->name() : "test") + "_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string Path(const std::string& name) const { return (path_ / name).string(); }
  std::string Write(const std::string& name, const std::string& text) const {
    const auto p = path_ / name;
    std::filesystem::create_directories(p.parent_path());
    WriteFileBytes(p, text);
    return p.string();
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The fitcal binary run as a user runs it: its exit code and what it printed.
struct FitcalRun {
  int exit_code = -1;
  std::string out, err;
};

inline FitcalRun RunFitcal(const TempDir& dir, const std::string& args) {
  static const std::string fitcal = std::string(FITCAL_BINARY_DIR) + "/tools/fitcal";
  const std::string out = dir.Path("stdout.txt"), err = dir.Path("stderr.txt");
  const int status = std::system((fitcal + " " + args + " >" + out + " 2>" + err).c_str());
  FitcalRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadFileBytes(out);
  r.err = ReadFileBytes(err);
  return r;
}

// The same for a command that must leave `scratch` as it was: stdout discarded, stderr captured
// beside `scratch` (not in it) and removed, under a 60 s timeout (a refusal must never block).
inline FitcalRun RunFitcalOutside(const std::filesystem::path& scratch, const std::string& args) {
  static const std::string fitcal = std::string(FITCAL_BINARY_DIR) + "/tools/fitcal";
  const std::filesystem::path err =
      scratch.parent_path() / (scratch.filename().string() + ".stderr");
  const int status = std::system(
      ("timeout 60 " + fitcal + " " + args + " > /dev/null 2> '" + err.string() + "'").c_str());
  FitcalRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = ReadFileBytes(err);
  std::filesystem::remove(err);
  return r;
}

}  // namespace fitcal::testing
