#pragma once
// A bounded single-producer single-consumer queue: the hand-off from a
// pipeline thread to the publisher without locks or allocation on push
// (a full queue refuses the item; the producer counts the drop).
// Lamport's ring with acquire/release indices.

#include <atomic>
#include <cstddef>
#include <vector>

namespace adit::daemon {

template <typename T>
class SpscQueue {
 public:
  explicit SpscQueue(std::size_t capacity) : slots_(capacity + 1) {}

  // Producer thread only. False when full.
  bool push(T&& item) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t next = (head + 1) % slots_.size();
    if (next == tail_.load(std::memory_order_acquire)) return false;
    slots_[head] = std::move(item);
    head_.store(next, std::memory_order_release);
    return true;
  }
  bool push(const T& item) {
    T copy = item;
    return push(std::move(copy));
  }

  // Consumer thread only. False when empty.
  bool pop(T& out) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = std::move(slots_[tail]);
    tail_.store((tail + 1) % slots_.size(), std::memory_order_release);
    return true;
  }

 private:
  std::vector<T> slots_;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
};

}  // namespace adit::daemon
