#pragma once
// The IMU-rate pose on LCM (ADIT/<payload>/POSE_IMU, pose_t, docs/PROTOCOL.md):
// sent at once on the calling thread (the IMU source's, through
// PipelineSinks::imu_pose) by an LCM instance of its own that only publishes,
// so the pose waits for no queue and no other thread. The exception to the
// endpoint's one-thread rule (lcm_endpoint.hpp), for a flight controller's
// latency: a queue drained every 2 ms by the endpoint would cost up to that.
//
// One producer thread at a time; the message and its buffer are reused, so
// nothing is allocated per pose.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "adit/slam/inertial_filter.hpp"

namespace adit::daemon {

class ImuPosePublisher {
 public:
  // Throws std::runtime_error when LCM cannot open `lcm_url`.
  ImuPosePublisher(const std::string& lcm_url, const std::string& payload_id);
  ~ImuPosePublisher();
  ImuPosePublisher(const ImuPosePublisher&) = delete;
  ImuPosePublisher& operator=(const ImuPosePublisher&) = delete;

  // The extrapolated state as pose_t: utime its time, flags VALID, no
  // covariance (the scan-rate POSE carries it), no session id (POSE does).
  void publish(const slam::InertialState& state);
  std::uint64_t published() const { return published_.load(std::memory_order_relaxed); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<std::uint64_t> published_{0};
};

}  // namespace adit::daemon
