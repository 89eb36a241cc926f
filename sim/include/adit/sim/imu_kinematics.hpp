#pragma once
// The true motion an IMU mounted on a BodyTrack feels, without any sensor
// error: the angular rate and the specific force in the IMU's axes.
//
// Angular rate: the mean over the sample period T centred on t, the rotation
// vector of R(t − T/2)ᵀ·R(t + T/2) divided by T. Integrated sample by sample
// (q ← q·exp(ω·T)) it gives the track's orientation exactly at the half
// periods, whatever the rate: what an integrating MEMS gyro's filtered output
// approximates, without its group delay.
// Specific force at the IMU origin r (body frame):
//   f = Rᵀ(a + g·ẑ) + α × r + ω × (ω × r)
// with a the body origin's acceleration in the world, α the angular
// acceleration (difference of the mean rates over one period).
// `wheeled`: a from the robot's wheel inputs (its positions are a polyline
// of 5 cm pieces: second differences would be spikes at the corners).
// `smooth`: a = (p(t+h) − 2p(t) + p(t−h))/h², h = kSmoothSpan: exactly the
// acceleration of the path smoothed by a triangle of ±h (Δ²p/h² is that
// convolution), which stays within about a millimetre of the path on the
// drone's and the walker's tracks and cancels the 200 Hz samples' kinks.

#include <Eigen/Geometry>

#include "adit/sim/body_track.hpp"
#include "adit/sim/imu.hpp"

namespace adit::sim {

inline constexpr double kSmoothSpan = 0.05;  // s

struct ImuKinematics {
  Eigen::Vector3d angular_rate = Eigen::Vector3d::Zero();    // rad/s, IMU axes
  Eigen::Vector3d specific_force = Eigen::Vector3d::Zero();  // m/s², IMU axes
};

// The body's mean angular rate over [t − period/2, t + period/2], body axes.
Eigen::Vector3d body_angular_rate(const BodyTrack& body, double t, double period_s);
// The body origin's acceleration in the world at t (no gravity).
Eigen::Vector3d body_acceleration(const BodyTrack& body, double t, ImuMotion motion);

ImuKinematics imu_kinematics(const BodyTrack& body, double t, double period_s, const Eigen::Isometry3d& mount,
                             ImuMotion motion);

}  // namespace adit::sim
