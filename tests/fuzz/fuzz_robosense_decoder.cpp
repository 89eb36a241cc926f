// libFuzzer: any bytes into the RS-16 and Helios 16P decoders (MSOP and DIFOP).
// The first byte picks the decoder, so DIFOP state carries into later MSOP inputs.
#include <cstddef>
#include <cstdint>

#include "adit/drivers/lidar/robosense.hpp"

namespace {

adit::drivers::RoboSenseAngles angles() {
  adit::drivers::RoboSenseAngles a;
  for (int i = 0; i < 16; ++i) {
    a.elevation_deg.push_back(-15.0F + 2.0F * static_cast<float>(i));
    a.azimuth_deg.push_back(i % 2 == 0 ? -4.0F : 3.6F);
  }
  return a;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace adit::drivers;
  static RoboSenseDecoder rs16(RoboSenseModel::rs16, angles(), RoboSenseReturnMode::single);
  static RoboSenseDecoder helios(RoboSenseModel::helios16p, angles(), RoboSenseReturnMode::dual);
  for (RoboSenseDecoder* decoder : {&rs16, &helios}) {
    const DecodedPacket out = decoder->decode({data, size}, 0);
    if (out.points.size() > decoder->max_points_per_packet()) __builtin_trap();
  }
  return 0;
}
