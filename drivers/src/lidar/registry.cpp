#include "adit/drivers/lidar/registry.hpp"

#include <array>

namespace adit::drivers {

std::span<const LidarFamily> lidar_families() {
  // One line per family.
  static const std::array kFamilies{
      velodyne_family(),
      hesai_family(),
      robosense_family(),
      livox_family(),   // before Ouster: version byte, length field and size must all agree
      ouster_family(),  // last: it recognises packets by port only
  };
  return kFamilies;
}

DetectedLidar detect_lidar(std::span<const std::uint8_t> payload, std::uint16_t dst_port) {
  for (const LidarFamily& family : lidar_families()) {
    if (std::string model = family.detect(payload, dst_port); !model.empty()) return {&family, std::move(model)};
  }
  return {};
}

std::string_view known_lidar_packets() {
  return "Velodyne 1206 B, blocks 0xFF 0xEE, product byte 0x22/0x24 VLP-16, 0x28 VLP-32C, 0x21 HDL-32E, "
         "0xA1/0x63 VLS-128 (port 2368); Hesai pre-header 0xEE 0xFF: 6.1 XT16 568 B, XT32 1080 B, XT32M 820 B, "
         "3.1 QT64 1072 B, 3.2 QT128 818-1127 B (by header flags), Pandar64 1194/1198 B, Pandar40P 1262/1266 B "
         "(blocks 0xFF 0xEE); RoboSense MSOP 1248 B (0x55 0xAA 0x05 0x0A / 0x55 0xAA 0x05 0x5A); "
         "Livox SDK2 (Mid-360) version 0, length field = size, ports 56300/56301 (points) 56401 (IMU); "
         "Livox SDK1 (Avia) version 5, data types 0-8 (1362 B for types 2 and 4), port 56001 (any); Ouster by port 7502 and the metadata's "
         "packet size";
}

const LidarFamily* find_lidar_family(std::string_view name) {
  for (const LidarFamily& family : lidar_families()) {
    if (family.name == name) return &family;
  }
  return nullptr;
}

const LidarFamily* lidar_family_of_model(std::string_view model) {
  // Model names are the makers' own, and their prefixes do not overlap.
  static constexpr std::pair<std::string_view, std::string_view> kPrefixes[] = {
      {"VLP-", "velodyne"}, {"HDL-", "velodyne"}, {"VLS-", "velodyne"}, {"Pandar", "hesai"},
      {"RS-", "robosense"}, {"Helios", "robosense"}, {"OS", "ouster"},
      {"Mid-360", "livox"}, {"Avia", "livox"}};
  for (const auto& [prefix, family] : kPrefixes)
    if (model.starts_with(prefix)) return find_lidar_family(family);
  return nullptr;
}

}  // namespace adit::drivers
