#include "adit/daemon/imu_pose_feed.hpp"

#include "adit/common/clock.hpp"

namespace adit::daemon {

namespace {
// A scan's anchor is taken within one IMU period; a few slots let the
// odometry run ahead of a replay's readings without waiting.
constexpr std::size_t kAnchorSlots = 4;
}  // namespace

ImuPoseFeed::ImuPoseFeed(const slam::ImuExtrapolatorConfig& config, Sink sink)
    : anchors_(kAnchorSlots, Overflow::drop_oldest, [] { return Anchor{}; }),
      extrapolator_(config),
      sink_(std::move(sink)) {
  latency_ms_.reserve(kImuPoseLatencyCapacity);
}

void ImuPoseFeed::anchor(const slam::InertialState& state, const slam::Matrix18d& covariance) {
  Anchor* slot = anchors_.acquire();  // never waits: drops the oldest
  if (slot == nullptr) return;
  slot->state = state;
  slot->covariance = covariance;
  anchors_.publish(slot);
}

void ImuPoseFeed::reading(const slam::ImuSample& reading, std::int64_t received_mono_ns) {
  // Every anchor handed over, oldest first: the newest one counts.
  while (Anchor* a = anchors_.take()) {
    extrapolator_.anchor(a->state, a->covariance);
    anchors_.release(a);
  }
  const std::optional<slam::InertialState> state = extrapolator_.add(reading);
  if (!state) return;
  if (sink_) sink_(*state, extrapolator_.pose_covariance());
  poses_.fetch_add(1, std::memory_order_relaxed);
  if (latency_ms_.size() < kImuPoseLatencyCapacity)
    latency_ms_.push_back(1e-6 * static_cast<double>(monotonic_ns() - received_mono_ns));
}

}  // namespace adit::daemon
