#pragma once
// Keyframes from the mapping thread to the loop-closure thread. No capacity
// and under a mutex: a keyframe comes about once a metre, the graph needs
// every one (a dropped keyframe would cut the odometry chain), and neither
// side is the odometry thread. push() never waits for the consumer. Behind a
// live source the consumer keeps it short by skipping loop searches while
// it is long (loop_closure_stage.hpp).

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

namespace adit::daemon {

struct KeyframeItem {
  std::int64_t stamp_ns = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // where the map placed it
  std::vector<Eigen::Vector3f> points;                      // body frame, deskewed, downsampled
};

class KeyframeQueue {
 public:
  void push(KeyframeItem item) {
    {
      const std::lock_guard lock(mutex_);
      items_.push_back(std::move(item));
    }
    ready_.notify_one();
  }
  // The producer is done: pop() returns what is left, then nothing.
  void close() {
    {
      const std::lock_guard lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }
  // Waits up to `timeout` for an item; nullopt when none came (or closed and empty).
  template <typename Duration>
  std::optional<KeyframeItem> pop(Duration timeout) {
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return !items_.empty() || closed_; });
    if (items_.empty()) return std::nullopt;
    KeyframeItem item = std::move(items_.front());
    items_.pop_front();
    return item;
  }
  bool closed_and_empty() const {
    const std::lock_guard lock(mutex_);
    return closed_ && items_.empty();
  }
  std::size_t depth() const {
    const std::lock_guard lock(mutex_);
    return items_.size();
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<KeyframeItem> items_;
  bool closed_ = false;
};

}  // namespace adit::daemon
