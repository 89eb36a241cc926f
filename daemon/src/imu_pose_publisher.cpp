#include "adit/daemon/imu_pose_publisher.hpp"

#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include "adit/protocol/channels.hpp"
#include "adit/pose_t.hpp"

namespace adit::daemon {

struct ImuPosePublisher::Impl {
  lcm::LCM lcm;
  std::string channel;
  adit::pose_t message;
  std::vector<std::uint8_t> buffer;
  std::int64_t seq = 0;

  Impl(const std::string& url, const std::string& payload_id)
      : lcm(url), channel(protocol::channel_name(payload_id, protocol::Channel::imu_pose)) {
    if (!lcm.good()) throw std::runtime_error(fmt::format("LCM cannot open '{}'", url));
    message.schema = 1;
    message.flags = adit::pose_t::FLAG_VALID;
    buffer.resize(static_cast<std::size_t>(message.getEncodedSize()));  // fixed: the session id stays empty
  }
};

ImuPosePublisher::ImuPosePublisher(const std::string& lcm_url, const std::string& payload_id)
    : impl_(std::make_unique<Impl>(lcm_url, payload_id)) {}

ImuPosePublisher::~ImuPosePublisher() = default;

void ImuPosePublisher::publish(const slam::InertialState& state, const slam::Matrix6d& covariance) {
  Impl& i = *impl_;
  adit::pose_t& m = i.message;
  m.utime = static_cast<std::int64_t>(state.t * 1e6);
  m.seq = i.seq++;
  const Eigen::Vector3d& p = state.pose.translation();
  const Eigen::Quaterniond q(state.pose.linear());
  m.position[0] = p.x();
  m.position[1] = p.y();
  m.position[2] = p.z();
  m.orientation[0] = q.w();
  m.orientation[1] = q.x();
  m.orientation[2] = q.y();
  m.orientation[3] = q.z();
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m.covariance[6 * r + c] = covariance(r, c);  // row-major, as POSE's
  const int size = m.encode(i.buffer.data(), 0, static_cast<int>(i.buffer.size()));
  if (size > 0 && i.lcm.publish(i.channel, i.buffer.data(), static_cast<unsigned>(size)) == 0)
    published_.fetch_add(1, std::memory_order_relaxed);
}

std::optional<std::string> imu_pose_latency_warning(const config::Config& config) {
  if (!config.imu.enabled || !(config.imu.pose_horizon_s > 0.0)) return std::nullopt;
  if (config.imu.source == config::ImuSource::can)
    return "POSE_IMU: a CAN IMU's readings are read on the CAN thread, which runs with the default scheduler: "
           "the IMU-rate pose may come later than 2 ms after a reading on a busy core (decision 041)";
  if (config.threads.receiver.policy == config::SchedPolicy::fifo) return std::nullopt;
  return "POSE_IMU: the LiDAR's IMU is read on the receiver thread, which runs with the default scheduler: the "
         "IMU-rate pose may come later than 2 ms after a reading on a busy core; set threads.receiver: "
         "{policy: fifo, priority: 50} (decision 041)";
}

}  // namespace adit::daemon
