#include "adit/drivers/lidar/hesai_encoder.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "civil_time.hpp"
#include "hesai_spec.hpp"

namespace adit::drivers {

void encode_hesai_xt32_packet(const HesaiXt32Packet& packet, std::span<std::uint8_t, kHesaiXt32PacketSize> out) {
  const HesaiDecoder::Spec& s = hesai_spec(HesaiModel::pandar_xt32);
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  out[0] = 0xEE;
  out[1] = 0xFF;
  out[2] = s.protocol_major;
  out[3] = 1;  // minor
  out[6] = static_cast<std::uint8_t>(s.lasers);
  out[7] = static_cast<std::uint8_t>(s.blocks);
  out[9] = 4;  // distance unit, mm
  out[10] = 1;  // returns
  const auto put16 = [&](std::size_t at, std::uint32_t v) {
    out[at] = static_cast<std::uint8_t>(v);
    out[at + 1] = static_cast<std::uint8_t>(v >> 8);
  };
  const std::size_t block_bytes = s.block_bytes();
  for (std::size_t b = 0; b < s.blocks; ++b) {
    const std::size_t at = s.header_bytes() + b * block_bytes;
    put16(at, packet.azimuth[b]);
    for (std::size_t c = 0; c < s.lasers; ++c) {
      const std::size_t unit = at + 2 + c * s.unit_bytes;
      put16(unit, packet.distance[b * 32 + c]);
      out[unit + 2] = packet.reflectivity[b * 32 + c];
    }
  }
  const std::size_t tail = s.tail_offset();
  out[tail + s.tail_return_mode] = 0x37;  // strongest
  put16(tail + s.tail_motor_speed, packet.rpm);
  const CivilTime t = civil_from_seconds(packet.time_ns / 1'000'000'000);
  const std::size_t date = tail + s.tail_date_time;
  out[date] = static_cast<std::uint8_t>(t.year - s.year_base);
  out[date + 1] = static_cast<std::uint8_t>(t.month);
  out[date + 2] = static_cast<std::uint8_t>(t.day);
  out[date + 3] = static_cast<std::uint8_t>(t.hour);
  out[date + 4] = static_cast<std::uint8_t>(t.minute);
  out[date + 5] = static_cast<std::uint8_t>(t.second);
  const auto micros = static_cast<std::uint32_t>(packet.time_ns / 1000 % 1'000'000);
  put16(tail + s.tail_timestamp, micros & 0xFFFF);
  put16(tail + s.tail_timestamp + 2, micros >> 16);
  put16(tail + s.tail_sequence, packet.sequence & 0xFFFF);
  put16(tail + s.tail_sequence + 2, packet.sequence >> 16);
}

HesaiAngleCorrection hesai_xt32_nominal_angles() {
  HesaiAngleCorrection a;
  for (int c = 0; c < 32; ++c) {
    a.elevation_deg.push_back(15.0F - static_cast<float>(c));
    a.azimuth_deg.push_back(0.0F);
  }
  return a;
}

std::string format_hesai_angle_csv(const HesaiAngleCorrection& angles) {
  std::string out = "Channel,Elevation,Azimuth\n";
  for (std::size_t i = 0; i < angles.elevation_deg.size(); ++i) {
    out += fmt::format("{},{:.3f},{:.3f}\n", i + 1, angles.elevation_deg[i], angles.azimuth_deg[i]);
  }
  return out;
}

}  // namespace adit::drivers
