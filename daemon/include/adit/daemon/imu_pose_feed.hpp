#pragma once
// The pose at the IMU's rate, for a flight controller (slam/imu_extrapolator.hpp).
//
// In:   the odometry filter's state and covariance after each LiDAR-inertial scan
//       (anchor(), odometry thread), and every body-frame IMU reading as its
//       source hands it on (reading(), the source's own thread: the LiDAR
//       assembly thread for an Ouster's or a Livox's IMU, the CAN thread).
// Out:  the pose sink (PipelineSinks::imu_pose: LCM on aditd), called on the
//       source's thread with each reading's extrapolated state and its pose
//       covariance (body tangent [ρ; δθ], as the scan-rate pose's), and each
//       pose's latency from its reading's arrival (the datagram's or the CAN
//       frame's receipt) to the sink's return.
// The anchors cross threads through a lock-free hand-off that keeps the
// newest; the reading side allocates, locks and logs nothing.

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "adit/daemon/handoff.hpp"
#include "adit/slam/imu_extrapolator.hpp"

namespace adit::daemon {

// Latencies kept for the figures: the first 65 536 poses (11 min at 100 Hz).
inline constexpr std::size_t kImuPoseLatencyCapacity = std::size_t{1} << 16;

class ImuPoseFeed {
 public:
  using Sink = std::function<void(const slam::InertialState&, const slam::Matrix6d& covariance)>;

  // `sink` may be empty: the poses are then counted and timed only.
  ImuPoseFeed(const slam::ImuExtrapolatorConfig& config, Sink sink);

  // Odometry thread: the filter's state and covariance after a scan it corrected.
  void anchor(const slam::InertialState& state, const slam::Matrix18d& covariance);
  // The IMU source's thread: one reading, received at `received_mono_ns`.
  void reading(const slam::ImuSample& reading, std::int64_t received_mono_ns);

  std::uint64_t poses() const { return poses_.load(std::memory_order_relaxed); }
  // The source's thread only, or once it has ended.
  const std::vector<double>& latency_ms() const { return latency_ms_; }

 private:
  struct Anchor {
    slam::InertialState state;
    slam::Matrix18d covariance = slam::Matrix18d::Zero();
  };
  Handoff<Anchor> anchors_;
  slam::ImuExtrapolator extrapolator_;
  Sink sink_;
  std::atomic<std::uint64_t> poses_{0};
  std::vector<double> latency_ms_;
};

}  // namespace adit::daemon
