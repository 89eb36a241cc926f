#pragma once
// A bounded single-producer/single-consumer ring of small trivially copyable
// values (buffer indices), lock-free, that lets the producer drop the oldest
// value when full. Head and tail are 64-bit counters that never wrap in
// practice, so there is no ABA. The consumer and a dropping producer both
// claim the oldest value by CAS on the tail; whoever wins owns it. Slots are
// atomics, so a slot re-filled while the consumer looks at it is a stale
// read that the failed CAS discards, never a data race.
// (Lamport 1983 for the SPSC ring; the overwrite-by-CAS is the usual way to
// give a lock-free ring "keep the newest" semantics.)

#include <atomic>
#include <bit>
#include <cstdint>
#include <memory>
#include <optional>
#include <type_traits>

namespace adit::daemon {

template <typename T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T> && std::atomic<T>::is_always_lock_free);

 public:
  explicit SpscRing(std::size_t capacity)
      : capacity_(std::bit_ceil(capacity)), mask_(capacity_ - 1), slots_(std::make_unique<std::atomic<T>[]>(capacity_)) {}

  // Producer: false when full.
  bool try_push(T value) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) >= capacity_) return false;
    slots_[head & mask_].store(value, std::memory_order_relaxed);
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  // Producer, from a full ring: takes the oldest value away from the consumer.
  std::optional<T> steal_oldest() {
    std::uint64_t tail = tail_.load(std::memory_order_acquire);
    while (tail != head_.load(std::memory_order_relaxed)) {
      const T value = slots_[tail & mask_].load(std::memory_order_acquire);
      if (tail_.compare_exchange_weak(tail, tail + 1, std::memory_order_acq_rel)) return value;
    }
    return std::nullopt;
  }

  // Consumer.
  std::optional<T> try_pop() {
    std::uint64_t tail = tail_.load(std::memory_order_acquire);
    while (tail != head_.load(std::memory_order_acquire)) {
      const T value = slots_[tail & mask_].load(std::memory_order_acquire);
      if (tail_.compare_exchange_weak(tail, tail + 1, std::memory_order_acq_rel)) return value;
    }
    return std::nullopt;
  }

  std::size_t size() const {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire));
  }
  std::size_t capacity() const { return capacity_; }

 private:
  std::size_t capacity_;
  std::size_t mask_;
  std::unique_ptr<std::atomic<T>[]> slots_;
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::atomic<std::uint64_t> tail_{0};
};

}  // namespace adit::daemon
