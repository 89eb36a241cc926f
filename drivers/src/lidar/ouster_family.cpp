// Ouster in the LiDAR registry. Ouster packets carry no magic number and their
// layout depends on the sensor's metadata, so a capture is recognised by the
// default lidar port alone and decoding needs the metadata JSON.

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/ouster_decoder.hpp"
#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "adit/drivers/lidar/registry.hpp"

namespace adit::drivers {
namespace {
constexpr std::uint16_t kDefaultLidarPort = 7502;
// The smallest lidar packet: 16 columns of 16 legacy pixels (16 + 16·12 + 4 bytes each).
constexpr std::size_t kSmallestPacket = 16 * (16 + 16 * 12 + 4);
}  // namespace

LidarFamily ouster_family() {
  LidarFamily f;
  f.name = "ouster";
  f.detect = [](std::span<const std::uint8_t> payload, std::uint16_t dst_port) -> std::string {
    return dst_port == kDefaultLidarPort && payload.size() >= kSmallestPacket ? "Ouster" : "";
  };
  f.make_decoder = [](const std::string& model, const std::filesystem::path& metadata) -> std::unique_ptr<LidarDecoder> {
    if (metadata.empty())
      throw InputError("", "calibration", "the " + model + " needs its sensor metadata JSON (--calibration)");
    return std::make_unique<OusterDecoder>(load_ouster_metadata(metadata));
  };
  // Loss is counted by frame id and column, not by time.
  f.packet_period_ns = [](const std::string&, std::span<const std::uint8_t>) -> std::int64_t { return 0; };
  return f;
}

}  // namespace adit::drivers
