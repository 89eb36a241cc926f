// libFuzzer: any bytes into the Livox decoders (Mid-360 SDK2, Avia SDK1) and the
// IMU packet reader. Seeds: synthetic packets of each kind (fuzz_livox_decoder.seeds).
// Checks: never more points than the decoder's storage, none unless `ok`, every
// point's time inside the packet's span, an IMU reading only from an IMU packet.
#include <cstddef>
#include <cstdint>

#include "adit/drivers/lidar/livox.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace adit::drivers;
  static LivoxDecoder mid360(LivoxModel::mid360);
  static LivoxDecoder avia(LivoxModel::avia);
  const std::span<const std::uint8_t> bytes(data, size);
  for (LivoxDecoder* decoder : {&mid360, &avia}) {
    const DecodedPacket out = decoder->decode(bytes, 0);
    if (out.points.size() > decoder->max_points_per_packet()) __builtin_trap();
    if (out.status != PacketStatus::ok && !out.points.empty()) __builtin_trap();
    for (const DecodedPoint& p : out.points) {
      if (p.sensor_time_ns < out.sensor_time_ns) __builtin_trap();
      if (!(p.azimuth_deg >= 0.0F && p.azimuth_deg < 360.0F)) __builtin_trap();
    }
  }
  const auto imu = decode_livox_imu(bytes);
  if (imu && !livox_model_from_packet(bytes)) __builtin_trap();
  return 0;
}
