#pragma once
// Ground-truth trajectories in the TUM RGB-D benchmark format (Sturm et al.,
// IROS 2012): one line per pose, "time tx ty tz qx qy qz qw", time in seconds
// on the common clock, the pose of the frame in the world.

#include <cstdint>
#include <filesystem>
#include <span>

#include <Eigen/Geometry>

#include "adit/sim/body_track.hpp"
#include "adit/sim/imu.hpp"

namespace adit::sim {

// Writes every trajectory sample of body × frame (frame = identity: the body,
// the extrinsics: the sensor). Throws adit::InputError on I/O failure.
void write_tum(const std::filesystem::path& file, const BodyTrack& body, const Eigen::Isometry3d& frame,
               std::int64_t start_time_ns);

// The IMU's true biases, one line per sample (truth_imu.csv):
//   # comment lines first, then the header
//   t,gyro_bias_x,gyro_bias_y,gyro_bias_z,accel_bias_x,accel_bias_y,accel_bias_z
// t in seconds on the truth files' clock (the LiDAR's; the sample's IMU stamp is
// t + the IMU's time offset), biases in rad/s and m/s² in the IMU's axes: what
// the IMU's readings carry on top of the true motion, noise and vibration.
void write_imu_truth(const std::filesystem::path& file, std::span<const ImuSample> samples,
                     std::int64_t start_time_ns, double time_offset_s);

}  // namespace adit::sim
