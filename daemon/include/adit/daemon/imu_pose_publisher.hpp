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
#include <optional>
#include <string>

#include "adit/config/config.hpp"
#include "adit/slam/inertial_filter.hpp"

namespace adit::daemon {

class ImuPosePublisher {
 public:
  // Throws std::runtime_error when LCM cannot open `lcm_url`.
  ImuPosePublisher(const std::string& lcm_url, const std::string& payload_id);
  ~ImuPosePublisher();
  ImuPosePublisher(const ImuPosePublisher&) = delete;
  ImuPosePublisher& operator=(const ImuPosePublisher&) = delete;

  // The extrapolated state as pose_t: utime its time, flags VALID, the
  // covariance (body tangent [ρ; δθ], as POSE's), no session id (POSE has it).
  void publish(const slam::InertialState& state, const slam::Matrix6d& covariance);
  std::uint64_t published() const { return published_.load(std::memory_order_relaxed); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<std::uint64_t> published_{0};
};

// Why `config`'s IMU-rate pose may miss its 2 ms latency, or nullopt: the
// pose goes out on the thread that reads the IMU, and only a SCHED_FIFO
// thread keeps it under 2 ms beside the odometry and mapping on a busy core
// (p99 0.26-0.32 ms against 1.2-2.4 ms, docs/decisions/041-imu-rate-pose.md).
// A LiDAR's own IMU is read on the receiver thread (`threads.receiver`); a
// CAN IMU on the CAN thread, which has no real-time setting. Nullopt too when
// no IMU-rate pose is published.
std::optional<std::string> imu_pose_latency_warning(const config::Config& config);

}  // namespace adit::daemon
