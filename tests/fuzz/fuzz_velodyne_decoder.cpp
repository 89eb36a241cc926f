// Velodyne decoder + scan assembly on arbitrary payloads: each input is one
// packet, decoded by every model and azimuth model. Seeds: the UDP payloads of
// the real captures (fuzz_velodyne_decoder.seeds).
#include <cstddef>
#include <cstdint>
#include <span>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/velodyne.hpp"

namespace {
using namespace adit::drivers;

VelodyneCalibration calibration(std::size_t lasers) {
  VelodyneCalibration c;
  c.source = "fuzz";
  for (std::size_t i = 0; i < lasers; ++i) {
    VelodyneLaser l;
    l.laser_id = static_cast<int>(i);
    l.vert_correction = (static_cast<double>(i) / static_cast<double>(lasers) - 0.5) * 0.8;
    l.rot_correction = (i % 3 == 0) ? 0.07 : -0.02;
    l.dist_correction = 0.01;
    l.vert_offset_correction = 0.01;
    l.horiz_offset_correction = -0.02;
    c.lasers.push_back(l);
  }
  return c;
}

struct Fixture {
  VelodyneDecoder decoders[8] = {
      {VelodyneModel::vlp16, calibration(16)},
      {VelodyneModel::vlp32c, calibration(32)},
      {VelodyneModel::hdl32e, calibration(32)},
      {VelodyneModel::vls128, calibration(128)},
      {VelodyneModel::vlp16, calibration(16), {0.0F, 1000.0F, VelodyneAzimuthModel::reference_decoders}},
      {VelodyneModel::vlp32c, calibration(32), {0.0F, 1000.0F, VelodyneAzimuthModel::reference_decoders}},
      {VelodyneModel::hdl32e, calibration(32), {0.0F, 1000.0F, VelodyneAzimuthModel::reference_decoders}},
      {VelodyneModel::vls128, calibration(128), {0.0F, 1000.0F, VelodyneAzimuthModel::reference_decoders}},
  };
  ScanAssembler assembler{assembler_config_for(decoders[0], 1'327'104, 0.0F)};
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Fixture fixture;
  const std::span<const std::uint8_t> payload(data, size);
  for (VelodyneDecoder& decoder : fixture.decoders) {
    const DecodedPacket packet = decoder.decode(payload, 1'700'000'000'000'000'000);
    for (const DecodedPoint& p : packet.points) {
      // Every decoded value must be finite and the azimuth in range.
      if (!(p.azimuth_deg >= 0.0F && p.azimuth_deg < 360.0F) || !(p.point.range_m == p.point.range_m)) __builtin_trap();
    }
    fixture.assembler.add(packet);
  }
  return 0;
}
