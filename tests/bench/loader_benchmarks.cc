// Loader throughput on big inputs:
//   BM_ReadEncoderCsv   a large encoder log (FITCAL_BENCH_ENCODER_MB, default 200 MB; 1024 for
//                       the 1 GB) written once to a temporary directory; MB/s of file
//                       text and the bytes the loaded EncoderLog holds per sample (target ~40:
//                       t_s 8 B + a 32-byte sample row).
//   BM_LoadDataset      a data set of FITCAL_BENCH_RUNS runs (default 10,000; 100 encoder rows
//                       and 5 ground-truth rows each): dataset.yaml + every file, all threads.
// The page cache is warm after the first iteration: these measure parsing, not the disk.
//   build/tests/loader_benchmarks --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "io/dataset.h"
#include "io/log_files.h"
#include "io/text_file.h"
#include "tests/bench/bench_support.h"
#include "tests/three_wheel_files.h"

namespace {

namespace fs = std::filesystem;

using fitcal::bench::EnvOr;
using fitcal::bench::ScratchDir;

// Rows as the simulator writes them (io::EncoderCsv): 100 Hz, rates with 9 significant digits,
// random from `seed` (the loader refuses two runs with the same log as a duplicated run).
void WriteEncoderCsv(const fs::path& path, std::size_t target_bytes, std::size_t max_rows,
                     std::uint64_t seed = 1) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  std::fputs("t,w_a,w_b,w_c\n", f);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> rate(-12.0, 12.0);
  std::size_t bytes = 14;
  for (std::size_t k = 0; bytes < target_bytes && k < max_rows; ++k) {
    const int n = std::fprintf(f, "%.6f,%.9g,%.9g,%.9g\n", 0.01 * static_cast<double>(k), rate(rng),
                               rate(rng), rate(rng));
    bytes += static_cast<std::size_t>(n);
  }
  std::fclose(f);
}

// The large encoder log, written at the first call.
const fs::path& BigEncoderCsv() {
  static const ScratchDir dir;
  static const fs::path path = [] {
    const fs::path p = dir.path() / "big_encoders.csv";
    WriteEncoderCsv(p, fitcal::bench::EnvBytes("FITCAL_BENCH_ENCODER_MB", 200),
                    static_cast<std::size_t>(-1));
    return p;
  }();
  return path;
}

void BM_ReadEncoderCsv(benchmark::State& state) {
  const fs::path& path = BigEncoderCsv();
  const std::size_t file_bytes = fs::file_size(path);
  double bytes_per_sample = 0.0;
  std::size_t samples = 0;
  for (auto _ : state) {
    const fitcal::EncoderLog log = fitcal::io::ReadEncoderCsv(path.string());
    samples = log.samples.size();
    bytes_per_sample =
        static_cast<double>(log.t_s.capacity() * sizeof(double) +
                            log.samples.capacity_rows() *
                                static_cast<std::size_t>(log.samples.stride()) * sizeof(double)) /
        static_cast<double>(samples);
    benchmark::DoNotOptimize(log.samples.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * file_bytes));
  state.counters["file_MB"] = static_cast<double>(file_bytes) / (1 << 20);
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["bytes_per_sample"] = bytes_per_sample;
}
BENCHMARK(BM_ReadEncoderCsv)->Unit(benchmark::kMillisecond)->UseRealTime();

// The share of BM_ReadEncoderCsv that is reading the file into memory (no parsing).
void BM_ReadTextFileOnly(benchmark::State& state) {
  const fs::path& path = BigEncoderCsv();
  for (auto _ : state) {
    const std::string text = fitcal::io::ReadTextFile(path.string());
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * fs::file_size(path)));
}
BENCHMARK(BM_ReadTextFileOnly)->Unit(benchmark::kMillisecond)->UseRealTime();

// Run i of a data set, its files in runs/.
fitcal::io::DatasetEntry Entry(long i, const std::string& trajectory, int repetition) {
  fitcal::io::DatasetEntry e;
  e.id = "run" + std::to_string(i);
  e.trajectory = trajectory;
  e.repetition = repetition;
  e.encoders = "runs/" + e.id + "_enc.csv";
  e.ground_truth = "runs/" + e.id + "_gt.csv";
  return e;
}

// dataset.yaml of `entries` in `dir` and its robot (Palacin's apr02).
void WriteIndex(const fs::path& dir, const std::vector<fitcal::io::DatasetEntry>& entries) {
  fs::copy_file(fs::path(FITCAL_SOURCE_DIR) / "data" / "robots" / "apr02.yaml", dir / "robot.yaml");
  std::FILE* f = std::fopen((dir / "dataset.yaml").c_str(), "wb");
  std::fputs(fitcal::io::DatasetYaml("robot.yaml", entries).c_str(), f);
  std::fclose(f);
}

void BM_LoadDataset(benchmark::State& state) {
  static ScratchDir dir;
  const long runs = EnvOr("FITCAL_BENCH_RUNS", 10000);
  if (!fs::exists(dir.path() / "dataset.yaml")) {
    fs::create_directories(dir.path() / "runs");
    std::vector<fitcal::io::DatasetEntry> entries;
    for (long i = 0; i < runs; ++i) {
      const fitcal::io::DatasetEntry e =
          Entry(i, "T" + std::to_string(i % 36), static_cast<int>(i / 36) + 1);
      WriteEncoderCsv(dir.path() / e.encoders, static_cast<std::size_t>(-1), 100,
                      static_cast<std::uint64_t>(i) + 1);
      std::FILE* f = std::fopen((dir.path() / e.ground_truth).c_str(), "wb");
      std::fputs("t,x,y,theta\n", f);
      for (int k = 0; k < 5; ++k) {
        std::fprintf(f, "%.3f,%.4f,%.4f,0\n", 0.25 * k, 0.01 * k, 1e-4 * static_cast<double>(i));
      }
      std::fclose(f);
      entries.push_back(e);
    }
    WriteIndex(dir.path(), entries);
  }
  for (auto _ : state) {
    const fitcal::io::Dataset dataset = fitcal::io::LoadDataset(dir.path().string());
    benchmark::DoNotOptimize(dataset.runs.data());
  }
  state.counters["runs"] = static_cast<double>(runs);
}
BENCHMARK(BM_LoadDataset)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ReadDatasetIndex(benchmark::State& state) {
  // Only dataset.yaml of the data set above (yaml-cpp parse + path checks).
  static ScratchDir dir;
  const long runs = EnvOr("FITCAL_BENCH_RUNS", 10000);
  if (!fs::exists(dir.path() / "dataset.yaml")) {
    std::vector<fitcal::io::DatasetEntry> entries;
    for (long i = 0; i < runs; ++i) entries.push_back(Entry(i, "T", 1));
    WriteIndex(dir.path(), entries);
  }
  for (auto _ : state) {
    const fitcal::io::DatasetIndex index = fitcal::io::ReadDatasetIndex(dir.path().string());
    benchmark::DoNotOptimize(index.runs.data());
  }
}
BENCHMARK(BM_ReadDatasetIndex)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
