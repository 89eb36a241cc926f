#pragma once
// Counts the pose_t messages of one payload on its own LCM socket, as a
// tablet (or, on POSE_IMU, a flight controller) receives them, and keeps the
// stamp of the newest.

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "adit/pose_t.hpp"
#include "adit/protocol/channels.hpp"
#include "adit/protocol/checked_decode.hpp"

namespace adit::test {

class PoseCounter {
 public:
  PoseCounter(const std::string& url, const std::string& payload, protocol::Channel channel = protocol::Channel::pose)
      : lcm_(url) {
    lcm_.subscribe(protocol::channel_name(payload, channel), &PoseCounter::on_pose, this);
    thread_ = std::thread([this] {
      while (running_) lcm_.handleTimeout(20);
    });
  }
  ~PoseCounter() {
    running_ = false;
    thread_.join();
  }
  PoseCounter(const PoseCounter&) = delete;
  PoseCounter& operator=(const PoseCounter&) = delete;
  std::size_t count() const { return count_; }
  std::size_t valid() const { return valid_; }
  std::int64_t first_utime() const { return first_utime_; }  // 0 before the first pose
  std::int64_t last_utime() const { return last_utime_; }    // the sensor stamp of the newest pose

 private:
  void on_pose(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    pose_t pose;
    if (!protocol::checked_decode(rbuf->data, rbuf->data_size, pose)) return;
    if (count_ == 0) first_utime_ = pose.utime;
    last_utime_ = pose.utime;
    ++count_;
    if (pose.flags & pose_t::FLAG_VALID) ++valid_;
  }
  lcm::LCM lcm_;
  std::atomic<bool> running_{true};
  std::atomic<std::size_t> count_{0};
  std::atomic<std::size_t> valid_{0};
  std::atomic<std::int64_t> first_utime_{0};
  std::atomic<std::int64_t> last_utime_{0};
  std::thread thread_;
};

}  // namespace adit::test
