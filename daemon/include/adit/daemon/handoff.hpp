#pragma once
// Hands preallocated items (packets, scans, results) from one thread to the
// next without allocation or locks: a fixed pool of T, a ring of filled items
// (producer → consumer) and a ring of free ones (consumer → producer).
//
// When the consumer falls behind and the pool runs dry, a live source
// (Overflow::drop_oldest) takes back the oldest filled item and reuses it,
// counting the drop: a late scan is worth less than the current one. A file
// replay (Overflow::wait) instead gets nullptr and retries, so nothing is lost.

#include <atomic>
#include <cstdint>
#include <optional>
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
  // Producer: hands a filled item (from acquire) to the consumer.
  void publish(T* item) {
    filled_.try_push(index_of(item));  // cannot fail: the pool has as many items as the ring has slots
    published_.fetch_add(1, std::memory_order_relaxed);
  }

  // Consumer: the oldest filled item, or nullptr.
  T* take() {
    auto index = filled_.try_pop();
    return index ? &pool_[*index] : nullptr;
  }
  // Consumer: gives a taken item back to the pool.
  void release(T* item) { free_.try_push(index_of(item)); }

  std::uint64_t published() const { return published_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  std::size_t depth() const { return filled_.size(); }
  std::size_t capacity() const { return pool_.size(); }

 private:
  std::uint32_t index_of(const T* item) const { return static_cast<std::uint32_t>(item - pool_.data()); }

  Overflow overflow_;
  std::vector<T> pool_;
  SpscRing<std::uint32_t> filled_;
  SpscRing<std::uint32_t> free_;
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace adit::daemon
