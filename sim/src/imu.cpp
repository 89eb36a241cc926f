#include "adit/sim/imu.hpp"

#include <algorithm>
#include <cmath>

#include "adit/sim/hash_noise.hpp"
#include "adit/sim/imu_kinematics.hpp"

namespace adit::sim {
namespace {

// Streams of the counter-based draws: index 3·k + axis for sample k.
constexpr std::uint64_t kAccelTurnOnStream = 0x496D7542ULL;  // the robot accelerometer's constant bias, as before
constexpr std::uint64_t kAccelNoiseStream = 0x496D754EULL;
constexpr std::uint64_t kAccelWalkStream = 0x496D7557ULL;
constexpr std::uint64_t kGyroTurnOnStream = 0x47797242ULL;
constexpr std::uint64_t kGyroNoiseStream = 0x4779724EULL;
constexpr std::uint64_t kGyroWalkStream = 0x47797257ULL;

Eigen::Vector3d draw3(const NoiseStream& s, std::uint64_t k) {
  return {s.gaussian(3 * k), s.gaussian(3 * k + 1), s.gaussian(3 * k + 2)};
}

}  // namespace

Eigen::Vector3d wheeled_acceleration(const BodyTrack& body, std::size_t i) {
  const auto& s = body.samples();
  const double dt = 1.0 / BodyTrack::kRate;
  const std::size_t last = s.size() - 1;
  const auto at = [&](std::ptrdiff_t k) { return std::clamp<std::ptrdiff_t>(k, 0, static_cast<std::ptrdiff_t>(last)); };
  const auto index = static_cast<std::ptrdiff_t>(i);
  // The route's positions are a polyline of 5 cm pieces, so their second
  // differences are spikes at the corners. A vehicle on its wheels
  // accelerates along its heading by dv/dt and across it by v·ω; the floor's
  // bumps add the vertical part (smooth). Speed and yaw rate are the sim's
  // wheel inputs, central differences over ±25 ms.
  constexpr std::ptrdiff_t kHalf = 5;
  const std::size_t a = static_cast<std::size_t>(at(index - kHalf)), b = static_cast<std::size_t>(at(index + kHalf));
  const double dv = b > a ? (s[b].speed_mps - s[a].speed_mps) / (static_cast<double>(b - a) * dt) : 0.0;
  const std::size_t z0 = static_cast<std::size_t>(at(index - 1)), z1 = static_cast<std::size_t>(at(index + 1));
  const double az = z1 > z0 + 1 ? (s[z1].position.z() - 2.0 * s[i].position.z() + s[z0].position.z()) / (dt * dt) : 0.0;
  Eigen::Vector3d forward = s[i].orientation * Eigen::Vector3d::UnitX();
  forward.z() = 0.0;
  forward.normalize();
  const Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(forward);
  return dv * forward + s[i].speed_mps * s[i].yaw_rate_rps * left + az * Eigen::Vector3d::UnitZ();
}

Eigen::Vector3d specific_force_at(const BodyTrack& body, std::size_t i) {
  return body.samples()[i].orientation.conjugate() *
         (wheeled_acceleration(body, i) + Eigen::Vector3d(0.0, 0.0, kStandardGravity));
}

std::vector<ImuSample> simulate_imu(const BodyTrack& body, const ImuOptions& o) {
  std::vector<ImuSample> out;
  if (body.samples().size() < 3 || !(o.rate_hz > 0.0)) return out;
  const double period = 1.0 / o.rate_hz;
  const ImuNoise& n = o.noise;
  const NoiseStream accel_noise(o.seed, kAccelNoiseStream), accel_walk(o.seed, kAccelWalkStream);
  const NoiseStream gyro_noise(o.seed, kGyroNoiseStream), gyro_walk(o.seed, kGyroWalkStream);
  Eigen::Vector3d accel_bias = n.accel_turn_on_sigma * draw3(NoiseStream(o.seed, kAccelTurnOnStream), 0);
  Eigen::Vector3d gyro_bias = n.gyro_turn_on_sigma * draw3(NoiseStream(o.seed, kGyroTurnOnStream), 0);
  // Per sample: white noise σ = density·√rate; the bias walks by walk·√period.
  const double accel_white = n.accel_noise_density * std::sqrt(o.rate_hz);
  const double gyro_white = n.gyro_noise_density * std::sqrt(o.rate_hz);
  const double accel_step = n.accel_bias_walk * std::sqrt(period);
  const double gyro_step = n.gyro_bias_walk * std::sqrt(period);
  const auto count = static_cast<std::uint64_t>(std::floor(body.duration() * o.rate_hz + 1e-9));
  out.reserve(count + 1);
  const Eigen::Matrix3d axes = o.mount.linear();
  for (std::uint64_t k = 0; k <= count; ++k) {
    if (k > 0) {
      accel_bias += accel_step * draw3(accel_walk, k);
      gyro_bias += gyro_step * draw3(gyro_walk, k);
    }
    ImuSample s;
    s.t = static_cast<double>(k) * period;
    s.stamp = s.t + o.time_offset_s;
    const ImuKinematics truth = imu_kinematics(body, s.t, period, o.mount, o.motion);
    const VibrationSample shake = rotor_vibration(o.vibration, o.seed, s.t);
    s.gyro = truth.angular_rate + axes.transpose() * shake.gyro + gyro_bias + gyro_white * draw3(gyro_noise, k);
    s.accel = truth.specific_force + axes.transpose() * shake.accel + accel_bias + accel_white * draw3(accel_noise, k);
    s.gyro_bias = gyro_bias;
    s.accel_bias = accel_bias;
    out.push_back(s);
  }
  return out;
}

}  // namespace adit::sim
