#pragma once
// A temporary directory per test, removed afterwards, and helpers to read and write whole files.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

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

#ifdef FITCAL_BINARY_DIR
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
#endif

}  // namespace fitcal::testing
