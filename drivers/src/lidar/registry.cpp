#include "adit/drivers/lidar/registry.hpp"

#include <array>

namespace adit::drivers {

std::span<const LidarFamily> lidar_families() {
  // One line per family.
  static const std::array kFamilies{
      velodyne_family(),
      hesai_family(),
      robosense_family(),
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
      {"RS-", "robosense"}, {"Helios", "robosense"}, {"OS", "ouster"}};
  for (const auto& [prefix, family] : kPrefixes)
    if (model.starts_with(prefix)) return find_lidar_family(family);
  return nullptr;
}

}  // namespace adit::drivers
