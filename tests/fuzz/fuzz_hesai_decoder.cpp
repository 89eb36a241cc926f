// libFuzzer: any bytes into every Hesai model's decoder. Seeds: the captures'
// UDP payloads (fuzz_hesai_decoder.seeds).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "adit/drivers/lidar/hesai.hpp"

namespace {

adit::drivers::HesaiAngleCorrection angles(int lasers) {
  adit::drivers::HesaiAngleCorrection a;
  for (int c = 0; c < lasers; ++c) {
    a.elevation_deg.push_back(15.0F - 0.5F * static_cast<float>(c));
    a.azimuth_deg.push_back(c % 2 == 0 ? 5.0F : -5.0F);
  }
  return a;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace adit::drivers;
  static std::vector<std::unique_ptr<HesaiDecoder>> decoders = [] {
    std::vector<std::unique_ptr<HesaiDecoder>> all;
    for (const auto model : {HesaiModel::pandar_xt16, HesaiModel::pandar_xt32, HesaiModel::pandar_xt32m,
                             HesaiModel::pandar_qt64, HesaiModel::pandar_qt128, HesaiModel::pandar_40p,
                             HesaiModel::pandar_64}) {
      all.push_back(std::make_unique<HesaiDecoder>(model, angles(hesai_laser_count(model))));
    }
    return all;
  }();
  for (auto& decoder : decoders) {
    const DecodedPacket out = decoder->decode({data, size}, 0);
    if (out.points.size() > decoder->max_points_per_packet()) __builtin_trap();
    if (out.status != PacketStatus::ok && !out.points.empty()) __builtin_trap();
  }
  return 0;
}
