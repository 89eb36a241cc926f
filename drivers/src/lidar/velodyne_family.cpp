// The Velodyne entry of the LiDAR registry.
#include "adit/common/error.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/lidar/velodyne.hpp"

namespace adit::drivers {

LidarFamily velodyne_family() {
  LidarFamily f;
  f.name = "velodyne";
  f.detect = [](std::span<const std::uint8_t> payload, std::uint16_t) -> std::string {
    const auto model = velodyne_model_from_packet(payload);
    return model ? std::string(to_string(*model)) : std::string();
  };
  f.make_decoder = [](const std::string& model, const std::filesystem::path& calibration) -> std::unique_ptr<LidarDecoder> {
    const auto m = velodyne_model_from_name(model);
    if (!m) throw InputError("", "model", "not a Velodyne model: " + model);
    if (calibration.empty()) {
      throw InputError("", "calibration", "the " + model + " needs its calibration YAML (--calibration)");
    }
    return std::make_unique<VelodyneDecoder>(*m, load_velodyne_calibration(calibration));
  };
  f.packet_period_ns = [](const std::string& model, std::span<const std::uint8_t> payload) -> std::int64_t {
    const auto m = velodyne_model_from_name(model);
    const auto mode = velodyne_return_mode_from_packet(payload);
    return m ? velodyne_packet_period_ns(*m, mode.value_or(VelodyneReturnMode::strongest)) : 0;
  };
  return f;
}

}  // namespace adit::drivers
