#pragma once
// What the benchmarks share: sizes from the environment, where the shared data are (also for the
// tests that read them) and a scratch directory for the inputs they write once.

#include <sys/resource.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/test_paths.h"

namespace fitcal::bench {

// CPU seconds (user + system) of the children this process has waited for: the fitcal processes a
// benchmark ran, whatever else the machine was doing.
inline double ChildrenCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// The environment variable `name` as a number, `fallback` when it is not set.
inline long EnvOr(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::atol(v) : fallback;
}

// The environment variable `name` (megabytes, `fallback_mb` when not set) in bytes.
inline std::uint64_t EnvBytes(const char* name, long fallback_mb) {
  return static_cast<std::uint64_t>(EnvOr(name, fallback_mb)) << 20;
}

// A fresh directory under the system's temporary directory, removed with everything in it.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix = "fitcal-bench") {
    std::string tmpl = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (mkdtemp(tmpl.data()) == nullptr) std::abort();
    path_ = tmpl;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace fitcal::bench
