// Livox's entry in the LiDAR registry (registry.cpp): SDK2 packets are a Mid-360's, SDK1 packets
// an Avia's; no calibration file (the packets carry Cartesian points).
#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/registry.hpp"

namespace adit::drivers {

LidarFamily livox_family() {
  LidarFamily f;
  f.name = "livox";
  f.detect = [](std::span<const std::uint8_t> payload, std::uint16_t) -> std::string {
    // Point packets only: an IMU packet (another port) is not where the data is.
    const auto model = livox_model_from_packet(payload);
    return model && !decode_livox_imu(payload) ? std::string(livox_model_name(*model)) : std::string();
  };
  f.make_decoder = [](const std::string& model, const std::filesystem::path&) -> std::unique_ptr<LidarDecoder> {
    return make_livox_decoder(model);
  };
  f.packet_period_ns = [](const std::string& model, std::span<const std::uint8_t> payload) -> std::int64_t {
    const auto m = livox_model_from_name(model);
    return m ? livox_packet_period_ns(*m, payload) : 0;
  };
  return f;
}

}  // namespace adit::drivers
