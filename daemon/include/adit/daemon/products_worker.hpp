#pragma once
// A finished session's products (products::write_session_products: 3D
// occupancy, 2D grid, top view with targets, cross-sections, targets.csv; the
// storage figures into summary.json) made on a thread of its own at the
// lowest priority (SCHED_IDLE: it runs only on CPU time nothing else wants),
// so that the next START is answered at once and its odometry never waits.
// Sessions are made in the order they stopped.
//
// Crash safety: a session's products are written into
// <session>/products.partial and renamed to <session>/products once whole;
// summary.json gains "products" by a write to a temporary file and a rename.
// A crash or kill meanwhile leaves the session's own files as they were, and
// at most a products.partial folder (removed when the session is queued
// again; `adit products SESSION` makes its products by hand).
//
// stop() (and the destructor) drops the sessions not yet begun and cancels
// the one being made (ProductsOptions::cancel: between steps and every octree
// batch; the rays to the path finish first), saying so in the log; it raises
// the thread back to SCHED_OTHER first, when the kernel allows, so that a busy
// machine does not keep an idle-priority thread from reaching its check.
// Measured: 2.7-5.8 s of CPU for a 60-90 s drive (docs/PRODUCTS.md).
//
// With join_previous (session.join_previous), each session is then joined to
// the newest earlier session whose map it overlaps
// (products::join_previous_session: <session>/joined.json; cancelled between
// places by stop()), logged either way.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <filesystem>
#include <mutex>
#include <thread>

#include "adit/slam/session_join.hpp"

namespace adit::daemon {

// What is made of each session queued.
struct AfterSessionSteps {
  bool products = true;        // products::write_session_products (session.products)
  bool join_previous = false;  // products::join_previous_session (session.join_previous)
  slam::SessionJoinConfig join;  // its places and checks (the defaults in aditd)
};

class ProductsWorker {
 public:
  // Products with the library's defaults (ProductsOptions{}: 5 cm grid, 10 cm octree).
  explicit ProductsWorker(AfterSessionSteps steps = {});
  ~ProductsWorker();
  ProductsWorker(const ProductsWorker&) = delete;
  ProductsWorker& operator=(const ProductsWorker&) = delete;

  // Queues a session folder whose summary.json is written; never waits.
  void enqueue(std::filesystem::path session_dir);
  // Drops what has not begun, cancels the one being made, ends the thread.
  void stop();
  // Blocks until nothing is queued or being made (tests, `aditd --once`).
  void wait_idle();

  std::size_t made() const;    // sessions whose products were written
  std::size_t failed() const;  // sessions whose products failed (logged)
  std::size_t cancelled() const;  // begun and cancelled by stop()
  std::size_t joined() const;     // sessions joined to an earlier one

 private:
  void run();
  void make_products(const std::filesystem::path& dir);
  void join_previous(const std::filesystem::path& dir);

  const AfterSessionSteps steps_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::filesystem::path> queue_;
  bool busy_ = false;
  bool stopping_ = false;
  std::size_t made_ = 0, failed_ = 0, cancelled_ = 0, joined_ = 0;
  std::atomic<bool> cancel_{false};
  std::thread thread_;  // last: started once the rest exists
};

}  // namespace adit::daemon
