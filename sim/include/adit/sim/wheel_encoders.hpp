#pragma once
// Wheel encoders of a differential-drive robot as CANopen TPDOs in a candump
// log: each wheel's position actual value (object 0x6064, int32 counts,
// little-endian) in TPDO1 of its node (0x180 + node id), as the template
// firmware-config/templates/vlp16-diffdrive-robot.yaml expects. The wheels
// turn with the body's speed and yaw rate (v ∓ ω·track/2)/r on the TRUE
// radius, which differs from the configured one by `radius_error`; counts are
// quantised after a little noise, and now and then a wheel slips (spins
// faster than the ground moves).

#include <cstdint>
#include <filesystem>
#include <vector>

#include "adit/drivers/can/frame.hpp"
#include "adit/sim/body_track.hpp"

namespace adit::sim {

struct WheelOptions {
  double rate_hz = 100.0;                 // TPDO rate per wheel
  double radius_m = 0.1651;               // as configured
  double radius_error = 0.004;            // true radius = radius_m × (1 + radius_error)
  double track_m = 0.555;
  int counts_per_revolution = 16384;
  double count_noise = 0.3;               // σ in counts before quantisation
  double slips_per_minute = 1.0;          // events: one wheel spins 30 % fast for 0.3 s
  double time_offset_s = 0.0;             // CAN clock minus the LiDAR clock
  std::int64_t start_time_ns = 0;
  std::uint64_t seed = 0;
  std::uint32_t left_id = 0x181;
  std::uint32_t right_id = 0x182;
};

// What the wheels really did, per frame time (seconds since start, common clock).
struct WheelTruth {
  std::vector<double> time_s;
  std::vector<double> left_rad, right_rad;  // wheel angles (with slip)
};

// Appends the wheels' frames to `frames` (time order; the session merges
// them with the IMU's into can.log).
WheelTruth simulate_wheel_encoders(const BodyTrack& body, const WheelOptions& options,
                                   std::vector<drivers::can::Frame>& frames);
// "time,left_rad,right_rad" per frame (time in seconds on the common clock).
void write_wheel_truth(const std::filesystem::path& file, const WheelTruth& truth, std::int64_t start_time_ns);

}  // namespace adit::sim
