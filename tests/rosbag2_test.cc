// io/rosbag2: the bags ROS 2's own recorder wrote (../shared/data/rosbag2, skipped when absent),
// round trips through the writer in both storage formats, compressed and split, and malformed
// bags, each of which must give one io::InputError with a one-line message.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "io/input_error.h"
#include "io/rosbag2/bag_reader.h"
#include "tests/bags/bag_writer.h"
#include "tests/bags/ros_message_encoders.h"
#include "io/rosbag2/cdr_reader.h"
#include "io/rosbag2/crc32.h"
#include "io/rosbag2/ros_messages.h"
#include "tests/test_files.h"

namespace fitcal::io::rosbag2 {
namespace {

namespace fs = std::filesystem;

const fs::path kRealBags = fs::path(FITCAL_SHARED_DIR) / "data" / "rosbag2";

#define SKIP_WITHOUT_REAL_BAGS() \
  if (!fs::is_directory(kRealBags)) GTEST_SKIP() << "no " << kRealBags

// One message as read, with its payload copied (BagMessage::payload lives until the next read).
struct ReadMessage {
  std::string topic;
  std::string type;
  std::int64_t time_ns;
  std::vector<std::uint8_t> payload;
  std::string what;
};

std::vector<ReadMessage> ReadAll(BagReader& bag) {
  std::vector<ReadMessage> out;
  BagMessage m;
  while (bag.ReadNext(&m)) {
    std::vector<std::uint8_t> payload(m.payload.data, m.payload.data + m.payload.size);
    out.push_back({m.topic->name, m.topic->type, m.time_ns, std::move(payload), Describe(m)});
  }
  return out;
}

// The message of the InputError `f` throws, "" when it throws none.
std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// An InputError whose message is one line, mentions `expected` and is not a dump of the file.
void ExpectOneLineError(const std::function<void()>& f, const std::string& expected) {
  const std::string message = InputErrorOf(f);
  ASSERT_FALSE(message.empty()) << "no InputError; expected one about '" << expected << "'";
  EXPECT_NE(message.find(expected), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_LT(message.size(), 400u) << message;
}

// ---------------------------------------------------------------------------------------------
// 1. The recorder's bags.

// cdr_test: every field of BasicTypes is zero except int32_value (123), in all three messages.
void ExpectRecordedBasicTypes(const BasicTypes& b) {
  EXPECT_FALSE(b.bool_value);
  EXPECT_EQ(b.byte_value, 0);
  EXPECT_EQ(b.float64_value, 0.0);
  EXPECT_EQ(b.int32_value, 123);
  EXPECT_EQ(b.uint32_value, 0u);
  EXPECT_EQ(b.int64_value, 0);
  EXPECT_EQ(b.uint64_value, 0u);
}

// cdr_test's Arrays: its own values, then the .msg defaults (Defaults.msg and the *_default
// arrays of Arrays.msg, as printed in the bag's stored message definition).
void ExpectRecordedArrays(const Arrays& a) {
  EXPECT_EQ(a.values.bool_values, (std::array<bool, 3>{true, false, true}));
  EXPECT_EQ(a.values.float64_values, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(a.values.string_values,
            (std::array<std::string, 3>{"Complex Hello1", "Complex Hello2", "Complex Hello3"}));
  for (const BasicTypes& b : a.basic_types_values) EXPECT_EQ(b, BasicTypes());
  for (const BasicTypes& d : a.defaults_values) {
    EXPECT_TRUE(d.bool_value);
    EXPECT_EQ(d.byte_value, 50);
    EXPECT_EQ(d.char_value, 100);
    EXPECT_EQ(d.float32_value, 1.125f);
    EXPECT_EQ(d.float64_value, 1.125);
    EXPECT_EQ(d.int8_value, -50);
    EXPECT_EQ(d.uint8_value, 200);
    EXPECT_EQ(d.int16_value, -1000);
    EXPECT_EQ(d.uint16_value, 2000);
    EXPECT_EQ(d.int32_value, -30000);
    EXPECT_EQ(d.uint32_value, 60000u);
    EXPECT_EQ(d.int64_value, -40000000);
    EXPECT_EQ(d.uint64_value, 50000000u);
  }
  const ArrayValues& def = a.defaults;
  EXPECT_EQ(def.bool_values, (std::array<bool, 3>{false, true, false}));
  EXPECT_EQ(def.char_values, (std::array<std::uint8_t, 3>{0, 1, 127}));
  EXPECT_EQ(def.float32_values, (std::array<float, 3>{1.125f, 0.0f, -1.125f}));
  EXPECT_EQ(def.float64_values, (std::array<double, 3>{3.1415, 0.0, -3.1415}));
  EXPECT_EQ(def.int8_values, (std::array<std::int8_t, 3>{0, 127, -128}));
  EXPECT_EQ(def.int16_values, (std::array<std::int16_t, 3>{0, 32767, -32768}));
  EXPECT_EQ(def.uint16_values, (std::array<std::uint16_t, 3>{0, 1, 65535}));
  EXPECT_EQ(def.int32_values[2], std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(def.uint32_values[2], std::numeric_limits<std::uint32_t>::max());
  EXPECT_EQ(def.int64_values[1], std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(def.uint64_values[2], std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(def.string_values, (std::array<std::string, 3>{"", "max value", "min value"}));
  EXPECT_EQ(a.alignment_check, 0);
}

// Topics, counts and times agree with the metadata.yaml the recorder wrote.
void ExpectMatchesMetadata(const BagReader& bag, const std::vector<ReadMessage>& messages) {
  const BagMetadata* metadata = bag.metadata();
  ASSERT_NE(metadata, nullptr);
  EXPECT_EQ(bag.storage_identifier(), metadata->storage_identifier);
  EXPECT_EQ(bag.message_count(), metadata->message_count);
  EXPECT_EQ(messages.size(), metadata->message_count);
  EXPECT_EQ(bag.start_time_ns(), metadata->starting_time_ns);
  EXPECT_EQ(bag.end_time_ns() - bag.start_time_ns(), metadata->duration_ns);
  ASSERT_FALSE(messages.empty());
  EXPECT_EQ(messages.front().time_ns, metadata->starting_time_ns);
  EXPECT_EQ(messages.back().time_ns, metadata->starting_time_ns + metadata->duration_ns);
  EXPECT_EQ(bag.topics().size(), metadata->topics.size());
  for (const TopicInfo& expected : metadata->topics) {
    const TopicInfo* topic = bag.FindTopic(expected.name);
    ASSERT_NE(topic, nullptr) << expected.name;
    EXPECT_EQ(topic->type, expected.type);
    EXPECT_EQ(topic->serialization_format, expected.serialization_format);
    EXPECT_EQ(topic->message_count, expected.message_count) << expected.name;
    const auto n = std::count_if(messages.begin(), messages.end(),
                                 [&](const ReadMessage& m) { return m.topic == expected.name; });
    EXPECT_EQ(static_cast<std::uint64_t>(n), expected.message_count) << expected.name;
  }
  for (std::size_t i = 1; i < messages.size(); ++i) {
    EXPECT_LE(messages[i - 1].time_ns, messages[i].time_ns);
  }
}

class RealBag : public ::testing::TestWithParam<const char*> {};

TEST_P(RealBag, CdrTestMatchesMetadataAndDecodes) {
  SKIP_WITHOUT_REAL_BAGS();
  BagReader bag((kRealBags / GetParam() / "cdr_test").string());
  const std::vector<ReadMessage> messages = ReadAll(bag);
  ExpectMatchesMetadata(bag, messages);
  EXPECT_EQ(bag.FindTopic("/test_topic")->message_count, 3u);
  EXPECT_EQ(bag.FindTopic("/array_topic")->message_count, 4u);
  for (const ReadMessage& m : messages) {
    const RosMessage decoded = DecodeMessage(m.type, ByteView(m.payload), m.what);
    if (m.topic == "/test_topic") {
      EXPECT_EQ(m.payload.size(), 52u);
      ExpectRecordedBasicTypes(std::get<BasicTypes>(decoded));
    } else {
      EXPECT_EQ(m.payload.size(), 696u);
      ExpectRecordedArrays(std::get<Arrays>(decoded));
    }
  }
  EXPECT_EQ(messages[0].time_ns, 1586406456763032325);  // first /test_topic message
  EXPECT_EQ(messages[1].topic, "/array_topic");
  EXPECT_EQ(messages[1].time_ns, 1586406456782683500);
}

TEST_P(RealBag, TalkerStringsSayHelloWorld) {
  SKIP_WITHOUT_REAL_BAGS();
  BagReader bag((kRealBags / GetParam() / "talker").string());
  const std::vector<ReadMessage> messages = ReadAll(bag);
  ExpectMatchesMetadata(bag, messages);
  int next = 0;
  for (const ReadMessage& m : messages) {
    if (m.topic != "/topic") continue;
    EXPECT_EQ(m.type, "std_msgs/msg/String");
    EXPECT_EQ(DecodeString(ByteView(m.payload), m.what).data,
              "Hello, world! " + std::to_string(next++));
  }
  EXPECT_EQ(next, 10);
  EXPECT_EQ(bag.FindTopic("/parameter_events")->message_count, 0u);
  // /rosout carries rcl_interfaces/msg/Log, which fitcal does not decode.
  const auto rosout = std::find_if(messages.begin(), messages.end(),
                                   [](const ReadMessage& m) { return m.topic == "/rosout"; });
  ASSERT_NE(rosout, messages.end());
  ExpectOneLineError([&] { DecodeMessage(rosout->type, ByteView(rosout->payload), rosout->what); },
                     "unknown message type \"rcl_interfaces/msg/Log\"");
}

INSTANTIATE_TEST_SUITE_P(Storage, RealBag, ::testing::Values("sqlite3", "mcap"));

TEST(RealBags, BothStorageFormatsHoldTheSameMessages) {
  SKIP_WITHOUT_REAL_BAGS();
  for (const char* name : {"cdr_test", "talker"}) {
    BagReader sqlite((kRealBags / "sqlite3" / name).string());
    BagReader mcap((kRealBags / "mcap" / name).string());
    const std::vector<ReadMessage> a = ReadAll(sqlite);
    const std::vector<ReadMessage> b = ReadAll(mcap);
    ASSERT_EQ(a.size(), b.size()) << name;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].topic, b[i].topic) << name << " " << i;
      EXPECT_EQ(a[i].time_ns, b[i].time_ns) << name << " " << i;
      EXPECT_EQ(a[i].payload, b[i].payload) << name << " " << i;
      if (!IsKnownMessageType(a[i].type)) continue;
      EXPECT_EQ(DecodeMessage(a[i].type, ByteView(a[i].payload), a[i].what),
                DecodeMessage(b[i].type, ByteView(b[i].payload), b[i].what));
    }
  }
}

TEST(RealBags, OpensSingleFilesAndMetadataYaml) {
  SKIP_WITHOUT_REAL_BAGS();
  BagReader db3((kRealBags / "sqlite3" / "cdr_test" / "cdr_test_0.db3").string());
  BagReader mcap((kRealBags / "mcap" / "talker" / "talker.mcap").string());
  BagReader yaml((kRealBags / "mcap" / "cdr_test" / "metadata.yaml").string());
  EXPECT_EQ(db3.metadata(), nullptr);
  EXPECT_EQ(db3.storage_identifier(), "sqlite3");
  EXPECT_EQ(db3.message_count(), 7u);
  EXPECT_EQ(mcap.storage_identifier(), "mcap");
  EXPECT_EQ(mcap.message_count(), 20u);
  EXPECT_EQ(mcap.FindTopic("/topic")->type, "std_msgs/msg/String");
  EXPECT_EQ(yaml.message_count(), 7u);
  EXPECT_EQ(yaml.files().size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// 2. Round trips through the writer.

Header MakeHeader(std::int64_t t_ns, const std::string& frame) {
  Header h;
  h.stamp.sec = static_cast<std::int32_t>(t_ns / 1000000000);
  h.stamp.nanosec = static_cast<std::uint32_t>(t_ns % 1000000000);
  h.frame_id = frame;
  return h;
}

JointState MakeJointState(int i, std::int64_t t_ns) {
  JointState js;
  js.header = MakeHeader(t_ns, "base_link");
  js.name = {"wheel_left", "wheel_right", "caster_" + std::to_string(i % 3)};
  js.position = {0.01 * i, -0.02 * i, 1e-300 * i};
  js.velocity = {1.5, -1.5 + i, 0.0};
  if (i % 2 == 0) js.effort = {0.25, 0.5, std::numeric_limits<double>::max()};
  return js;
}

PoseStamped MakePose(int i, std::int64_t t_ns) {
  PoseStamped p;
  p.header = MakeHeader(t_ns, "mocap");
  p.pose.position = {0.1 * i, -0.2 * i, 0.05};
  p.pose.orientation = {0.0, 0.0, std::sin(0.01 * i), std::cos(0.01 * i)};
  return p;
}

Odometry MakeOdometry(int i, std::int64_t t_ns) {
  Odometry o;
  o.header = MakeHeader(t_ns, "odom");
  o.child_frame_id = "base_footprint";
  o.pose.pose = MakePose(i, t_ns).pose;
  o.twist.twist.linear = {0.3, 0.0, 0.0};
  o.twist.twist.angular = {0.0, 0.0, 0.1 * i};
  for (std::size_t k = 0; k < 36; ++k) {
    o.pose.covariance[k] = k % 7 == 0 ? 1e-3 * (i + 1) : 0.0;
    o.twist.covariance[k] = k % 7 == 0 ? 2e-3 : 1e-9 * static_cast<double>(k);
  }
  return o;
}

TfMessage MakeTf(int i, std::int64_t t_ns) {
  TfMessage tf;
  for (int k = 0; k < i % 3; ++k) {  // 0, 1 or 2 transforms
    TransformStamped t;
    t.header = MakeHeader(t_ns, "odom");
    t.child_frame_id = "link_" + std::to_string(k);
    t.transform.translation = {1.0 * k, 2.0, -3.0};
    t.transform.rotation = {0.0, 0.0, 0.0, 1.0};
    tf.transforms.push_back(t);
  }
  return tf;
}

struct Written {
  std::string topic;
  std::int64_t time_ns;
  RosMessage message;
};

// 4 topics x 40 messages, times interleaved and some written out of order (a late /tf), so the
// reader has to sort within chunks and merge across files.
std::vector<Written> MakeMessages() {
  const std::int64_t t0_ns = 1700000000123456789;
  std::vector<Written> out;
  for (int i = 0; i < 40; ++i) {
    const std::int64_t t_ns = t0_ns + i * 10000000;
    out.push_back({"/joint_states", t_ns, MakeJointState(i, t_ns)});
    out.push_back({"/mocap/pose", t_ns + 1000, MakePose(i, t_ns + 1000)});
    out.push_back({"/odom", t_ns + 2000, MakeOdometry(i, t_ns + 2000)});
    const std::int64_t tf_ns = i % 5 == 4 ? t_ns - 25000000 : t_ns + 3000;  // late arrivals
    out.push_back({"/tf", tf_ns, MakeTf(i, tf_ns)});
  }
  return out;
}

std::vector<std::uint8_t> Encode(const RosMessage& message) {
  if (const auto* js = std::get_if<JointState>(&message)) return EncodeJointState(*js);
  if (const auto* p = std::get_if<PoseStamped>(&message)) return EncodePoseStamped(*p);
  if (const auto* o = std::get_if<Odometry>(&message)) return EncodeOdometry(*o);
  return EncodeTfMessage(std::get<TfMessage>(message));
}

void WriteBag(const fs::path& dir, const BagWriterOptions& options,
              const std::vector<Written>& messages) {
  BagWriter bag(dir.string(), options);
  bag.AddTopic("/joint_states", "sensor_msgs/msg/JointState");
  bag.AddTopic("/mocap/pose", "geometry_msgs/msg/PoseStamped");
  bag.AddTopic("/odom", "nav_msgs/msg/Odometry");
  bag.AddTopic("/tf", "tf2_msgs/msg/TFMessage");
  for (const Written& m : messages) bag.Write(m.topic, m.time_ns, ByteView(Encode(m.message)));
  bag.Close();
}

// Expects `bag` to hand out the `written` messages in time order, each decoding to what was
// written.
void ExpectReadBackInTimeOrder(BagReader& bag, std::vector<Written> written) {
  std::stable_sort(written.begin(), written.end(),
                   [](const Written& a, const Written& b) { return a.time_ns < b.time_ns; });
  const std::vector<ReadMessage> read = ReadAll(bag);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    ASSERT_EQ(read[i].topic, written[i].topic) << i;
    EXPECT_EQ(read[i].time_ns, written[i].time_ns) << i;
    EXPECT_EQ(DecodeMessage(read[i].type, ByteView(read[i].payload), read[i].what),
              written[i].message)
        << i;
  }
}

struct RoundTripCase {
  const char* name;
  StorageFormat storage;
  Compression compression;
  bool split;
};

class RoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(RoundTrip, WrittenMessagesReadBackEqualInTimeOrder) {
  const RoundTripCase& c = GetParam();
  testing::TempDir tmp;
  const fs::path dir = tmp.path() / "bag";
  BagWriterOptions options;
  options.storage = c.storage;
  options.mcap.compression = c.compression;
  options.mcap.chunk_bytes = 4096;  // many chunks
  options.split_after_messages = c.split ? 90 : 0;
  const std::vector<Written> expected = MakeMessages();
  WriteBag(dir, options, expected);

  BagReader bag(dir.string());
  EXPECT_EQ(bag.files().size(), c.split ? 2u : 1u);
  EXPECT_EQ(bag.metadata()->relative_file_paths.size(), bag.files().size());
  EXPECT_EQ(bag.message_count(), expected.size());
  EXPECT_EQ(bag.FindTopic("/odom")->message_count, 40u);
  EXPECT_EQ(bag.FindTopic("/tf")->type, "tf2_msgs/msg/TFMessage");
  EXPECT_EQ(bag.start_time_ns(), bag.metadata()->starting_time_ns);
  EXPECT_EQ(bag.end_time_ns() - bag.start_time_ns(), bag.metadata()->duration_ns);
  ExpectReadBackInTimeOrder(bag, expected);
}

INSTANTIATE_TEST_SUITE_P(
    Formats, RoundTrip,
    ::testing::Values(
        RoundTripCase{"sqlite3", StorageFormat::kSqlite3, Compression::kNone, false},
        RoundTripCase{"sqlite3_split", StorageFormat::kSqlite3, Compression::kNone, true},
        RoundTripCase{"mcap", StorageFormat::kMcap, Compression::kNone, false},
        RoundTripCase{"mcap_split", StorageFormat::kMcap, Compression::kNone, true},
        RoundTripCase{"mcap_zstd", StorageFormat::kMcap, Compression::kZstd, false},
        RoundTripCase{"mcap_zstd_split", StorageFormat::kMcap, Compression::kZstd, true},
        RoundTripCase{"mcap_lz4", StorageFormat::kMcap, Compression::kLz4, false},
        RoundTripCase{"mcap_lz4_split", StorageFormat::kMcap, Compression::kLz4, true}),
    [](const ::testing::TestParamInfo<RoundTripCase>& p) { return p.param.name; });

TEST(RoundTrip, McapWithoutSummaryOrCrcsReads) {
  testing::TempDir tmp;
  BagWriterOptions options;
  options.mcap.summary = false;
  options.mcap.crcs = false;
  options.mcap.compression = Compression::kLz4;
  WriteBag(tmp.path() / "bag", options, MakeMessages());
  BagReader bag((tmp.path() / "bag").string());
  EXPECT_EQ(ReadAll(bag).size(), 160u);
}

// Messages outside chunks (spec "Data Section"), in a split bag: the reader groups them into
// blocks and merges the blocks and files by time.
TEST(RoundTrip, McapWithoutChunksReads) {
  testing::TempDir tmp;
  BagWriterOptions options;
  options.mcap.chunked = false;
  options.split_after_messages = 100;
  const std::vector<Written> expected = MakeMessages();
  WriteBag(tmp.path() / "bag", options, expected);
  BagReader bag((tmp.path() / "bag").string());
  EXPECT_EQ(bag.files().size(), 2u);
  ExpectReadBackInTimeOrder(bag, expected);
}

// Times written as a permutation, so every chunk (or block of loose messages, 4 MiB each)
// overlaps every other in time: the reader must merge all of them.
TEST(RoundTrip, OverlappingChunksComeOutInTimeOrder) {
  testing::TempDir tmp;
  const std::int64_t n = 60000;  // ~6 MB of messages: two loose blocks
  for (bool chunked : {true, false}) {
    const fs::path dir = tmp.path() / (chunked ? "chunked" : "loose");
    BagWriterOptions options;
    options.mcap.chunked = chunked;
    options.mcap.chunk_bytes = 64 << 10;
    BagWriter writer(dir.string(), options);
    writer.AddTopic("/chatter", "std_msgs/msg/String");
    for (std::int64_t i = 0; i < n; ++i) {
      const std::int64_t t_ns = (i * 7919) % n;  // 7919 is prime: a permutation of 0..n-1
      const StringMessage text{"message " + std::to_string(t_ns) + std::string(50, '.')};
      writer.Write("/chatter", t_ns, ByteView(EncodeString(text)));
    }
    writer.Close();
    BagReader bag(dir.string());
    BagMessage m;
    std::int64_t expected_ns = 0;
    while (bag.ReadNext(&m)) {
      ASSERT_EQ(m.time_ns, expected_ns);
      ASSERT_EQ(DecodeString(m.payload, Describe(m)).data.substr(0, 14),
                ("message " + std::to_string(expected_ns) + "......").substr(0, 14));
      ++expected_ns;
    }
    EXPECT_EQ(expected_ns, n);
  }
}

TEST(RoundTrip, EmptyBagHasTopicsAndNoMessages) {
  testing::TempDir tmp;
  for (StorageFormat storage : {StorageFormat::kSqlite3, StorageFormat::kMcap}) {
    const fs::path dir = tmp.path() / (storage == StorageFormat::kMcap ? "m" : "s");
    WriteBag(dir, BagWriterOptions{storage, {}, 0}, {});
    BagReader bag(dir.string());
    EXPECT_EQ(bag.topics().size(), 4u);
    EXPECT_EQ(bag.message_count(), 0u);
    BagMessage m;
    EXPECT_FALSE(bag.ReadNext(&m));
    EXPECT_FALSE(bag.ReadNext(&m));
  }
}

TEST(Cdr, BigEndianPayloadsDecode) {
  const JointState js = MakeJointState(3, 1234567890123);
  const std::vector<std::uint8_t> be = EncodeJointState(js, /*big_endian=*/true);
  EXPECT_EQ(be[1], 0x00);  // CDR_BE
  EXPECT_EQ(DecodeJointState(ByteView(be), "be"), js);
  const Odometry odom = MakeOdometry(5, 42);
  EXPECT_EQ(DecodeOdometry(ByteView(EncodeOdometry(odom, true)), "be"), odom);
  const TfMessage tf = MakeTf(2, 7);
  EXPECT_EQ(DecodeTfMessage(ByteView(EncodeTfMessage(tf, true)), "be"), tf);
}

TEST(Cdr, JointStateLayoutIsTheRos2One) {
  // Hand-laid CDR_LE: stamp (7, 8), frame_id "a", name ["j"], position [0.5], no velocity/effort.
  const std::vector<std::uint8_t> bytes = {
      0x00, 0x01, 0x00, 0x00,                                    // encapsulation
      7,    0,    0,    0,    8,   0, 0,    0,                   // sec, nanosec
      2,    0,    0,    0,    'a', 0, 0,    0,                   // "a" + NUL + 2 padding
      1,    0,    0,    0,    2,   0, 0,    0,    'j', 0, 0, 0,  // name: 1 string "j"
      1,    0,    0,    0,                         // position: 1 double, at 32: aligned
      0,    0,    0,    0,    0,   0, 0xE0, 0x3F,  // 0.5
      0,    0,    0,    0,    0,   0, 0,    0};    // velocity [], effort []
  const JointState js = DecodeJointState(ByteView(bytes), "hand-made");
  EXPECT_EQ(js.header.stamp.sec, 7);
  EXPECT_EQ(js.header.stamp.nanosec, 8u);
  EXPECT_EQ(js.header.frame_id, "a");
  EXPECT_EQ(js.name, std::vector<std::string>{"j"});
  EXPECT_EQ(js.position, std::vector<double>{0.5});
  EXPECT_TRUE(js.velocity.empty());
  EXPECT_TRUE(js.effort.empty());
  EXPECT_EQ(EncodeJointState(js), bytes);
}

TEST(Crc32, MatchesTheStandardCheckValue) {
  // CRC-32/ISO-HDLC check value of "123456789" (the catalogue's test vector).
  const char* text = "123456789";
  EXPECT_EQ(ComputeCrc32(reinterpret_cast<const std::uint8_t*>(text), 9), 0xCBF43926u);
}

// ---------------------------------------------------------------------------------------------
// 3. Malformed bags and payloads.

fs::path WriteSmallBag(const fs::path& dir, StorageFormat storage, Compression compression) {
  BagWriterOptions options;
  options.storage = storage;
  options.mcap.compression = compression;
  WriteBag(dir, options, MakeMessages());
  return dir / (dir.filename().string() + (storage == StorageFormat::kMcap ? "_0.mcap" : "_0.db3"));
}

void Overwrite(const fs::path& file, std::size_t offset, const std::string& bytes) {
  std::string data = testing::ReadFileBytes(file);
  ASSERT_LE(offset + bytes.size(), data.size());
  data.replace(offset, bytes.size(), bytes);
  testing::WriteFileBytes(file, data);
}

void Truncate(const fs::path& file, double fraction) {
  const std::string data = testing::ReadFileBytes(file);
  testing::WriteFileBytes(file, data.substr(0, static_cast<std::size_t>(data.size() * fraction)));
}

TEST(Malformed, TruncatedFiles) {
  testing::TempDir tmp;
  const fs::path mcap = WriteSmallBag(tmp.path() / "m", StorageFormat::kMcap, Compression::kNone);
  Truncate(mcap, 0.5);
  ExpectOneLineError([&] { BagReader bag(mcap.string()); }, "truncated file");
  ExpectOneLineError([&] { BagReader bag(mcap.string()); }, mcap.string());
  Truncate(mcap, 0.0001);  // a few bytes of magic
  ExpectOneLineError([&] { BagReader bag(mcap.string()); }, "truncated file");
  const fs::path db3 = WriteSmallBag(tmp.path() / "s", StorageFormat::kSqlite3, Compression::kNone);
  Truncate(db3, 0.5);
  ExpectOneLineError([&] { ReadAll(*std::make_unique<BagReader>(db3.string())); }, db3.string());
}

TEST(Malformed, BadMagic) {
  testing::TempDir tmp;
  const fs::path mcap = WriteSmallBag(tmp.path() / "m", StorageFormat::kMcap, Compression::kNone);
  Overwrite(mcap, 1, "NCAP");
  ExpectOneLineError([&] { BagReader bag(mcap.string()); }, "bad magic");
  const fs::path db3 = WriteSmallBag(tmp.path() / "s", StorageFormat::kSqlite3, Compression::kNone);
  Overwrite(db3, 0, "MySQL");
  ExpectOneLineError([&] { BagReader bag(db3.string()); }, "bad magic");
  const fs::path end = WriteSmallBag(tmp.path() / "e", StorageFormat::kMcap, Compression::kZstd);
  Overwrite(end, fs::file_size(end) - 3, "XYZ");
  ExpectOneLineError([&] { BagReader bag(end.string()); }, "bad magic after the Footer");
}

TEST(Malformed, CorruptChunkFailsItsCrc) {
  testing::TempDir tmp;
  const fs::path mcap = WriteSmallBag(tmp.path() / "m", StorageFormat::kMcap, Compression::kNone);
  const std::string data = testing::ReadFileBytes(mcap);
  const std::size_t at = data.find("base_footprint");  // inside an Odometry payload in a chunk
  ASSERT_NE(at, std::string::npos);
  Overwrite(mcap, at, "B");
  ExpectOneLineError([&] { BagReader bag(mcap.string()); }, "Chunk CRC mismatch");
}

TEST(Malformed, CorruptCompressedChunk) {
  testing::TempDir tmp;
  const fs::path mcap = WriteSmallBag(tmp.path() / "m", StorageFormat::kMcap, Compression::kLz4);
  const std::string data = testing::ReadFileBytes(mcap);
  const std::size_t lz4 = data.find(std::string("\x03\x00\x00\x00lz4", 7));
  ASSERT_NE(lz4, std::string::npos);
  Overwrite(mcap, lz4 + 7 + 8 + 40, "\xff\xff\xff\xff");  // inside the first compressed chunk
  const std::string message = InputErrorOf([&] { BagReader bag(mcap.string()); });
  EXPECT_TRUE(message.find("cannot decompress") != std::string::npos ||
              message.find("CRC mismatch") != std::string::npos)
      << message;
}

TEST(Malformed, UnknownChunkCompression) {
  testing::TempDir tmp;
  const fs::path mcap = WriteSmallBag(tmp.path() / "m", StorageFormat::kMcap, Compression::kZstd);
  const std::string data = testing::ReadFileBytes(mcap);
  const std::size_t zstd = data.find("zstd");
  ASSERT_NE(zstd, std::string::npos);
  Overwrite(mcap, zstd, "brot");
  ExpectOneLineError([&] { BagReader bag(mcap.string()); }, "unknown compression \"brot\"");
}

TEST(Malformed, UnknownMessageType) {
  const std::vector<std::uint8_t> payload = EncodeString(StringMessage{"hi"});
  ExpectOneLineError([&] { DecodeMessage("my_msgs/msg/Secret", ByteView(payload), "t.mcap /x"); },
                     "t.mcap /x: unknown message type \"my_msgs/msg/Secret\"");
}

TEST(Malformed, SequenceLengthLargerThanThePayload) {
  JointState js = MakeJointState(1, 5);
  std::vector<std::uint8_t> payload = EncodeJointState(js);
  // name[] count follows stamp (8) and frame_id (4 + "base_link\0" = 14, padded to 16).
  const std::size_t count_at = 4 + 8 + 16;
  ASSERT_EQ(payload[count_at], 3);
  payload[count_at + 3] = 0x7f;  // 2^31 strings
  ExpectOneLineError([&] { DecodeJointState(ByteView(payload), "js"); }, "sequence length");
  TfMessage tf = MakeTf(2, 9);
  std::vector<std::uint8_t> tf_bytes = EncodeTfMessage(tf);
  tf_bytes[4 + 2] = 0x10;  // transforms[] count 2 -> 0x100002
  ExpectOneLineError([&] { DecodeTfMessage(ByteView(tf_bytes), "tf"); }, "sequence length");
}

TEST(Malformed, ShortPayloadsAndUnterminatedStrings) {
  std::vector<std::uint8_t> pose = EncodePoseStamped(MakePose(1, 2));
  pose.resize(pose.size() - 5);
  ExpectOneLineError([&] { DecodePoseStamped(ByteView(pose), "p"); },
                     "payload shorter than its fields");
  std::vector<std::uint8_t> text = EncodeString(StringMessage{"abc"});
  text.back() = 'x';
  ExpectOneLineError([&] { DecodeString(ByteView(text), "s"); }, "no terminating NUL");
  std::vector<std::uint8_t> huge = EncodeString(StringMessage{"abc"});
  huge[7] = 0x40;  // string length 0x40000004
  ExpectOneLineError([&] { DecodeString(ByteView(huge), "s"); }, "exceeds");
  const std::vector<std::uint8_t> header_only = {0x00, 0x01};
  ExpectOneLineError([&] { DecodeString(ByteView(header_only), "s"); }, "CDR header");
  const std::vector<std::uint8_t> xcdr2 = {0x00, 0x07, 0x00, 0x00, 1, 0, 0, 0, 0};
  ExpectOneLineError([&] { DecodeString(ByteView(xcdr2), "s"); }, "unsupported CDR encapsulation");
}

// Opens `file` and reads and decodes everything in it; an InputError is a fine outcome, any
// other exception fails the test (and a crash fails the run).
void ReadEverythingOrInputError(const fs::path& file) {
  try {
    BagReader bag(file.string());
    BagMessage m;
    while (bag.ReadNext(&m)) {
      if (IsKnownMessageType(m.topic->type)) DecodeMessage(m.topic->type, m.payload, Describe(m));
    }
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

// Seeded random damage (1-4 bytes overwritten) and truncation at many lengths, with the MCAP
// CRCs off so that the damage reaches every parser rather than stopping at a CRC check.
TEST(Malformed, RandomDamageEndsInInputErrorOrSuccess) {
  testing::TempDir tmp;
  std::mt19937 rng(20240611);
  std::vector<Written> messages = MakeMessages();
  messages.resize(48);
  int bag = 0;
  for (StorageFormat storage : {StorageFormat::kMcap, StorageFormat::kSqlite3}) {
    for (Compression compression : {Compression::kNone, Compression::kZstd, Compression::kLz4}) {
      if (storage == StorageFormat::kSqlite3 && compression != Compression::kNone) continue;
      const fs::path dir = tmp.path() / ("b" + std::to_string(bag++));
      BagWriterOptions options;
      options.storage = storage;
      options.mcap.compression = compression;
      options.mcap.crcs = false;
      options.mcap.chunk_bytes = 2048;
      WriteBag(dir, options, messages);
      const fs::path file = dir / (dir.filename().string() +
                                   (storage == StorageFormat::kMcap ? "_0.mcap" : "_0.db3"));
      const std::string original = testing::ReadFileBytes(file);
      for (int trial = 0; trial < 150; ++trial) {
        std::string damaged = original;
        for (std::uint32_t k = 0, n = 1 + rng() % 4; k < n; ++k) {
          damaged[rng() % damaged.size()] = static_cast<char>(rng());
        }
        testing::WriteFileBytes(file, damaged);
        ReadEverythingOrInputError(file);
      }
      for (std::size_t length = 0; length < original.size(); length += 1 + original.size() / 60) {
        testing::WriteFileBytes(file, original.substr(0, length));
        ReadEverythingOrInputError(file);
      }
    }
  }
}

TEST(Malformed, MetadataProblems) {
  testing::TempDir tmp;
  const fs::path dir = tmp.path() / "bag";
  WriteSmallBag(dir, StorageFormat::kMcap, Compression::kNone);
  const fs::path yaml = dir / "metadata.yaml";
  std::string text = testing::ReadFileBytes(yaml);
  const std::string good = text;
  text.replace(text.find("bag_0.mcap"), 10, "../x.mcap");
  testing::WriteFileBytes(yaml, text);
  ExpectOneLineError([&] { BagReader bag(dir.string()); }, "outside the bag directory");
  testing::WriteFileBytes(yaml, "rosbag2_bagfile_information: {version: 5}\n");
  ExpectOneLineError([&] { BagReader bag(dir.string()); }, "missing key 'storage_identifier'");
  testing::WriteFileBytes(yaml, "rosbag2_bagfile_information: [\n");
  ExpectOneLineError([&] { BagReader bag(dir.string()); }, yaml.string());
  fs::remove(yaml);
  ExpectOneLineError([&] { BagReader bag(dir.string()); }, "no metadata.yaml");
}

}  // namespace
}  // namespace fitcal::io::rosbag2
