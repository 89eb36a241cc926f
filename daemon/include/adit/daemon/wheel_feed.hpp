#pragma once
// Wheel encoders for the odometry's prior (config `can:` + `wheel_odometry:`),
// and an accelerometer on the same bus for its gravity prior (config `imu:`).
// A thread reads CAN frames (SocketCAN on the payload, or a candump -L log
// for replays), records the bus when `can.record` is set, decodes the two
// wheel signals, integrates slam::WheelOdometry and hands timed planar poses
// to the odometry thread through a lock-free hand-off. The odometry thread
// keeps the recent ones in a WheelHistory and asks it for the motion between
// two scans (slam::wheel_motion_prior).

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <thread>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "adit/config/config.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/pose2.hpp"

namespace adit::daemon {

// The messages that carry the config's signals: its DBC file and inline
// signals (throws adit::InputError naming the DBC file).
std::vector<drivers::can::MessageSpec> can_messages_of(const config::Config& config);

struct WheelSample {
  double t = 0.0;         // s, on the LiDAR clock (wheel_odometry.time_offset_s removed)
  slam::Pose2 pose;       // integrated body pose
  double distance = 0.0;  // m travelled so far
};

// One accelerometer reading: specific force in the body frame (the config's
// imu.rpy_deg applied), m/s².
struct ImuSample {
  double t = 0.0;  // s, on the LiDAR clock (imu.time_offset_s removed)
  Eigen::Vector3d specific_force = Eigen::Vector3d::Zero();
};

// What the CAN thread hands over, in bus order.
using CanSample = std::variant<WheelSample, ImuSample>;

// The odometry thread's recent samples of one kind (with a time `t`): fixed
// capacity, the oldest dropped, time strictly advancing (others are ignored).
template <typename Sample>
class TimedRing {
 public:
  explicit TimedRing(std::size_t capacity) : ring_(std::max<std::size_t>(capacity, 2)) {}
  void push(const Sample& sample) {
    if (size_ > 0 && !(sample.t > back().t)) return;
    if (size_ == ring_.size()) {
      first_ = (first_ + 1) % ring_.size();
      --size_;
    }
    ring_[(first_ + size_) % ring_.size()] = sample;
    ++size_;
  }
  std::size_t size() const { return size_; }
  // Oldest first; i < size().
  const Sample& operator[](std::size_t i) const { return ring_[(first_ + i) % ring_.size()]; }
  const Sample& back() const { return (*this)[size_ - 1]; }
  // Time of the newest sample; -infinity when empty.
  double latest() const { return size_ == 0 ? -std::numeric_limits<double>::infinity() : back().t; }

 private:
  std::vector<Sample> ring_;
  std::size_t first_ = 0;
  std::size_t size_ = 0;
};

// The odometry thread's recent accelerometer readings: fixed capacity, oldest dropped.
class ImuHistory {
 public:
  explicit ImuHistory(std::size_t capacity) : samples_(capacity) {}
  void push(const ImuSample& sample) { samples_.push(sample); }
  double latest() const { return samples_.latest(); }
  // The mean specific force over [t0, t1], the readings joined by straight
  // lines; nullopt unless readings lie on both sides and `min_samples` within.
  std::optional<Eigen::Vector3d> mean(double t0, double t1, std::size_t min_samples = 3) const;

 private:
  TimedRing<ImuSample> samples_;
};

// The odometry thread's recent wheel samples: fixed capacity, oldest dropped.
class WheelHistory {
 public:
  explicit WheelHistory(std::size_t capacity) : samples_(capacity) {}
  void push(const WheelSample& sample) { samples_.push(sample); }
  // Time of the newest sample; -infinity when empty.
  double latest() const { return samples_.latest(); }
  // Distance travelled at the newest sample (0 when empty).
  double latest_distance() const { return samples_.size() == 0 ? 0.0 : samples_.back().distance; }
  // The body motion from t0 to t1 by the wheels (interpolated), nullopt
  // when the samples do not cover [t0, t1].
  std::optional<slam::MotionPrior> prior(double t0, double t1) const;
  // The body's mean kinematic acceleration over [t0, t1] in the body frame
  // (x forward, y left), as a planar vehicle on its wheels moves: the change
  // of forward speed over the interval, v(t1) − v(t0) over t1 − t0, plus the
  // centripetal ω·v to the left (ω × v). The speeds are central differences
  // over ±`half_window` s; nullopt when the samples do not cover that.
  std::optional<Eigen::Vector3d> acceleration(double t0, double t1, double half_window = 0.05) const;

 private:
  bool interpolate(double t, slam::Pose2& pose, double& distance) const;
  TimedRing<WheelSample> samples_;
};

struct WheelFeedStats {
  std::atomic<std::uint64_t> frames{0};
  std::atomic<std::uint64_t> samples{0};
  std::atomic<std::uint64_t> untrusted{0};  // slip, glitches, gaps (slam::WheelStep other than integrated)
  std::atomic<std::uint64_t> slip_episodes{0};  // a wheel lost traction and was held at its trusted speed
  std::atomic<std::uint64_t> dropped{0};    // live: the odometry thread fell behind
  std::atomic<std::uint64_t> recorded{0};
  std::atomic<std::uint64_t> imu_samples{0};
  std::atomic<std::int64_t> last_frame_us{0};
};

class WheelFeed {
 public:
  // Opens the source (throws adit::InputError naming the log or the
  // interface) and builds the decoder; `replay` hand-offs wait instead of
  // dropping, so a replay as fast as possible loses nothing.
  explicit WheelFeed(const config::Config& config);
  ~WheelFeed();
  WheelFeed(const WheelFeed&) = delete;
  WheelFeed& operator=(const WheelFeed&) = delete;

  // Starts the thread; `record_file` (candump -L) may be empty.
  void start(const std::filesystem::path& record_file);
  void stop();
  // Odometry thread: moves samples into `history`, oldest first, until one
  // at or after `until_t` has moved (a replay: the rest waits in the
  // hand-off, so the history keeps the window the next scans need) or none
  // is left (live: everything).
  // Accelerometer readings go to `imu` (dropped when null).
  void drain_into(WheelHistory& history, double until_t, ImuHistory* imu = nullptr);
  // A replayed log has been read to its end and every sample handed over.
  bool finished() const { return finished_.load(std::memory_order_acquire); }
  bool replay() const { return replay_; }
  const WheelFeedStats& stats() const { return stats_; }
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
  WheelFeedStats stats_;
  Heartbeat beat_{"wheels"};
  std::atomic<bool> stop_{false};
  std::atomic<bool> finished_{false};
  std::thread thread_;
};

}  // namespace adit::daemon
