#include "adit/sim/imu.hpp"

#include <algorithm>
#include <cmath>

#include "adit/sim/hash_noise.hpp"

namespace adit::sim {
namespace {

constexpr std::uint64_t kBiasStream = 0x496D7542ULL;
constexpr std::uint64_t kNoiseStream = 0x496D754EULL;
constexpr double kGravity = 9.80665;

drivers::can::Frame accel_frame(std::int64_t time_us, std::uint32_t id, const Eigen::Vector3d& f, double lsb) {
  drivers::can::Frame frame;
  frame.time_us = time_us;
  frame.id = id;
  frame.length = 6;
  frame.set_interface_name("can0");
  for (int axis = 0; axis < 3; ++axis) {
    const long counts = std::clamp(std::lround(f(axis) / lsb), -32768L, 32767L);
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(counts));
    frame.data[static_cast<std::size_t>(2 * axis)] = static_cast<std::uint8_t>(u & 0xFF);
    frame.data[static_cast<std::size_t>(2 * axis + 1)] = static_cast<std::uint8_t>(u >> 8);
  }
  return frame;
}

}  // namespace

Eigen::Vector3d specific_force_at(const BodyTrack& body, std::size_t i) {
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
  const Eigen::Vector3d acceleration = dv * forward + s[i].speed_mps * s[i].yaw_rate_rps * left + az * Eigen::Vector3d::UnitZ();
  return s[i].orientation.conjugate() * (acceleration + Eigen::Vector3d(0.0, 0.0, kGravity));
}

ImuTruth simulate_imu(const BodyTrack& body, const ImuOptions& o, std::vector<drivers::can::Frame>& frames) {
  ImuTruth truth;
  for (int axis = 0; axis < 3; ++axis)
    truth.bias(axis) = o.bias_sigma_mps2 * gaussian(o.seed, kBiasStream, static_cast<std::uint64_t>(axis));
  const std::size_t samples = body.samples().size();
  if (samples < 3) return truth;
  const auto count = static_cast<std::uint64_t>(body.duration() * o.rate_hz);
  for (std::uint64_t k = 0; k <= count; ++k) {
    const double t = static_cast<double>(k) / o.rate_hz;
    const auto i = std::clamp<std::size_t>(static_cast<std::size_t>(std::lround(t * BodyTrack::kRate)), 1, samples - 2);
    Eigen::Vector3d f = specific_force_at(body, i) + truth.bias;
    for (int axis = 0; axis < 3; ++axis)
      f(axis) += o.noise_mps2 * gaussian(o.seed, kNoiseStream, 3 * k + static_cast<std::uint64_t>(axis));
    const std::int64_t time_us = (o.start_time_ns + std::llround((t + o.time_offset_s) * 1e9)) / 1000;
    frames.push_back(accel_frame(time_us + 300, o.id, f, o.lsb_mps2));  // after the wheels' two PDOs
  }
  return truth;
}

}  // namespace adit::sim
