#include "adit/sim/truth.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/slam/tum.hpp"

namespace adit::sim {

void write_tum(const std::filesystem::path& file, const BodyTrack& body, const Eigen::Isometry3d& frame,
               std::int64_t start_time_ns) {
  slam::TumWriter out(file);
  const auto& samples = body.samples();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = samples[i].position;
    pose.linear() = samples[i].orientation.toRotationMatrix();
    const std::int64_t ns = start_time_ns + static_cast<std::int64_t>(i) * static_cast<std::int64_t>(1e9 / BodyTrack::kRate);
    out.write(ns, pose * frame);
  }
  if (!out.flush()) throw InputError(file.string(), "", "could not write the trajectory");
}

void write_imu_truth(const std::filesystem::path& file, std::span<const ImuSample> samples,
                     std::int64_t start_time_ns, double time_offset_s) {
  std::ofstream out(file, std::ios::trunc);
  out << fmt::format("# adit sim: the IMU's true biases per sample, in its axes (rad/s, m/s^2); t on the truth files' "
                     "clock, the IMU stamps t + {} s\n",
                     time_offset_s);
  out << "t,gyro_bias_x,gyro_bias_y,gyro_bias_z,accel_bias_x,accel_bias_y,accel_bias_z\n";
  for (const ImuSample& s : samples) {
    const std::int64_t ns = start_time_ns + std::llround(s.t * 1e9);
    out << fmt::format("{}.{:09},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}\n", ns / 1'000'000'000, ns % 1'000'000'000,
                       s.gyro_bias.x(), s.gyro_bias.y(), s.gyro_bias.z(), s.accel_bias.x(), s.accel_bias.y(),
                       s.accel_bias.z());
  }
  if (!out) throw InputError(file.string(), "", "could not write the IMU truth");
}

}  // namespace adit::sim
