#pragma once
// The CAN bus's motion sensors: wheel encoders for the odometry's prior
// (config `can:` + `wheel_odometry:`) and an IMU (config `imu:` with
// `source: can`): an accelerometer, and a gyroscope when its three signals
// are given. Either may be configured without the other (a drone's bus
// carries the IMU alone).
//
// In:   CAN frames, from SocketCAN on the payload or a candump -L log for replays.
// Out:  timed wheel poses (slam::WheelOdometry integrated) and IMU readings
//       (each accelerometer frame paired with its gyroscope frame,
//       can_imu_pairing.hpp, checked by ImuMonitor, then turned into body
//       axes by imu.rpy_deg), in bus order, through one lock-free hand-off to
//       the odometry thread, which keeps them in the feed's slam::WheelHistory
//       and slam::ImuHistory (catch_up(), the ImuSource interface); the bus
//       as candump -L when `can.record` is set (the IMU frames with it).
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

#include "adit/common/host_clock.hpp"
#include "adit/config/config.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/daemon/imu_source.hpp"
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
  std::atomic<std::uint64_t> imu_samples{0};  // IMU readings handed over (ImuStats::samples)
  std::atomic<std::int64_t> last_frame_us{0};
  // The bus's health from its error frames (drivers/can/bus_status.hpp),
  // from the socket or a replayed log alike.
  std::atomic<int> bus_state{0};  // drivers::can::BusState
  std::atomic<std::uint64_t> error_frames{0};
  std::atomic<std::uint64_t> bus_off{0};     // times the controller went bus-off
  std::atomic<std::uint64_t> recoveries{0};  // times it came back (restarted, error-active, frames again)
};

class CanFeed final : public ImuSource {
 public:
  // Opens the source (throws adit::InputError naming the log or the
  // interface) and builds the decoder; `replay` hand-offs wait instead of
  // dropping, so a replay as fast as possible loses nothing.
  // Live frames are stamped on `clock` (common/host_clock.hpp), the same
  // step-free timeline as the LiDAR's.
  explicit CanFeed(const config::Config& config, HostClock clock = HostClock());
  ~CanFeed() override;
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
  // IMU readings go to `imu` (dropped when null). Without wheels
  // (wheel_odometry disabled) only the IMU is waited for.
  void drain_into(slam::WheelHistory& history, double until_t, slam::ImuHistory* imu = nullptr,
                  const std::function<bool()>& idle = {});

  // Odometry thread: drain_into() the feed's own histories, wheels() and
  // history() (the IMU's, when imu.source is can). Calling it twice for the
  // same `until_t` costs nothing.
  void catch_up(double until_t, const std::function<bool()>& idle) override;
  const slam::WheelHistory& wheels() const { return wheel_history_; }
  bool has_wheels() const { return wheels_; }
  bool has_imu() const { return imu_; }
  const slam::ImuHistory& history() const override { return imu_history_; }
  const ImuMounting& mounting() const override { return mounting_; }
  const ImuStats& imu_stats() const override { return imu_stats_; }
  const char* imu_name() const override { return "can"; }
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
  ImuStats imu_stats_;  // before impl_: its monitor writes here
  std::unique_ptr<Impl> impl_;
  bool replay_ = false;
  bool wheels_ = false;  // wheel_odometry.enabled
  bool imu_ = false;     // imu.enabled with source can
  ImuMounting mounting_;
  Handoff<CanSample> samples_;
  double drained_t_ = -std::numeric_limits<double>::infinity();  // the last sample taken (odometry thread)
  slam::WheelHistory wheel_history_{8192};          // odometry thread: 80 s at 100 Hz
  slam::ImuHistory imu_history_{kImuHistoryCapacity};  // odometry thread
  CanFeedStats stats_;
  Heartbeat beat_{"can"};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace adit::daemon
