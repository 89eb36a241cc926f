#pragma once
// One IMU reading out of a CAN bus that carries the accelerometer and the
// gyroscope in frames of their own (the simulator: 0x190 and, 100 µs later,
// 0x191; docs/CAN-AND-GPIO.md): each accelerometer frame is paired with the
// gyroscope frame within kWindow_s of it, whichever comes first, into one
// slam::ImuSample stamped at the accelerometer's time. An accelerometer
// without its gyroscope frame is still handed on (has_gyro false, counted
// unpaired); a gyroscope frame without its accelerometer frame is dropped
// (counted). Without gyroscope signals every accelerometer frame is a
// reading at once. Values stay in the IMU's axes here. A value type for the
// CAN thread: no allocation, no lock.

#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "adit/slam/motion_history.hpp"

namespace adit::daemon {

class CanImuPairing {
 public:
  static constexpr double kWindow_s = 0.005;  // half the period of a 100 Hz unit

  struct Result {
    std::optional<slam::ImuSample> reading;  // a reading ready for the odometry
    unsigned saturated_axes = 0;              // of `reading`: bits 0-2 accelerometer, 3-5 gyroscope
    bool accel_alone = false;                 // `reading` is an accelerometer frame whose gyroscope never came
    bool gyro_dropped = false;                // a gyroscope frame without its accelerometer was dropped
  };

  explicit CanImuPairing(bool gyro) : gyro_(gyro) {}

  // `saturated` bits 0-2: the axes at their encoding's limit.
  Result add_accel(double t, const Eigen::Vector3d& specific_force, unsigned saturated = 0);
  Result add_gyro(double t, const Eigen::Vector3d& angular_rate, unsigned saturated = 0);
  bool gyro() const { return gyro_; }

 private:
  struct Pending {
    double t = 0.0;
    Eigen::Vector3d value = Eigen::Vector3d::Zero();
    unsigned saturated = 0;
    bool held = false;
  };
  static bool near(double a, double b) { return a - b <= kWindow_s && b - a <= kWindow_s; }

  bool gyro_;
  Pending accel_;
  Pending rate_;
};

}  // namespace adit::daemon
