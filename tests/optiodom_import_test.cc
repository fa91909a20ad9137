// `fitcal import optiodom` on the published recordings in ../shared/data/optiodom (skipped when
// that directory is absent), and the ticks encoder format it writes.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "diagnosis/channel_order_check.h"
#include "fit/final_pose_errors.h"
#include "fit/segment_cost.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/aligned_run.h"
#include "cli/import_optiodom.h"
#include "tests/test_paths.h"
#include "tests/omni3_robot.h"
#include "tests/three_wheel_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

const fs::path kOmni3 = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / "omni3";
const fs::path kCircleSession = kOmni3 / "circular" / "221220201643";
const fs::path kSquareSession = kOmni3 / "square" / "221220201934";

#define SKIP_WITHOUT_DATA()                                                   \
  if (!fs::is_directory(kCircleSession) || !fs::is_directory(kSquareSession)) \
  GTEST_SKIP() << "no " << kOmni3

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("fitcal_optiodom_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// A copy of the circle session under `tmp` (circular/<session>, as the recordings lay it out),
// for a test to spoil one of its files.
fs::path CopyOfCircleSession(const fs::path& tmp) {
  const fs::path session = tmp / "circular" / kCircleSession.filename();
  fs::create_directories(session);
  for (const auto& entry : fs::directory_iterator(kCircleSession)) {
    fs::copy_file(entry.path(), session / entry.path().filename());
  }
  return session;
}

TEST(OptiOdomImport, ReadsMetadataAndMapsTheAuthorsWheelsToOurs) {
  SKIP_WITHOUT_DATA();
  const optiodom::OptiOdomImport s = optiodom::ReadOptiOdomSessions({kCircleSession.string()});
  ASSERT_EQ(s.runs.size(), 4u);
  EXPECT_EQ(s.runs[0].trajectory, "circular_221220201643");
  ASSERT_TRUE(s.model->robot().encoder.has_value());
  EXPECT_EQ(s.model->robot().encoder->ticks_per_rev, 12.0 * 1024.0);  // README: 12:1, 1024 counts
  const Omni3Robot robot = Omni3RobotOf(dynamic_cast<const Omni3Model&>(*s.model));
  EXPECT_DOUBLE_EQ(robot.nominal.radius_m[0], 0.051);  // Di = 0.102 m
  EXPECT_DOUBLE_EQ(robot.nominal.distance_m[2], 0.195);
  EXPECT_NEAR(RadToDeg(robot.nominal.angle_rad[1]), 60.0, 1e-12);
  // Run 1, row 2 of the file holds ticks (-6, 24, 1): ours are their negatives, same order.
  EXPECT_EQ(s.rows[0].encoder[1][0], 6.0);
  EXPECT_EQ(s.rows[0].encoder[1][1], -24.0);
  EXPECT_EQ(s.rows[0].encoder[1][2], -1.0);
}

// The one channel-order check (diagnosis/channel_order_check.h, as the importer runs it) keeps
// the documented mapping on each single session, and finds two columns swapped on the windows of
// the ground-truth track, where a wrong order cannot hide behind a closed path.
TEST(OptiOdomImport, DocumentedWheelMappingIsTheOneTheGroundTruthSupports) {
  SKIP_WITHOUT_DATA();
  for (const fs::path& dir : {kCircleSession, kSquareSession}) {
    const optiodom::OptiOdomImport s = optiodom::ReadOptiOdomSessions({dir.string()});
    const auto& model = s.model;
    const std::vector<RunLog>& logs = s.runs;
    std::vector<const GroundTruthTrack*> tracks;
    for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
    const std::vector<AlignedRun> runs = AlignRuns(logs);
    ChannelOrderOptions every;
    every.score_every_mapping = true;  // as the importer: the best other order's SSR
    const ChannelOrderReport documented = CheckRecordedChannelOrder(runs, tracks, *model, every);
    EXPECT_FALSE(documented.likely_miswired) << dir << ": " << documented.message;
    EXPECT_TRUE(documented.on_windows) << dir;
    // Nominal parameters: every other order/sign at least 3x worse over the windows (a wrong
    // sign or order moves a 0.5 m window by tens of cm, the nominal by a few cm).
    EXPECT_GT(documented.best_nominal_ssr, 3.0 * documented.recorded_nominal_ssr) << dir;
    ChannelMapping swap;
    swap.column = {1, 0, 2};
    swap.sign = {1, 1, 1};
    const ChannelOrderReport swapped =
        CheckRecordedChannelOrder(ApplyChannelMapping(runs, swap), tracks, *model);
    ASSERT_TRUE(swapped.likely_miswired) << dir;
    EXPECT_EQ(swapped.best.column, swap.column);
    EXPECT_EQ(swapped.best.sign, swap.sign);
  }
}

// The runs of the sessions `dirs`, with `fix` applied to those of the session labelled `rewired`:
// what a driver rewired between two recordings leaves. A swap or a sign flip is its own inverse,
// so `fix` is also what repairs them.
struct Sessions {
  optiodom::OptiOdomImport import;
  std::vector<AlignedRun> runs;
  std::vector<const GroundTruthTrack*> tracks;
};
Sessions RewiredSessions(const std::vector<std::string>& dirs, const std::string& rewired,
                         const ChannelMapping& fix) {
  Sessions s{optiodom::ReadOptiOdomSessions(dirs), {}, {}};
  for (const RunLog& log : s.import.runs) s.tracks.push_back(&log.ground_truth);
  s.runs = AlignRuns(s.import.runs);
  for (AlignedRun& run : s.runs) {
    if (run.trajectory == rewired) run = ApplyChannelMapping({run}, fix).front();
  }
  return s;
}

// One session of nine rewired (omni3's wheels a and c swapped in square/221220201953, 12 of 67
// runs): the pool of every run still found the documented order best (its windows' SSR 66.5
// against 1.86 clean) and the fit wrote a calibration with every parameter NOT DETERMINED. Each
// session is checked alone too, and the rewired one is named.
TEST(OptiOdomImport, AMiswiringInOneSessionOfManyIsFoundAndTheSessionNamed) {
  SKIP_WITHOUT_DATA();
  std::vector<std::string> dirs;
  for (const char* path : {"circular", "square"}) {
    for (const auto& entry : fs::directory_iterator(kOmni3 / path)) dirs.push_back(entry.path());
  }
  std::sort(dirs.begin(), dirs.end());
  ChannelMapping swap;
  swap.column = {2, 1, 0};
  swap.sign = {1, 1, 1};
  const Sessions clean = RewiredSessions(dirs, "", swap);
  const ChannelOrderReport ok = CheckRecordedChannelOrder(clean.runs, clean.tracks,
                                                          *clean.import.model);
  EXPECT_FALSE(ok.likely_miswired) << ok.message;
  const Sessions s = RewiredSessions(dirs, "square_221220201953", swap);
  const ChannelOrderReport report = CheckRecordedChannelOrder(s.runs, s.tracks, *s.import.model);
  ASSERT_TRUE(report.likely_miswired);
  EXPECT_EQ(report.best.column, swap.column);
  EXPECT_EQ(report.best.sign, swap.sign);
  EXPECT_NE(report.message.find("session 'square_221220201953' (12 of 67 runs)"),
            std::string::npos)
      << report.message;
}

// A differential drive's right wheel negated: on closed loops the left wheel negated instead
// closes them as well (final-pose SSR 0.0311 both), and the final poses named the left wheel,
// whose fix mirrors the odometry. The windows follow the path and name the right one.
TEST(OptiOdomImport, ANegatedWheelIsNamedFromTheWindowsNotItsMirror) {
  const fs::path diff = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / "diff" / "circular";
  if (!fs::is_directory(diff / "231220200121")) GTEST_SKIP() << "no " << diff;
  ChannelMapping negate_right;
  negate_right.column = {0, 1};
  negate_right.sign = {-1, 1};
  const optiodom::OptiOdomImport s = optiodom::ReadOptiOdomSessions({(diff / "231220200121")});
  ASSERT_EQ(s.model->robot().channels[0].rate_column, "w_right");
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : s.runs) tracks.push_back(&log.ground_truth);
  const ChannelOrderReport report = CheckRecordedChannelOrder(
      ApplyChannelMapping(AlignRuns(s.runs), negate_right), tracks, *s.model);
  ASSERT_TRUE(report.likely_miswired);
  EXPECT_EQ(report.best.sign, negate_right.sign) << report.message;
  EXPECT_NE(report.message.find("right = -w_right"), std::string::npos) << report.message;
}

TEST(OptiOdomImport, WritesATicksDataSetThatLoadsBackToTheSameRuns) {
  SKIP_WITHOUT_DATA();
  const fs::path out = TempDir("roundtrip");
  optiodom::ImportOptiOdomOptions options;
  options.sessions = {kCircleSession.string()};
  options.out = (out / "ds").string();
  ASSERT_EQ(tools::RunImportOptiOdomCommand(options), 0);
  const io::Dataset ds = io::LoadDataset(options.out);
  const Omni3Robot robot = ReadOmni3Robot(ds.robot_path);
  ASSERT_TRUE(robot.encoder.has_value());
  EXPECT_EQ(robot.encoder->ticks_per_rev, 12288.0);
  EXPECT_FALSE(robot.encoder->cumulative);
  const optiodom::OptiOdomImport s = optiodom::ReadOptiOdomSessions({kCircleSession.string()});
  ASSERT_EQ(ds.runs.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const RunLog& direct = s.runs[i];
    EXPECT_EQ(ds.runs[i].trajectory, "circular_221220201643");
    EXPECT_EQ(ds.runs[i].repetition, s.rows[i].number);
    ASSERT_EQ(ds.runs[i].encoders.samples.size(), direct.encoders.samples.size());
    // Times are written with 1 us resolution: rates (ticks / dt) agree to ~1e-6 / 0.04 relative.
    for (std::size_t k = 0; k < direct.encoders.samples.size(); ++k) {
      for (int w = 0; w < 3; ++w) {
        EXPECT_NEAR(ds.runs[i].encoders.samples[k].value[w], direct.encoders.samples[k].value[w],
                    1e-4 * (1.0 + std::abs(direct.encoders.samples[k].value[w])));
      }
    }
  }
  // Running the import again replaces the data set it wrote (README, Outputs: issue 42).
  EXPECT_EQ(tools::RunImportOptiOdomCommand(options), 0);
  EXPECT_TRUE(fs::exists(out / "ds" / "dataset.yaml"));
  fs::remove_all(out);
}

TEST(OptiOdomImport, BadSessionIsOneErrorAndWritesNothing) {
  SKIP_WITHOUT_DATA();
  const fs::path tmp = TempDir("bad");
  const fs::path session = tmp / "circular" / "221220201643";
  fs::create_directories(session);
  // Metadata says N = 4 but only one run file is present.
  fs::copy_file(kCircleSession / "221220201643_metadata.csv",
                session / "221220201643_metadata.csv");
  fs::copy_file(kCircleSession / "221220201643_run-01.csv", session / "221220201643_run-01.csv");
  try {
    optiodom::ReadOptiOdomSessions({session.string()});
    FAIL() << "expected an InputError";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("N = 4"), std::string::npos) << e.what();
  }
  optiodom::ImportOptiOdomOptions options;
  options.sessions = {session.string()};
  options.out = (tmp / "out").string();
  EXPECT_EQ(tools::RunImportOptiOdomCommand(options), 1);
  EXPECT_FALSE(fs::exists(tmp / "out"));
  fs::remove_all(tmp);
}

// A time that does not advance is named with the previous row's, as the file writes both.
TEST(OptiOdomImport, ATimeThatDoesNotAdvanceNamesBothTimes) {
  SKIP_WITHOUT_DATA();
  const fs::path tmp = TempDir("time");
  const fs::path session = CopyOfCircleSession(tmp);
  const fs::path run = session / "221220201643_run-01.csv";
  std::ifstream in(run);
  std::string text, line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (n == 3) line.replace(0, line.find(','), "0.0399999999999636");  // row 2's time again
    text += line + "\n";
  }
  in.close();
  WriteText(run, text);
  try {
    optiodom::ReadOptiOdomSessions({session.string()});
    FAIL() << "expected an InputError";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":3: time 0.0399999999999636 s is not after the "
                                         "previous row's 0.0399999999999636 s"),
              std::string::npos)
        << e.what();
  }
  fs::remove_all(tmp);
}

// Sessions of two robots (an omni3 circle and a diff drive's) make no one robot.yaml: a usage
// error (exit 2) before anything is read, nothing written.
TEST(OptiOdomImport, SessionsOfTwoRobotsAreRefused) {
  SKIP_WITHOUT_DATA();
  const fs::path diff = kOmni3.parent_path() / "diff" / "circular" / "231220200121";
  if (!fs::is_directory(diff)) GTEST_SKIP() << "no " << diff;
  const fs::path tmp = TempDir("two_robots");
  optiodom::ImportOptiOdomOptions options;
  options.sessions = {kCircleSession.string(), diff.string()};
  options.out = (tmp / "out").string();
  EXPECT_EQ(tools::RunImportOptiOdomCommand(options), 2);
  EXPECT_FALSE(fs::exists(tmp / "out"));
  fs::remove_all(tmp);
}

// A session whose metadata names no OptiOdom robot is refused by name (exit 1), listed first or
// not: listed first it set the type the other sessions were held to, and the good one was blamed.
TEST(OptiOdomImport, AnUnknownRobotTypeIsBlamedOnItsOwnSession) {
  SKIP_WITHOUT_DATA();
  const fs::path tmp = TempDir("type");
  const fs::path bad = CopyOfCircleSession(tmp);
  WriteText(bad / "221220201643_metadata.csv", "type,omni33,,,\n");
  const std::string good = kSquareSession.string();
  for (const std::vector<std::string>& order : {std::vector<std::string>{bad.string(), good},
                                                std::vector<std::string>{good, bad.string()}}) {
    optiodom::ImportOptiOdomOptions options;
    options.sessions = order;
    options.out = (tmp / "out").string();
    try {
      optiodom::ImportOptiOdom(options, [](const std::string&) {});
      ADD_FAILURE() << "expected an InputError";
    } catch (const io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad.string() + ": type 'omni33'"), std::string::npos)
          << e.what();
    }
    EXPECT_EQ(tools::RunImportOptiOdomCommand(options), 1);
    EXPECT_FALSE(fs::exists(tmp / "out"));
  }
  fs::remove_all(tmp);
}

TEST(EncoderTicks, IncrementsAndCumulativeGiveTheSameRatesAndTicksNeedAResolution) {
  const fs::path tmp = TempDir("ticks");
  WriteText(tmp / "inc.csv", "t,ticks_a,ticks_b,ticks_c\n0,5,5,5\n0.04,100,-50,0\n0.1,30,0,-12\n");
  WriteText(tmp / "cum.csv",
            "t,ticks_a,ticks_b,ticks_c\n0,1000,0,-7\n0.04,1100,-50,-7\n0.1,1130,-50,-19\n");
  const EncoderTicks inc{4096.0, false}, cum{4096.0, true};
  const EncoderLog a = io::ReadEncoderCsv((tmp / "inc.csv").string(), inc);
  const EncoderLog b = io::ReadEncoderCsv((tmp / "cum.csv").string(), cum);
  ASSERT_EQ(a.samples.size(), 2u);
  ASSERT_EQ(b.samples.size(), 2u);
  const double rad_per_tick = 2.0 * M_PI / 4096.0;
  EXPECT_NEAR(a.samples[0].value[0], 100 * rad_per_tick / 0.04, 1e-12);
  EXPECT_NEAR(a.samples[1].value[2], -12 * rad_per_tick / 0.06, 1e-12);
  for (int k = 0; k < 2; ++k) {
    for (int w = 0; w < 3; ++w) EXPECT_NEAR(a.samples[k].value[w], b.samples[k].value[w], 1e-12);
  }
  try {
    io::ReadEncoderCsv((tmp / "inc.csv").string());
    FAIL() << "ticks without a resolution must be rejected";
  } catch (const io::InputError& e) {
    EXPECT_EQ(e.line(), 1);
    EXPECT_NE(std::string(e.what()).find("ticks_per_rev"), std::string::npos);
  }
  // The rate format still loads.
  WriteText(tmp / "w.csv", "t,w_a,w_b,w_c\n0,0,0,0\n0.04,1.5,-2,0.25\n");
  EXPECT_DOUBLE_EQ(io::ReadEncoderCsv((tmp / "w.csv").string()).samples[0].value[1], -2.0);
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace fitcal
