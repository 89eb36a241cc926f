#pragma once
// An IMU as the odometry sees it, whatever carries it (config `imu.source`):
// the CAN bus (CanFeed: accelerometer and gyroscope signals) or the Ouster
// LiDAR's own IMU packets (OusterImu, UDP port 7503). Either way the readings
// are in the body frame (the mounting's rotation applied), stamped on the
// LiDAR clock (the clock of LidarScan::start_time_ns, imu.time_offset_s
// removed), in slam::ImuSample; the lever arm is not applied to them: it is
// carried in mounting() for the consumer (a rotating body's accelerometer
// away from its centre reads ω × (ω × r) + α × r more, which only the
// odometry's state can remove).
//
// The source's reading thread hands readings over through a lock-free
// hand-off; the odometry thread calls catch_up() and reads history(). Only
// that thread touches history().

#include <functional>

#include <Eigen/Core>

#include "adit/daemon/imu_stats.hpp"
#include "adit/slam/motion_history.hpp"

namespace adit::daemon {

class ImuPoseFeed;  // imu_pose_feed.hpp

// The IMU's pose in the body frame.
struct ImuMounting {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // IMU axes → body axes (already applied to readings)
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();    // the IMU's origin in the body frame (the lever arm)
};

class ImuSource {
 public:
  virtual ~ImuSource() = default;
  // Odometry thread: moves the readings handed over into history(), oldest
  // first. Live: everything handed over so far. A replay: until they reach
  // `until_t` (s, LiDAR clock) or the source ends, calling `idle` while
  // waiting (false: give up).
  virtual void catch_up(double until_t, const std::function<bool()>& idle) = 0;
  // Odometry thread: the recent readings.
  virtual const slam::ImuHistory& history() const = 0;
  virtual const ImuMounting& mounting() const = 0;
  virtual const ImuStats& imu_stats() const = 0;
  // "can" or "ouster", for the status and the reports.
  virtual const char* imu_name() const = 0;

  // Before the source's thread starts: every reading handed to the odometry
  // also goes to `feed`, on the source's thread (the IMU-rate pose).
  void feed_poses_to(ImuPoseFeed* feed) { pose_feed_ = feed; }

 protected:
  ImuPoseFeed* pose_feed_ = nullptr;
};

// Readings a history keeps: 40 s at 100 Hz, 10 s at 400 Hz.
inline constexpr std::size_t kImuHistoryCapacity = 4096;

}  // namespace adit::daemon
