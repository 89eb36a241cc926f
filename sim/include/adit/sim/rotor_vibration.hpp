#pragma once
// A multirotor's vibration as its IMU feels it: each rotor shakes the frame at
// its blade-pass frequency (revolutions per second × blades; a small
// quadcopter's 2-blade props at 4500-6000 rpm hover give 150-200 Hz), in the
// accelerometer (mostly along the thrust axis) and a little in the gyroscope.
// The rotors run at slightly different speeds (they balance the airframe), so
// their lines beat. The amplitudes are those at the IMU's sampler, after its
// mount and its (weak) anti-alias filter: a flight controller's logs show
// 1-3 m/s² at the blade-pass frequency on a soft-mounted IMU. Sampled at the
// IMU's instants, a 160 Hz line aliases to 40 Hz at 200 Hz and to 40 Hz at
// 100 Hz, as on a real IMU. The displacement is a few µm (2 m/s² at 150 Hz:
// 2.3 µm), so the trajectory does not carry it.

#include <cstdint>

#include <Eigen/Core>

namespace adit::sim {

struct RotorVibration {
  bool enabled = false;
  int rotors = 4;
  double blade_pass_hz = 160.0;  // mean over the rotors
  double spread = 0.04;          // each rotor within ±4 % of the mean (uniform, from the seed)
  double accel_mps2 = 1.0;       // amplitude of each rotor's line along the body z axis (x and y: half); 4 rotors: 1.4 m/s² rms, peaks to 4
  double gyro_radps = 0.01;      // amplitude of each rotor's line about each axis (0.6°/s)
};

struct VibrationSample {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // rad/s, body axes
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // m/s², body axes
};

// The vibration at time t (s); zero when disabled. Frequencies and phases
// come from the seed.
VibrationSample rotor_vibration(const RotorVibration& vibration, std::uint64_t seed, double t);

}  // namespace adit::sim
