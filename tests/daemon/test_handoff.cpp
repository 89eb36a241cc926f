#include <gtest/gtest.h>

#include <thread>

#include "adit/daemon/handoff.hpp"
#include "adit/daemon/spsc_ring.hpp"

namespace adit::daemon {
namespace {

TEST(SpscRing, FifoUntilFullThenRefuses) {
  SpscRing<std::uint32_t> ring(4);
  for (std::uint32_t i = 0; i < 4; ++i) EXPECT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(9));
  EXPECT_EQ(*ring.try_pop(), 0U);
  EXPECT_EQ(*ring.steal_oldest(), 1U);
  EXPECT_EQ(*ring.try_pop(), 2U);
  EXPECT_EQ(*ring.try_pop(), 3U);
  EXPECT_FALSE(ring.try_pop().has_value());
  EXPECT_FALSE(ring.steal_oldest().has_value());
}

TEST(Handoff, DropOldestKeepsTheNewestAndCountsTheDrops) {
  Handoff<int> handoff(3, Overflow::drop_oldest, [] { return 0; });
  for (int i = 1; i <= 5; ++i) {
    int* item = handoff.acquire();
    ASSERT_NE(item, nullptr);
    *item = i;
    handoff.publish(item);
  }
  EXPECT_EQ(handoff.dropped(), 2U);
  for (int expected : {3, 4, 5}) {
    int* item = handoff.take();
    ASSERT_NE(item, nullptr);
    EXPECT_EQ(*item, expected);
    handoff.release(item);
  }
  EXPECT_EQ(handoff.take(), nullptr);
}

TEST(Handoff, WaitPolicyRefusesInsteadOfDropping) {
  Handoff<int> handoff(2, Overflow::wait, [] { return 0; });
  handoff.publish(handoff.acquire());
  handoff.publish(handoff.acquire());
  EXPECT_EQ(handoff.acquire(), nullptr);
  handoff.release(handoff.take());
  EXPECT_NE(handoff.acquire(), nullptr);
  EXPECT_EQ(handoff.dropped(), 0U);
}

// The odometry's searches ask this before each extra registration: a live
// stream is behind while items wait behind the one in hand; a file replay
// never drops, so never is.
TEST(Handoff, FallingBehindWhileALiveStreamHasItemsWaiting) {
  Handoff<int> live(3, Overflow::drop_oldest, [] { return 0; });
  live.publish(live.acquire());
  int* in_hand = live.take();
  EXPECT_FALSE(live.falling_behind());
  live.publish(live.acquire());
  EXPECT_TRUE(live.falling_behind());
  live.release(in_hand);
  live.release(live.take());
  EXPECT_FALSE(live.falling_behind());

  Handoff<int> replay(3, Overflow::wait, [] { return 0; });
  replay.publish(replay.acquire());
  replay.publish(replay.acquire());
  EXPECT_FALSE(replay.falling_behind());
}

// Two threads, a slow consumer and a small pool: every item the consumer sees
// is intact (its two halves agree), sequence numbers only increase, and every
// item is either consumed or counted as dropped.
TEST(Handoff, ConcurrentDropOldestLosesNothingUncounted) {
  struct Item {
    std::uint64_t sequence = 0;
    std::uint64_t check = 0;
  };
  Handoff<Item> handoff(8, Overflow::drop_oldest, [] { return Item{}; });
  constexpr std::uint64_t kItems = 200'000;
  std::atomic<bool> done{false};
  std::uint64_t consumed = 0;
  std::uint64_t last = 0;
  bool intact = true;
  std::thread consumer([&] {
    while (true) {
      Item* item = handoff.take();
      if (item == nullptr) {
        if (done.load(std::memory_order_acquire) && handoff.depth() == 0) break;
        std::this_thread::yield();
        continue;
      }
      intact = intact && item->check == ~item->sequence && item->sequence > last;
      last = item->sequence;
      ++consumed;
      handoff.release(item);
    }
  });
  for (std::uint64_t s = 1; s <= kItems; ++s) {
    Item* item = nullptr;
    while ((item = handoff.acquire()) == nullptr) std::this_thread::yield();
    item->sequence = s;
    item->check = ~s;
    handoff.publish(item);
  }
  done.store(true, std::memory_order_release);
  consumer.join();
  EXPECT_TRUE(intact);
  EXPECT_EQ(consumed + handoff.dropped(), kItems);
  EXPECT_EQ(last, kItems);  // the newest is never dropped
}

TEST(Handoff, AcquireOrWaitWaitsForTheConsumerAndGivesUpWhenToldTo) {
  Handoff<int> handoff(1, Overflow::wait, [] { return 0; });
  int* first = handoff.acquire();
  ASSERT_NE(first, nullptr);
  handoff.publish(first);
  int calls = 0;
  EXPECT_EQ(handoff.acquire_or_wait([&] { return ++calls < 3; }), nullptr) << "the pool stays empty";
  EXPECT_EQ(calls, 3);
  // A consumer that releases the item later lets the producer go on.
  std::thread consumer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    handoff.release(handoff.take());
  });
  EXPECT_NE(handoff.acquire_or_wait([] { return true; }), nullptr);
  consumer.join();
}

TEST(Handoff, TakeOrWaitDrainsWhatWasPublishedBeforeCloseThenEnds) {
  Handoff<int> handoff(4, Overflow::wait, [] { return 0; });
  std::thread producer([&] {
    for (int i = 1; i <= 100; ++i) {
      int* item = handoff.acquire_or_wait([] { return true; });
      *item = i;
      handoff.publish(item);
    }
    handoff.close();
  });
  int expected = 1;
  while (int* item = handoff.take_or_wait([] { return true; })) {
    EXPECT_EQ(*item, expected++);
    handoff.release(item);
  }
  producer.join();
  EXPECT_EQ(expected, 101) << "every published item came through, in order";
  EXPECT_TRUE(handoff.drained());
}

TEST(Handoff, TakeOrWaitGivesUpWhenToldToBeforeAnythingCame) {
  Handoff<int> handoff(2, Overflow::wait, [] { return 0; });
  int calls = 0;
  EXPECT_EQ(handoff.take_or_wait([&] { return ++calls < 2; }), nullptr);
  EXPECT_EQ(calls, 2);
  EXPECT_FALSE(handoff.drained()) << "not closed: the producer may still publish";
}

}  // namespace
}  // namespace adit::daemon
