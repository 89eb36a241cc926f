#pragma once
// Sensor time to host time.
//
// TopOfHourClock turns a timestamp that only counts microseconds since the top
// of the hour (Velodyne) into absolute time, pinning the hour once against a
// reference (the host clock, or a GPS NMEA sentence which is authoritative)
// and then following the hour rollovers of the stream itself.
//
// ClockOffsetEstimator estimates host − sensor clock offset and its drift from
// (sensor time, host receive time) pairs. Each pair is offset + network and
// scheduling delay, with the delay ≥ 0, so the minimum over a window is the
// best estimate of the offset (the "minimum delay" filter of NTP, RFC 5905
// §10); a least-squares line through the last window minima gives the drift.
// Fixed storage, no allocation.

#include <array>
#include <cstdint>
#include <optional>

namespace adit::drivers {

class TopOfHourClock {
 public:
  static constexpr std::int64_t kHourNs = 3'600'000'000'000;

  // Absolute sensor time (ns since the epoch) of `us_past_hour`. The first
  // call pins the hour to the one that puts the time nearest `reference_ns`;
  // later calls follow rollovers (a jump back of more than half an hour).
  std::int64_t resolve(std::uint32_t us_past_hour, std::int64_t reference_ns);

  // Pins the hour from a GPS time (NMEA) taken at the same instant as `us_past_hour`.
  void anchor(std::uint32_t us_past_hour, std::int64_t utc_ns);

  bool anchored() const { return anchored_; }
  bool anchored_to_gps() const { return gps_; }
  std::uint64_t rollovers() const { return rollovers_; }

 private:
  bool anchored_ = false;
  bool gps_ = false;
  std::int64_t hour_start_ns_ = 0;
  std::uint32_t last_us_ = 0;
  std::uint64_t rollovers_ = 0;
};

struct ClockEstimate {
  std::int64_t offset_ns = 0;  // host − sensor at `at_sensor_ns`
  double drift_ppm = 0.0;      // growth of the offset, µs per second of sensor time
  std::int64_t at_sensor_ns = 0;
  std::uint32_t windows = 0;   // window minima the fit used
};

class ClockOffsetEstimator {
 public:
  static constexpr std::size_t kMaxWindows = 64;

  // `window_ns`: span of one minimum; `windows` (≤ kMaxWindows): how many minima the line is fitted to.
  // A step of the offset larger than `reset_ns` (clock set, sensor restart) restarts the estimate.
  explicit ClockOffsetEstimator(std::int64_t window_ns = 1'000'000'000, std::size_t windows = 16,
                                std::int64_t reset_ns = 1'000'000'000);

  void add(std::int64_t sensor_ns, std::int64_t host_ns);

  // Nullopt before the first sample.
  std::optional<ClockEstimate> estimate() const;
  // Host time of a sensor time by the current estimate (sensor time itself before any sample).
  std::int64_t to_host(std::int64_t sensor_ns) const;
  std::uint64_t resets() const { return resets_; }

 private:
  struct Minimum {
    std::int64_t sensor_ns = 0;
    std::int64_t offset_ns = 0;
  };
  void close_window();
  void refit();

  std::int64_t window_ns_;
  std::size_t capacity_;
  std::int64_t reset_ns_;
  std::array<Minimum, kMaxWindows> minima_{};
  std::size_t count_ = 0;
  std::size_t head_ = 0;  // next slot to write
  bool window_open_ = false;
  std::int64_t window_start_ns_ = 0;
  Minimum window_min_;
  std::int64_t last_sensor_ns_ = 0;
  std::optional<ClockEstimate> fit_;
  std::uint64_t resets_ = 0;
};

}  // namespace adit::drivers
