#pragma once
// Keyframes from the mapping thread to the loop-closure thread, under a mutex:
// a keyframe comes about once a metre, the graph needs every one (a dropped
// keyframe would cut the odometry chain), and neither side is the odometry
// thread. With no capacity (behind a live source) push() never waits; the
// consumer keeps the queue short by skipping loop searches while it is long
// (loop_closure_stage.hpp). With a capacity (a replay, which searches every
// keyframe) push() waits for room: as fast as it goes, the mapping ran ahead
// of the graph and the queue held about 1,600 keyframe scans (45 MB) by the
// end of the 30-minute drive (decision 071).

#include <chrono>
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
  bool anchored = false;  // mapped while the odometry was anchored to a prior map (the graph holds it there)
};

class KeyframeQueue {
 public:
  // 0: no capacity.
  explicit KeyframeQueue(std::size_t capacity = 0) : capacity_(capacity) {}

  // Queues `item`. While `capacity` items wait, it waits for room, calling
  // `idle()` every kRoomPoll: the producer's heartbeat, which says false once
  // the pipeline stops; then it queues the item anyway (none is ever dropped).
  template <typename Idle>
  void push(KeyframeItem item, Idle&& idle) {
    {
      std::unique_lock lock(mutex_);
      while (capacity_ > 0 && !room_.wait_for(lock, kRoomPoll, [&] { return room_or_closed(); })) {
        lock.unlock();
        const bool wait_on = idle();
        lock.lock();
        if (!wait_on) break;
      }
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
    room_.notify_all();
  }
  // Waits up to `timeout` for an item; nullopt when none came (or closed and empty).
  template <typename Duration>
  std::optional<KeyframeItem> pop(Duration timeout) {
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return !items_.empty() || closed_; });
    if (items_.empty()) return std::nullopt;
    KeyframeItem item = std::move(items_.front());
    items_.pop_front();
    lock.unlock();
    room_.notify_one();
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
  static constexpr std::chrono::milliseconds kRoomPoll{100};
  bool room_or_closed() const { return items_.size() < capacity_ || closed_; }  // under mutex_

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::condition_variable room_;
  std::deque<KeyframeItem> items_;
  bool closed_ = false;
};

}  // namespace adit::daemon
