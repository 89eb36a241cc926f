// libFuzzer target: any UDP payload through Ouster decoders of every profile
// and 16/32/64/128 beams. Nothing may crash, read out of bounds or return more
// points than it announced. Seeds: real payloads, extracted with
//   fuzz_seeds_from_pcap SEEDS ../shared/data/lidar/ouster/*.pcap
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <vector>

#include "adit/drivers/lidar/ouster_decoder.hpp"

namespace {

using adit::drivers::OusterDecoder;
using adit::drivers::OusterMetadata;
using adit::drivers::OusterProfile;

OusterMetadata metadata(OusterProfile profile, int beams) {
  OusterMetadata m;
  m.lidar_mode = "1024x10";
  m.columns_per_frame = 1024;
  m.columns_per_packet = 16;
  m.pixels_per_column = beams;
  for (int i = 0; i < beams; ++i) {
    m.beam_altitude_deg.push_back(22.5 - 45.0 * i / beams);
    m.beam_azimuth_deg.push_back(i % 4 - 1.5);
    m.pixel_shift_by_row.push_back(0);
  }
  m.lidar_origin_to_beam_origin_mm = 15.806;
  m.beam_to_lidar = {1, 0, 0, 15.806, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m.lidar_to_sensor = {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1};
  m.column_window = {0, 1023};
  m.lidar_profile = profile;
  return m;
}

std::vector<std::unique_ptr<OusterDecoder>> make_decoders() {
  std::vector<std::unique_ptr<OusterDecoder>> decoders;
  for (const auto profile : {OusterProfile::legacy, OusterProfile::rng19_rfl8_sig16_nir16,
                             OusterProfile::rng15_rfl8_nir8, OusterProfile::rng19_rfl8_sig16_nir16_dual})
    for (const int beams : {16, 32, 64, 128}) decoders.push_back(std::make_unique<OusterDecoder>(metadata(profile, beams)));
  return decoders;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto decoders = make_decoders();
  for (const auto& decoder : decoders) {
    const auto packet = decoder->decode(std::span<const std::uint8_t>(data, size), 0);
    if (packet.points.size() > decoder->max_points_per_packet()) std::abort();
    for (const auto& p : packet.points)
      if (!std::isfinite(p.point.x) || !(p.azimuth_deg >= 0.0F && p.azimuth_deg < 360.0F)) std::abort();
  }
  return 0;
}
