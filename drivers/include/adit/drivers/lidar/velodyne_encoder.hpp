#pragma once
// Velodyne data packets written from measurements: the inverse of
// VelodyneDecoder's packet layout (VLP-16 User Manual rev. E §9: 12 blocks of
// flag, azimuth in 0.01° and 32 × (distance in the model's unit, reflectivity);
// u32 µs past the hour; return-mode and product bytes). The simulator uses it
// to produce captures that the real decoder reads.

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "adit/drivers/lidar/velodyne.hpp"

namespace adit::drivers {

struct VelodyneBlock {
  std::uint16_t azimuth = 0;                    // 0.01°, [0, 36000)
  std::array<std::uint16_t, 32> distance{};     // in the model's distance unit; 0 = no return
  std::array<std::uint8_t, 32> reflectivity{};  // 0-100 diffuse, 101-255 retro-reflective (manual §6.3)
};

struct VelodyneDataPacket {
  std::array<VelodyneBlock, VelodyneDecoder::kBlocks> blocks{};
  std::uint32_t us_past_hour = 0;
  VelodyneReturnMode mode = VelodyneReturnMode::strongest;
};

void encode_velodyne_packet(VelodyneModel model, const VelodyneDataPacket& packet,
                            std::span<std::uint8_t, kVelodyneDataPacketSize> out);

// The model's nominal calibration: the manual's vertical angles and vertical
// offsets, no other corrections (VLP-16 manual, "Laser ID, vertical angle and
// vertical correction" table). Only the VLP-16 is tabulated; throws
// adit::InputError for the others.
VelodyneCalibration velodyne_nominal_calibration(VelodyneModel model);

// The calibration as the YAML parse_velodyne_calibration reads (round trip).
std::string format_velodyne_calibration(const VelodyneCalibration& calibration);

}  // namespace adit::drivers
