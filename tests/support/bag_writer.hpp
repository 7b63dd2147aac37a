#pragma once
// Test fixtures: a simulated IMU written as ROS 1 bags, ROS 2 SQLite bags and MCAP files (each
// format as its writers lay it out), and as the CSV `rostopic echo -p` would export.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rwcalc::test {

struct ImuSample {
  std::int64_t stamp_ns = 0, receive_ns = 0;
  double gyro[3] = {}, accel[3] = {};  // rad/s, m/s²
};

/// A static IMU of white noise at `rate_hz` from Unix time 1.7e9 s; receive times lag the stamps
/// by 0.1 to 0.3 ms (seeded).
std::vector<ImuSample> simulated_imu(std::size_t n, double rate_hz, unsigned seed = 11);

/// One topic of a bag; `imu` false writes std_msgs/String messages.
struct BagTopicSpec {
  std::string name;
  std::vector<ImuSample> messages;
  bool imu = true;
};

/// compression: "none", "bz2", "lz4" (ROS 1); "", "zstd", "lz4" (MCAP). Messages per chunk as given.
void write_ros1_bag(const std::filesystem::path& path, const std::vector<BagTopicSpec>& topics,
                    const std::string& compression = "none", std::size_t per_chunk = 1000);
void write_ros2_db3(const std::filesystem::path& path, const std::vector<BagTopicSpec>& topics);
void write_mcap(const std::filesystem::path& path, const std::vector<BagTopicSpec>& topics,
                const std::string& compression = "", std::size_t per_chunk = 1000, bool summary = true);

/// The `rostopic echo -p` CSV of the samples: %time, field.header.seq, field.header.stamp,
/// field.header.frame_id, orientation and covariances, angular_velocity, linear_acceleration.
std::string rostopic_csv(const std::vector<ImuSample>& samples);

}  // namespace rwcalc::test
