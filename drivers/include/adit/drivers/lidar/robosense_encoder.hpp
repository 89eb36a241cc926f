#pragma once
// RoboSense MSOP packets written from measurements, the inverse of
// RoboSenseDecoder (single-return mode): 42-byte header (magic; RS-16: UTC
// date-time YY MM DD hh mm ss, ms, µs; Helios 16P: u48 s, u32 µs and the range
// resolution byte), 12 blocks of (0xFFEE, azimuth in 0.01°, 32 × (distance,
// reflectivity)) big-endian, and the tail. The simulator uses it.

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "adit/drivers/lidar/robosense.hpp"

namespace adit::drivers {

struct RoboSenseBlock {
  std::uint16_t azimuth = 0;                    // 0.01°, [0, 36000)
  std::array<std::uint16_t, 32> distance{};     // in robosense_distance_unit_m; 0 = no return
  std::array<std::uint8_t, 32> reflectivity{};
};

struct RoboSenseMsop {
  std::array<RoboSenseBlock, 12> blocks{};
  std::int64_t time_ns = 0;  // Unix time of the first firing (µs resolution on the wire)
};

// The distance unit the encoder writes: RS-16 0.5 cm; Helios 16P 0.25 cm (flagged in the header).
float robosense_distance_unit_m(RoboSenseModel model);
void encode_robosense_msop(RoboSenseModel model, const RoboSenseMsop& packet,
                           std::span<std::uint8_t, kRoboSenseMsopSize> out);

// Nominal angles from the RS-LiDAR-16 user manual (vertical −15°..+15° in 2°
// steps, lasers 0-7 upwards from −15°, 8-15 downwards from +15°; no horizontal
// offsets). Only the RS-16 is tabulated; throws adit::InputError otherwise.
RoboSenseAngles robosense_nominal_angles(RoboSenseModel model);
// The "elevation,azimuth" CSV parse_robosense_angle_csv reads.
std::string format_robosense_angle_csv(const RoboSenseAngles& angles);

}  // namespace adit::drivers
