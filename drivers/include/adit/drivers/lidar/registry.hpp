#pragma once
// The LiDAR families adit knows, for tools that are handed a capture and must
// find out what is in it. Each family is one LidarFamily value; adding a
// family is one line in registry.cpp's table.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "adit/drivers/lidar/decoder.hpp"

namespace adit::drivers {

struct LidarFamily {
  std::string_view name;  // "velodyne", "hesai", "robosense", "livox", "ouster"
  // The model name when `payload` (sent to `dst_port`) is a data packet of this family, else "".
  std::string (*detect)(std::span<const std::uint8_t> payload, std::uint16_t dst_port);
  // A decoder for `model`, configured by its calibration or metadata file (some families can do
  // without one: then `calibration` is empty). Throws adit::InputError.
  std::unique_ptr<LidarDecoder> (*make_decoder)(const std::string& model, const std::filesystem::path& calibration);
  // The expected time between data packets like `payload`, 0 when unknown (for loss counting).
  std::int64_t (*packet_period_ns)(const std::string& model, std::span<const std::uint8_t> payload);
};

struct DetectedLidar {
  const LidarFamily* family = nullptr;
  std::string model;
};

std::span<const LidarFamily> lidar_families();
// The first family that recognises the packet; family == nullptr when none does.
DetectedLidar detect_lidar(std::span<const std::uint8_t> payload, std::uint16_t dst_port);
const LidarFamily* find_lidar_family(std::string_view name);
// One line naming every data packet detection knows (model: size, header, factory bytes, port),
// for the message of a tool that recognised nothing.
std::string_view known_lidar_packets();
// The family of a configured model name (VLP-16, PandarXT32, Helios16P, OS1-64, ...), nullptr when unknown.
const LidarFamily* lidar_family_of_model(std::string_view model);

// Each family's entry, defined beside its decoder.
LidarFamily velodyne_family();
LidarFamily hesai_family();
LidarFamily robosense_family();
LidarFamily ouster_family();
LidarFamily livox_family();

}  // namespace adit::drivers
