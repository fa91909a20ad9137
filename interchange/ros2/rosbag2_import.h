#pragma once
// What `fitcal import rosbag2 <bag> --out <data set> --robot <robot.yaml> --ground-truth <topic>`
// (cli/import_rosbag2.h) reads and decides: a rosbag2 recording (sqlite3 or MCAP, split or not;
// io/rosbag2/) -> a fitcal data set (README.md "Data set format"): robot.yaml (the robot file as
// given), dataset.yaml, and per run runs/<id>_encoders.csv and runs/<id>_ground_truth.csv.
//
// Encoders. One sensor_msgs/msg/JointState topic; the robot's channels are read from the joints
// named by --joints (robot channel order; default: the channel names themselves). With positions
// in the messages (cumulative wheel angles, what joint_state_broadcaster publishes) the CSV holds
// the mean rate of each interval, (angle(k) - angle(k-1)) / (t(k) - t(k-1)): exact, whatever the
// spacing. With velocities only, the instantaneous readings at both ends are averaged (the
// trapezoid rule: second order in the interval, the best a rate sampled at the ends gives). An
// angle channel (tricycle steering) is the position as read at the row's time.
//
// Time. t = 0 is the bag's first recording time; t is in seconds (ns resolution in the CSV). The
// default stamp is the header stamp: the time the driver measured the sample. The recording
// time adds the transport latency, which differs between the encoder and the ground-truth topics
// (a mocap pose crosses a network, joint states do not), so with it the two streams are offset
// by a few ms and jitter - a pose error of speed x offset at every final pose. --stamp recorded
// is for drivers that leave the header stamp empty or on another clock.
//
// Runs. --runs t0:t1,t2:t3 (s, same clock) cuts the given spans; --split-at-rest S cuts at the
// middle of every rest (all wheels slower than rest_rate) lasting at least S seconds and keeps the
// pieces in which the robot moves; neither: the whole bag is one run. Run i (1-based) gets id
// `<label>-NN`, trajectory label <label> (default: the bag's name) and repetition i, so
// `fitcal fit --train-reps` chooses runs by number.
//
// Real recordings (docs/ros2.md, "Import"): other nodes' JointStates skipped, wrapped positions
// unwrapped, non-unit quaternions and (with --stamp recorded) a clock stepping back refused, and
// the data set read back by `fit`'s loader before it is committed. A ground truth tracking
// another frame than --base-frame gets its nominal `ground_truth_frame` from /tf_static.

#include <string>
#include <vector>

#include "fit/final_pose_errors.h"
#include "io/rosbag2/bag_streams.h"
#include "odometry/run_log.h"

namespace fitcal {

struct ImportRosbag2Options {
  std::string bag;    // bag directory, metadata.yaml, or one .db3 / .mcap file
  std::string out;    // data set directory to write
  std::string robot;  // robot YAML (any registered model)
  std::string encoders = "/joint_states";
  std::vector<std::string> joints;  // robot channel order; empty: the channel names
  std::string ground_truth;         // topic
  std::string ground_truth_frames;  // "parent:child", for a tf2_msgs/msg/TFMessage topic (and a
                                    // PoseStamped's: the child names the frame it tracks)
  std::string base_frame = "base_link";  // the robot's base frame in /tf_static
  std::string stamp = "header";     // header | recorded
  std::string runs;                 // "t0:t1,t2:t3" (s since the bag's start)
  double split_at_rest_s = 0.0;     // > 0: cut at rests at least this long
  double rest_rate_rad_s = 0.02;    // a wheel slower than this is at rest
  std::string label;                // trajectory label; empty: the bag's name
  bool force = false;               // replace an existing --out
  bool quiet = false;
  // Write even when another channel order or sign explains the ground truth far better than the
  // one --joints gives (diagnosis/import_channel_order.h; exit 4 otherwise, as every import).
  bool skip_mapping_check = false;
};

struct Rosbag2Import {
  io::rosbag2::BagStreams streams;
  std::vector<RunLog> runs;  // as fitcal will load them
  // Per run, what the encoder CSV holds: t (s), and row-major one row per stamp of one value per
  // robot channel (robot channel order).
  std::vector<std::vector<double>> encoder_t_s;
  std::vector<std::vector<double>> encoder_values;
  // What the import repaired (wrapped joint positions), one line each.
  std::vector<std::string> notes;
  // Appended to the robot YAML the data set holds: the nominal `ground_truth_frame:` of a ground
  // truth that tracks a sensor, from the bag's /tf_static (io/rosbag2/static_transforms.h).
  std::string robot_yaml_addition;
  FinalPoseErrors nominal;  // Palacin Eq. 14 over the runs written, at the nominal (ImportRosbag2)
};

// Reads the bag and cuts the runs, writing nothing. Throws io::InputError for a bad bag or bad
// runs (file and what), std::invalid_argument for bad options.
Rosbag2Import ReadRosbag2Import(const ImportRosbag2Options& options);

// The whole import of `fitcal import rosbag2` (rosbag2_dataset.cc): `out` checked against the
// overwrite rule and the bag (an input), the bag read, the data set written (staged, refused
// unless the loader `fit` uses accepts it) and the runs' nominal CF. Throws UsageError for an
// `out` it may not write, io::InputError for a bad bag or data set; nothing is written then.
Rosbag2Import ImportRosbag2(const ImportRosbag2Options& options);

}  // namespace fitcal
