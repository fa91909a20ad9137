// rosbag2 read throughput (io/rosbag2) on bags of sensor_msgs/msg/JointState (6 joints, ~270
// bytes of CDR each) that the writer makes once in a temporary directory, about
// FITCAL_BENCH_BAG_MB (default 50) MB of messages each:
//   BM_ReadBag/mcap        MCAP, uncompressed 1 MiB chunks with CRCs (target: >= 200 MB/s)
//   BM_ReadBag/mcap_zstd   MCAP, zstd chunks
//   BM_ReadBag/mcap_lz4    MCAP, lz4 frame chunks
//   BM_ReadBag/sqlite3     sqlite3 (.db3)
//   BM_ReadAndDecode/mcap  the uncompressed MCAP, every message decoded to a JointState
// One iteration opens the bag (for MCAP the full checking scan) and reads every message.
// bytes_per_second is bag bytes on disk per second; payload_bytes_per_second counts the CDR
// payloads handed out (the same work whatever the compression). The page cache is warm after the
// first iteration: these measure parsing, checking and decompression, not the disk.
//   build/tests/rosbag2_benchmarks --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "io/rosbag2/bag_reader.h"
#include "tests/bags/bag_writer.h"
#include "tests/bags/ros_message_encoders.h"
#include "io/rosbag2/ros_messages.h"
#include "tests/bench/bench_support.h"
#include "cli/import_rosbag2.h"

namespace {

namespace fs = std::filesystem;
namespace rb = fitcal::io::rosbag2;

using fitcal::bench::EnvBytes;
using fitcal::bench::ScratchDir;

rb::JointState Sample(long i) {
  rb::JointState js;
  const std::int64_t t_ns = 1700000000000000000 + i * 10000000;  // 100 Hz
  js.header.stamp.sec = static_cast<std::int32_t>(t_ns / 1000000000);
  js.header.stamp.nanosec = static_cast<std::uint32_t>(t_ns % 1000000000);
  js.header.frame_id = "base_link";
  for (int j = 0; j < 6; ++j) {
    js.name.push_back("wheel_" + std::to_string(j));
    js.position.push_back(0.001 * static_cast<double>(i) * (j + 1));
    js.velocity.push_back(0.1 * (j + 1));
    js.effort.push_back(0.0);
  }
  return js;
}

struct Bag {
  fs::path dir;
  std::uint64_t file_bytes = 0;
};

// About FITCAL_BENCH_BAG_MB (default 50) MB of JointState messages at 100 Hz in a bag `name` of
// the scratch directory; with `ground_truth`, a PoseStamped on /mocap/pose at a tenth of the rate.
Bag WriteBag(const std::string& name, const rb::BagWriterOptions& options, bool ground_truth) {
  static const ScratchDir tmp("fitcal-rosbag2-bench");
  const std::uint64_t target_bytes = EnvBytes("FITCAL_BENCH_BAG_MB", 50);
  Bag bag{tmp.path() / name, 0};
  rb::BagWriter writer(bag.dir.string(), options);
  writer.AddTopic("/joint_states", "sensor_msgs/msg/JointState");
  if (ground_truth) writer.AddTopic("/mocap/pose", "geometry_msgs/msg/PoseStamped");
  std::uint64_t written = 0;
  for (long i = 0; written < target_bytes; ++i) {
    const rb::JointState js = Sample(i);
    const std::vector<std::uint8_t> payload = rb::EncodeJointState(js);
    const std::int64_t t_ns = 1700000000000000000 + i * 10000000;
    writer.Write("/joint_states", t_ns, rb::ByteView(payload));
    written += payload.size() + 31;  // + MCAP Message record prefix and fields
    if (ground_truth && i % 10 == 0) {
      // Where ImportBag's diff drive goes on wheel_0 (right, 0.1 rad/s) and wheel_1 (left,
      // 0.2 rad/s): an arc at v = 0.0075 m/s, omega = -1/60 rad/s (the import refuses a ground
      // truth no unit relates to the odometry).
      const double t_s = 0.01 * static_cast<double>(i), v = 0.0075, omega = -1.0 / 60.0;
      rb::PoseStamped p;
      p.header = js.header;
      p.pose.position.x = v / omega * std::sin(omega * t_s);
      p.pose.position.y = v / omega * (1.0 - std::cos(omega * t_s));
      p.pose.orientation.z = std::sin(0.5 * omega * t_s);
      p.pose.orientation.w = std::cos(0.5 * omega * t_s);
      const std::vector<std::uint8_t> pose = rb::EncodePoseStamped(p);
      writer.Write("/mocap/pose", t_ns + 1000, rb::ByteView(pose));
      written += pose.size() + 31;
    }
  }
  writer.Close();
  for (const std::string& file : writer.files()) bag.file_bytes += fs::file_size(file);
  return bag;
}

const Bag& GetBag(const std::string& name) {
  static std::map<std::string, Bag> bags;
  auto it = bags.find(name);
  if (it != bags.end()) return it->second;
  const rb::StorageFormat storage =
      name == "sqlite3" ? rb::StorageFormat::kSqlite3 : rb::StorageFormat::kMcap;
  const rb::Compression compression = name == "mcap_zstd"  ? rb::Compression::kZstd
                                      : name == "mcap_lz4" ? rb::Compression::kLz4
                                                           : rb::Compression::kNone;
  rb::BagWriterOptions options;
  options.storage = storage;
  options.mcap.compression = compression;
  return bags.emplace(name, WriteBag(name, options, false)).first->second;
}

void Report(benchmark::State& state, const Bag& bag, std::uint64_t payload_bytes) {
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bag.file_bytes));
  state.counters["payload_bytes_per_second"] = benchmark::Counter(
      static_cast<double>(payload_bytes), benchmark::Counter::kIsRate, benchmark::Counter::kIs1024);
  state.counters["bag_MB"] = static_cast<double>(bag.file_bytes) / (1 << 20);
}

void ReadBag(benchmark::State& state, const std::string& name) {
  const Bag& bag = GetBag(name);
  std::uint64_t payload_bytes = 0;
  for (auto _ : state) {
    rb::BagReader reader(bag.dir.string());
    rb::BagMessage m;
    std::uint64_t checksum = 0;
    while (reader.ReadNext(&m)) {
      payload_bytes += m.payload.size;
      checksum += m.payload.data[m.payload.size - 1];  // touch the payload
    }
    benchmark::DoNotOptimize(checksum);
  }
  Report(state, bag, payload_bytes);
}

void ReadAndDecode(benchmark::State& state, const std::string& name) {
  const Bag& bag = GetBag(name);
  std::uint64_t payload_bytes = 0;
  for (auto _ : state) {
    rb::BagReader reader(bag.dir.string());
    rb::BagMessage m;
    double sum_rad = 0;
    while (reader.ReadNext(&m)) {
      payload_bytes += m.payload.size;
      sum_rad += rb::DecodeJointState(m.payload, "bench").position[0];
    }
    benchmark::DoNotOptimize(sum_rad);
  }
  Report(state, bag, payload_bytes);
}

BENCHMARK_CAPTURE(ReadBag, mcap, std::string("mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ReadBag, mcap_zstd, std::string("mcap_zstd"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ReadBag, mcap_lz4, std::string("mcap_lz4"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ReadBag, sqlite3, std::string("sqlite3"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ReadAndDecode, mcap, std::string("mcap"))->Unit(benchmark::kMillisecond);

}  // namespace

// `fitcal import rosbag2` on one core: a diff_drive robot on wheel_0 (right) and wheel_1 (left) of
// the JointState bag above plus a PoseStamped ground truth at a tenth of its rate. ReadOnly: read,
// decode, interval rates, run logs (ReadRosbag2Import); EndToEnd: and the data set
// written (CSV text, files renamed into place).
const Bag& ImportBag() {
  static const Bag bag = [] {
    Bag b = WriteBag("import", {}, true);
    std::ofstream(b.dir.parent_path() / "robot.yaml")
        << "model: diff_drive\nname: bench\nwheels:\n  - {name: wheel_0, side: right, radius_m: "
           "0.05}\n  - {name: wheel_1, side: left, radius_m: 0.05}\nwheel_separation_m: 0.3\n"
           "bounds: {radius_m: [0.04, 0.06], wheel_separation_m: [0.2, 0.4]}\n";
    return b;
  }();
  return bag;
}

fitcal::ImportRosbag2Options ImportOptions() {
  fitcal::ImportRosbag2Options o;
  o.bag = ImportBag().dir.string();
  o.robot = (ImportBag().dir.parent_path() / "robot.yaml").string();
  o.ground_truth = "/mocap/pose";
  o.out = (ImportBag().dir.parent_path() / "dataset").string();
  o.force = true;
  o.quiet = true;
  return o;
}

void ImportRosbag2(benchmark::State& state, bool write) {
  const fitcal::ImportRosbag2Options o = ImportOptions();
  for (auto _ : state) {
    const auto imported =
        write ? fitcal::ImportRosbag2(o) : fitcal::ReadRosbag2Import(o);
    benchmark::DoNotOptimize(imported.runs.size());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * ImportBag().file_bytes));
  state.counters["bag_MB"] = static_cast<double>(ImportBag().file_bytes) / (1 << 20);
}
BENCHMARK_CAPTURE(ImportRosbag2, ReadOnly, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ImportRosbag2, EndToEnd, true)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
