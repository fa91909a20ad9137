#pragma once
// CDR encoders of the message types in io/rosbag2/ros_messages.h and std_msgs/msg/String, for the
// bags the tests write.

#include <cstdint>
#include <vector>

#include "io/rosbag2/ros_messages.h"
#include "tests/bags/test_messages.h"

namespace fitcal::io::rosbag2 {

// Encoders (little-endian CDR unless `big_endian`).
std::vector<std::uint8_t> EncodeJointState(const JointState& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodePoseStamped(const PoseStamped& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodeOdometry(const Odometry& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodeTfMessage(const TfMessage& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodeString(const StringMessage& msg, bool big_endian = false);

}  // namespace fitcal::io::rosbag2
