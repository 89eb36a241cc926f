#pragma once
// The CAN bus's motion sensors: wheel encoders for the odometry's prior
// (config `can:` + `wheel_odometry:`) and an accelerometer for its gravity
// prior (config `imu:`).
//
// In:   CAN frames, from SocketCAN on the payload or a candump -L log for replays.
// Out:  timed wheel poses (slam::WheelOdometry integrated) and accelerometer
//       readings in body axes, in bus order, through a lock-free hand-off to
//       the odometry thread, which keeps them in slam::WheelHistory and
//       slam::ImuHistory (slam/motion_history.hpp); the bus as candump -L
//       when `can.record` is set.
// Its thread ("can") does not allocate per frame; live, a full hand-off
// drops the oldest sample (counted); a replay waits, so nothing is lost.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <thread>
#include <variant>
#include <vector>

#include "adit/config/config.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/slam/motion_history.hpp"

namespace adit::daemon {

// The messages that carry the config's signals: its DBC file and inline
// signals (throws adit::InputError naming the DBC file).
std::vector<drivers::can::MessageSpec> can_messages_of(const config::Config& config);

// What the CAN thread hands over, in bus order.
using CanSample = std::variant<slam::WheelSample, slam::ImuSample>;

struct CanFeedStats {
  std::atomic<std::uint64_t> frames{0};
  std::atomic<std::uint64_t> samples{0};
  std::atomic<std::uint64_t> untrusted{0};  // slip, glitches, gaps (slam::WheelStep other than integrated)
  std::atomic<std::uint64_t> slip_episodes{0};  // a wheel lost traction and was held at its trusted speed
  std::atomic<std::uint64_t> dropped{0};    // live: the odometry thread fell behind
  std::atomic<std::uint64_t> recorded{0};
  std::atomic<std::uint64_t> imu_samples{0};
  std::atomic<std::int64_t> last_frame_us{0};
};

class CanFeed {
 public:
  // Opens the source (throws adit::InputError naming the log or the
  // interface) and builds the decoder; `replay` hand-offs wait instead of
  // dropping, so a replay as fast as possible loses nothing.
  explicit CanFeed(const config::Config& config);
  ~CanFeed();
  CanFeed(const CanFeed&) = delete;
  CanFeed& operator=(const CanFeed&) = delete;

  // Starts the thread; `record_file` (candump -L) may be empty.
  void start(const std::filesystem::path& record_file);
  void stop();
  // Odometry thread: moves samples into `history`, oldest first. Live:
  // everything handed over so far. A replay: until the wheels (and the
  // accelerometer) reach `until_t`, the rest waiting in the hand-off so the
  // history keeps the window the next scans need; with `idle`, it waits for
  // the log to get there or end, calling idle() meanwhile (false: give up).
  // Accelerometer readings go to `imu` (dropped when null).
  void drain_into(slam::WheelHistory& history, double until_t, slam::ImuHistory* imu = nullptr,
                  const std::function<bool()>& idle = {});
  // A replayed log has been read to its end and every sample handed over.
  bool finished() const { return samples_.closed(); }
  bool replay() const { return replay_; }
  const CanFeedStats& stats() const { return stats_; }
  const Heartbeat& heartbeat() const { return beat_; }

 private:
  struct Impl;
  void run();
  // Waits for room in a replay; false when stopped meanwhile.
  bool hand_over(const CanSample& sample);
  std::unique_ptr<Impl> impl_;
  bool replay_ = false;
  Handoff<CanSample> samples_;
  double drained_t_ = -std::numeric_limits<double>::infinity();  // the last sample taken (odometry thread)
  CanFeedStats stats_;
  Heartbeat beat_{"can"};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace adit::daemon
