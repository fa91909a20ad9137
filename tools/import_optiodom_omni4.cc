#include "tools/import_optiodom_omni4.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "fit/final_pose_errors.h"
#include "io/dataset.h"
#include "models/omni/omni_model.h"
#include "odometry/aligned_run.h"
#include "tools/import_channel_order.h"
#include "tools/optiodom_format.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

namespace {

constexpr int kWheels = 4;
// Our wheels for the authors' 1..4 and their geometry (header): position signs of (L1/2, L2/2),
// drive direction and roller angle.
constexpr struct {
  const char* name;
  double x_sign, y_sign, drive_angle_deg, roller_angle_deg;
} kLayout[kWheels] = {
    {"fl", 1, 1, 0, -45}, {"fr", 1, -1, 180, 45}, {"rl", -1, 1, 0, 45}, {"rr", -1, -1, 180, -45}};
// The box the fit may search. Palacin Eq. 16's (R +- 0.025 m, r +- 6.8 %, delta +- 2 deg) is too
// tight for these mecanum wheels: regressing the ground truth's steps on the counts gives a
// translation 8 % above the nominal radius (header), and a fit in Eq. 16's box rests on the r and
// delta bounds. Rollers make the effective radius of a mecanum wheel uncertain: +-15 %, +-5 deg.
constexpr double kDistanceBound_m = 0.025;
constexpr double kRadiusBound = 0.15;
constexpr double kAngleBound_deg = 5.0;

OptiOdomOmni4Metadata ReadMetadata(const std::string& path) {
  const optiodom::Metadata rows = optiodom::ReadMetadata(path, "omni4");
  OptiOdomOmni4Metadata meta;
  meta.gear_ratio = rows.Value("ngear", true);
  meta.encoder_counts_per_rev = rows.Value("encRes", true);
  const std::vector<double> l = rows.Values("Li", 2, true);
  std::copy(l.begin(), l.end(), meta.length_m.begin());
  const std::vector<double> d = rows.Values("Di", kWheels, true);
  std::copy(d.begin(), d.end(), meta.diameter_m.begin());
  meta.num_runs = rows.NumRuns();
  return meta;
}

void AppendNumber(std::string* out, double v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);  // shortest exact
  out->append(buffer, end);
}

std::string EncoderCsvText(const RunLog& log, const Robot& robot) {
  std::string out = "t";
  for (const ChannelInfo& c : robot.channels) out += "," + c.rate_column;
  out += "\n";
  out.reserve(log.encoders.t_s.size() * 64);
  for (std::size_t k = 0; k < log.encoders.t_s.size(); ++k) {
    AppendNumber(&out, log.encoders.t_s[k]);
    for (int i = 0; i < kWheels; ++i) {
      out += ',';
      AppendNumber(&out, k == 0 ? 0.0 : log.encoders.samples[k - 1].value[i]);
    }
    out += '\n';
  }
  return out;
}

std::string GroundTruthCsvText(const GroundTruthTrack& track) {
  std::string out = "t,x,y,theta\n";
  out.reserve(track.t_s.size() * 64);
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const Pose2d& pose = track.world_T_robot[k];
    for (double v : {track.t_s[k], pose.x, pose.y, pose.theta}) {
      AppendNumber(&out, v);
      out += ',';
    }
    out.back() = '\n';
  }
  return out;
}

}  // namespace

OptiOdomOmni4Session ReadOptiOdomOmni4Session(const std::string& directory) {
  // Wheel rates w_i = 2 pi enc_i / (counts per rev dt) over the interval ending at each row.
  return optiodom::ReadSession<OptiOdomOmni4Metadata, RunLog>(
      directory, ReadMetadata,
      [](const std::string& path, int number, const OptiOdomOmni4Session& session) {
        const optiodom::RunRows rows =
            optiodom::ReadRun(path, number, kWheels, "enc_1, enc_2, enc_3, enc_4");
        return optiodom::RunLogOf(session.path_type, session.name, rows,
                                  session.metadata.CountsPerWheelRev());
      });
}

RobotModelPtr OptiOdomOmni4NominalModel(const OptiOdomOmni4Metadata& metadata) {
  const double half_l1_m = 0.5 * metadata.length_m[0];
  const double half_l2_m = 0.5 * metadata.length_m[1];
  std::vector<OmniWheel> wheels;
  for (int i = 0; i < kWheels; ++i) {
    OmniWheel w;
    w.name = kLayout[i].name;
    const double x_m = kLayout[i].x_sign * half_l1_m;
    const double y_m = kLayout[i].y_sign * half_l2_m;
    w.distance_m = std::hypot(x_m, y_m);
    w.angle_rad = std::atan2(y_m, x_m);
    w.radius_m = 0.5 * metadata.diameter_m[i];
    w.drive_angle_rad = DegToRad(kLayout[i].drive_angle_deg);
    w.roller_angle_rad = DegToRad(kLayout[i].roller_angle_deg);
    wheels.push_back(w);
  }
  const auto [r_min, r_max] =
      std::minmax_element(metadata.diameter_m.begin(), metadata.diameter_m.end());
  const double distance_m = wheels[0].distance_m;
  OmniBounds bounds;
  bounds.distance_m = {distance_m - kDistanceBound_m, distance_m + kDistanceBound_m};
  bounds.radius_m = {0.5 * *r_min * (1.0 - kRadiusBound), 0.5 * *r_max * (1.0 + kRadiusBound)};
  bounds.angle_offset_rad = {DegToRad(-kAngleBound_deg), DegToRad(kAngleBound_deg)};
  return MakeOmniModel("optiodom_omni4", wheels, bounds);
}

Omni4ImportResult ImportOptiOdomOmni4(const std::vector<std::string>& session_dirs,
                                      const std::string& out_dir, bool force,
                                      bool skip_mapping_check) {
  const std::vector<OptiOdomOmni4Session> sessions = optiodom::ReadSessions<OptiOdomOmni4Session>(
      session_dirs, out_dir, force, ReadOptiOdomOmni4Session);
  const OptiOdomOmni4Metadata nominal =
      optiodom::MajorityRobot(sessions, std::equal_to<OptiOdomOmni4Metadata>()).metadata;
  Omni4ImportResult result;
  for (const auto& s : sessions) {
    if (!(s.metadata == nominal)) {
      result.notes.push_back("session " + s.name +
                             " declares other nominal lengths or diameters (perturbed starting "
                             "values, same robot): the common ones are used");
    }
  }
  const RobotModelPtr model = OptiOdomOmni4NominalModel(nominal);
  std::vector<RunLog> all_runs;
  for (const auto& s : sessions) all_runs.insert(all_runs.end(), s.runs.begin(), s.runs.end());
  result.channel_order = CheckImportedChannelOrder(all_runs, *model, skip_mapping_check);
  optiodom::CheckUniqueRunIds(all_runs, out_dir);
  const FinalPoseErrors nominal_errors =
      EvaluateFinalPoseErrors(*model, model->robot().nominal, AlignRuns(all_runs));
  optiodom::DatasetText text;
  text.encoder_csv = [&](std::size_t i) { return EncoderCsvText(all_runs[i], model->robot()); };
  text.ground_truth_csv = GroundTruthCsvText;
  optiodom::WriteDataset(all_runs, *model, text, out_dir, force, session_dirs);
  result.num_sessions = static_cast<int>(sessions.size());
  result.num_runs = static_cast<int>(all_runs.size());
  result.nominal_mean_cf = nominal_errors.cf;
  return result;
}

}  // namespace fitcal::tools
