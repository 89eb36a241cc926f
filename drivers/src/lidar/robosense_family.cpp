// RoboSense's entry in the LiDAR registry (registry.cpp). Without a DIFOP the
// decoder starts in single-return timing, the maker's SDK default; the first
// DIFOP sets the return mode and angles.
#include "adit/common/error.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/lidar/robosense.hpp"

namespace adit::drivers {

LidarFamily robosense_family() {
  LidarFamily f;
  f.name = "robosense";
  f.detect = [](std::span<const std::uint8_t> payload, std::uint16_t) -> std::string {
    const auto model = robosense_model_from_packet(payload);
    return model ? std::string(robosense_model_name(*model)) : std::string();
  };
  f.make_decoder = [](const std::string& model, const std::filesystem::path& calibration) -> std::unique_ptr<LidarDecoder> {
    if (calibration.empty()) {
      throw InputError("", "calibration", "the " + model + " needs its angle CSV (--calibration) until a DIFOP arrives");
    }
    return make_robosense_decoder(model, calibration, RoboSenseReturnMode::single);
  };
  // No packet counter and a block period that depends on the return mode: no time-based loss counting.
  f.packet_period_ns = [](const std::string&, std::span<const std::uint8_t>) -> std::int64_t { return 0; };
  return f;
}

}  // namespace adit::drivers
