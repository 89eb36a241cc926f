// Accelerometer and gyroscope frames into one reading (can_imu_pairing.hpp).
#include "adit/daemon/can_imu_pairing.hpp"

namespace adit::daemon {

CanImuPairing::Result CanImuPairing::add_accel(double t, const Eigen::Vector3d& f, unsigned saturated) {
  Result out;
  if (!gyro_) {
    out.reading = slam::ImuSample{t, f, Eigen::Vector3d::Zero(), false};
    out.saturated_axes = saturated & 0x7U;
    return out;
  }
  if (rate_.held && near(t, rate_.t)) {  // its gyroscope frame came first
    out.reading = slam::ImuSample{t, f, rate_.value, true};
    out.saturated_axes = (saturated & 0x7U) | (rate_.saturated & 0x7U) << 3;
    rate_.held = false;
    return out;
  }
  if (accel_.held) {  // the previous accelerometer frame's gyroscope never came
    out.reading = slam::ImuSample{accel_.t, accel_.value, Eigen::Vector3d::Zero(), false};
    out.saturated_axes = accel_.saturated & 0x7U;
    out.accel_alone = true;
  }
  if (rate_.held) {  // a gyroscope frame too far from this one
    out.gyro_dropped = true;
    rate_.held = false;
  }
  accel_ = {t, f, saturated, true};
  return out;
}

CanImuPairing::Result CanImuPairing::add_gyro(double t, const Eigen::Vector3d& w, unsigned saturated) {
  Result out;
  if (!gyro_) return out;
  if (accel_.held && near(t, accel_.t)) {
    out.reading = slam::ImuSample{accel_.t, accel_.value, w, true};
    out.saturated_axes = (accel_.saturated & 0x7U) | (saturated & 0x7U) << 3;
    accel_.held = false;
    return out;
  }
  if (accel_.held) {  // too far from this gyroscope frame: hand it on alone
    out.reading = slam::ImuSample{accel_.t, accel_.value, Eigen::Vector3d::Zero(), false};
    out.saturated_axes = accel_.saturated & 0x7U;
    out.accel_alone = true;
    accel_.held = false;
  }
  if (rate_.held) out.gyro_dropped = true;  // two gyroscope frames in a row: the older had no accelerometer
  rate_ = {t, w, saturated, true};
  return out;
}

}  // namespace adit::daemon
