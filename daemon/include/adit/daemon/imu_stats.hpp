#pragma once
// What an IMU source counts about its stream, written by the thread that
// reads the IMU (one writer) and read by the status, summary.json and the
// tools (atomics, relaxed). The problems are counted by reason, and the last
// one is kept by name (the packet or frame number and the axis) so that a
// slow thread can report it; the reading thread never logs.

#include <atomic>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

namespace adit::config {
enum class ImuSource;  // config.hpp
}

namespace adit::daemon {

// Why an IMU reading was flagged. Order = the index in ImuStats::problems.
enum class ImuProblem : std::uint8_t {
  gap,           // more than ImuMonitor::kGapPeriods nominal periods since the previous reading (kept)
  saturated,     // an axis at its encoding's limit or beyond the configured range (kept)
  stuck_axis,    // an axis read the same value ImuMonitor::kStuckReadings times in a row (kept)
  time_back,     // stamped at or before the previous reading (dropped)
  undecodable,   // not an IMU packet or frame of the expected layout (dropped)
  unpaired,      // CAN: an accelerometer frame without its gyroscope frame (kept, has_gyro false), or a
                 // gyroscope frame without its accelerometer frame (dropped)
  unclocked,     // Ouster: before the LiDAR clock's first estimate, or stamped more than 10 s from the
                 // LiDAR's newest packet: no stamp on the LiDAR clock (dropped)
};
inline constexpr std::size_t kImuProblemKinds = 7;

std::string_view to_string(ImuProblem problem);

struct ImuStats {
  std::atomic<std::uint64_t> packets{0};      // IMU packets (Ouster) or IMU frames (CAN, accelerometer and gyroscope) read
  std::atomic<std::uint64_t> samples{0};      // readings handed to the odometry
  std::atomic<std::uint64_t> gyro_samples{0}; // of which with a gyroscope reading (has_gyro)
  std::atomic<std::uint64_t> dropped{0};      // live: the odometry fell behind (the oldest dropped)
  std::atomic<double> rate_hz{0.0};           // from the readings' own stamps (the mean period, gaps left out)
  std::atomic<double> longest_gap_s{0.0};
  std::atomic<double> last_t{0.0};            // stamp of the newest reading, s on the LiDAR clock
  std::atomic<std::int64_t> last_seen_realtime_ns{0};
  std::atomic<double> time_offset_s{0.0};     // configured: IMU clock − LiDAR clock (imu.time_offset_s)
  // Ouster: the spread between the IMU packets' clock and the LiDAR's, as
  // (host − sensor) from the IMU packets' own system stamps minus the LiDAR
  // clock's estimate (min-delay filtered both); NaN when not measurable.
  std::atomic<double> clock_spread_s{std::numeric_limits<double>::quiet_NaN()};
  std::atomic<std::uint64_t> problems[kImuProblemKinds]{};
  // The last problem: its kind, the packet or frame number (1 = the first read) and the axis (0-5: ax ay az gx gy gz; -1: none).
  std::atomic<int> last_problem{-1};
  std::atomic<std::uint64_t> last_problem_packet{0};
  std::atomic<int> last_problem_axis{-1};

  std::uint64_t count(ImuProblem p) const { return problems[static_cast<std::size_t>(p)].load(std::memory_order_relaxed); }
};

// One line about the stream's problems for people ("IMU ouster: 2 gaps
// (longest 0.52 s), 1 stuck axis; last: stuck axis gz at packet 1234"), or
// "" when there are none. `source` names the stream.
std::string describe_problems(const ImuStats& stats, std::string_view source);
// The IMU stream's name in logs, health and tools: its `imu.source` value.
std::string_view imu_source_name(config::ImuSource source);

// Copies every figure (each atomically, not all at one instant): the
// pipeline's copy of its IMU source's stats.
void copy_stats(const ImuStats& from, ImuStats& to);

}  // namespace adit::daemon
