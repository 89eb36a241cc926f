#pragma once
// Hands preallocated items (packets, scans, results) from one thread to the
// next without allocation or locks: a fixed pool of T, a ring of filled items
// (producer → consumer) and a ring of free ones (consumer → producer).
//
// When the consumer falls behind and the pool runs dry, a live source
// (Overflow::drop_oldest) takes back the oldest filled item and reuses it,
// counting the drop: a late scan is worth less than the current one. A file
// replay (Overflow::wait) instead waits for a free item, so nothing is lost.
//
// Waiting (acquire_or_wait, take_or_wait) polls every kPoll and calls the
// caller's `idle()` in between, which beats the thread's heartbeat and says
// whether to go on waiting (false once the pipeline stops). The producer
// close()s the hand-off when it has published its last item; the consumer
// then drains what is left and take_or_wait gives nullptr.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <thread>
#include <vector>

#include "adit/daemon/spsc_ring.hpp"

namespace adit::daemon {

enum class Overflow { drop_oldest, wait };

template <typename T>
class Handoff {
 public:
  // `make` builds each pooled item (e.g. a scan with reserved capacity).
  template <typename Make>
  Handoff(std::size_t items, Overflow overflow, Make&& make)
      : overflow_(overflow), filled_(items), free_(items) {
    pool_.reserve(items);
    for (std::size_t i = 0; i < items; ++i) {
      pool_.push_back(make());
      free_.try_push(static_cast<std::uint32_t>(i));
    }
  }

  // Producer: an item to fill, or nullptr (wait policy, pool exhausted).
  T* acquire() {
    if (auto index = free_.try_pop()) return &pool_[*index];
    if (overflow_ == Overflow::wait) return nullptr;
    if (auto index = filled_.steal_oldest()) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return &pool_[*index];
    }
    // The consumer holds every item; only a pool smaller than the pipeline's
    // depth gets here. Free items come back soon.
    if (auto index = free_.try_pop()) return &pool_[*index];
    return nullptr;
  }
  // Producer: acquire(), waiting while it gives nullptr; nullptr when
  // `idle()` returns false first.
  template <typename Idle>
  T* acquire_or_wait(Idle&& idle) {
    for (;;) {
      if (T* item = acquire()) return item;
      if (!idle()) return nullptr;
      std::this_thread::sleep_for(kPoll);
    }
  }
  // Producer: hands a filled item (from acquire) to the consumer.
  void publish(T* item) {
    filled_.try_push(index_of(item));  // cannot fail: the pool has as many items as the ring has slots
    published_.fetch_add(1, std::memory_order_relaxed);
  }
  // Producer: nothing more will be published.
  void close() { closed_.store(true, std::memory_order_release); }
  bool closed() const { return closed_.load(std::memory_order_acquire); }

  // Consumer: the oldest filled item, or nullptr.
  T* take() {
    auto index = filled_.try_pop();
    return index ? &pool_[*index] : nullptr;
  }
  // Consumer: take(), waiting while nothing is filled; nullptr once the
  // producer has closed and everything it published was taken, or when
  // `idle()` returns false first.
  template <typename Idle>
  T* take_or_wait(Idle&& idle) {
    for (;;) {
      if (T* item = take()) return item;
      // Everything published before close() is visible once closed_ is seen.
      if (closed_.load(std::memory_order_acquire)) return take();
      if (!idle()) return nullptr;
      std::this_thread::sleep_for(kPoll);
    }
  }
  // Consumer: gives a taken item back to the pool.
  void release(T* item) { free_.try_push(index_of(item)); }

  // The producer has closed and every item it published was taken.
  bool drained() const { return closed() && filled_.size() == 0; }

  std::uint64_t published() const { return published_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  std::size_t depth() const { return filled_.size(); }
  // Consumer: a live source's items wait behind the one in hand, so a slow
  // consumer would soon drop some (a file replay waits instead: never).
  bool falling_behind() const { return overflow_ == Overflow::drop_oldest && filled_.size() > 0; }
  std::size_t capacity() const { return pool_.size(); }

  static constexpr std::chrono::microseconds kPoll{200};

 private:
  std::uint32_t index_of(const T* item) const { return static_cast<std::uint32_t>(item - pool_.data()); }

  Overflow overflow_;
  std::vector<T> pool_;
  SpscRing<std::uint32_t> filled_;
  SpscRing<std::uint32_t> free_;
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<bool> closed_{false};
};

}  // namespace adit::daemon
