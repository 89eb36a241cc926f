#include "adit/sim/rotor_vibration.hpp"

#include <cmath>
#include <numbers>

#include "adit/sim/hash_noise.hpp"

namespace adit::sim {

VibrationSample rotor_vibration(const RotorVibration& v, std::uint64_t seed, double t) {
  VibrationSample out;
  if (!v.enabled) return out;
  const NoiseStream draw(seed, 0x526F746FULL);
  const Eigen::Vector3d accel_share(0.5, 0.5, 1.0);
  for (int r = 0; r < v.rotors; ++r) {
    const auto base = static_cast<std::uint64_t>(r) * 8;
    const double hz = v.blade_pass_hz * (1.0 + v.spread * (2.0 * draw.uniform(base) - 1.0));
    const double turn = 2.0 * std::numbers::pi * hz * t;
    for (int axis = 0; axis < 3; ++axis) {
      const double accel_phase = 2.0 * std::numbers::pi * draw.uniform(base + 1 + static_cast<std::uint64_t>(axis));
      const double gyro_phase = 2.0 * std::numbers::pi * draw.uniform(base + 4 + static_cast<std::uint64_t>(axis));
      out.accel(axis) += v.accel_mps2 * accel_share(axis) * std::sin(turn + accel_phase);
      out.gyro(axis) += v.gyro_radps * std::sin(turn + gyro_phase);
    }
  }
  return out;
}

}  // namespace adit::sim
