// Hesai's entry in the LiDAR registry (registry.cpp).
#include "adit/common/error.hpp"
#include "adit/drivers/lidar/hesai.hpp"
#include "adit/drivers/lidar/registry.hpp"

namespace adit::drivers {

LidarFamily hesai_family() {
  LidarFamily f;
  f.name = "hesai";
  f.detect = [](std::span<const std::uint8_t> payload, std::uint16_t) -> std::string {
    const auto model = hesai_model_from_packet(payload);
    return model ? std::string(hesai_model_name(*model)) : std::string();
  };
  f.make_decoder = [](const std::string& model, const std::filesystem::path& calibration) -> std::unique_ptr<LidarDecoder> {
    if (calibration.empty()) {
      throw InputError("", "calibration", "the " + model + " needs its angle-correction CSV (--calibration)");
    }
    return make_hesai_decoder(model, calibration);
  };
  f.packet_period_ns = [](const std::string& model, std::span<const std::uint8_t> payload) -> std::int64_t {
    const auto m = hesai_model_from_name(model);
    return m ? hesai_packet_period_ns(*m, payload) : 0;
  };
  return f;
}

}  // namespace adit::drivers
