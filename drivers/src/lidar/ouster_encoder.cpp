#include "adit/drivers/lidar/ouster_encoder.hpp"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"

namespace adit::drivers {

OusterPacketEncoder::OusterPacketEncoder(const OusterPacketLayout& layout, std::span<std::uint8_t> packet)
    : layout_(layout), packet_(packet) {
  if (packet_.size() != layout_.packet_bytes)
    throw InputError("", "packet", "the buffer is not one packet of the layout");
  std::fill(packet_.begin(), packet_.end(), std::uint8_t{0});
  if (layout_.profile != OusterProfile::legacy) put(0, 1, 2);  // packet type: lidar
}

OusterPacketEncoder& OusterPacketEncoder::frame_id(std::uint16_t id) {
  if (layout_.profile != OusterProfile::legacy) {
    put(2, id, 2);
  } else {
    for (int c = 0; c < layout_.columns_per_packet; ++c) put(column(c) + 10, id, 2);
  }
  return *this;
}

OusterPacketEncoder& OusterPacketEncoder::column_header(int c, std::uint64_t timestamp_ns,
                                                        std::uint16_t measurement_id, bool valid) {
  put(column(c), timestamp_ns, 8);
  put(column(c) + 8, measurement_id, 2);
  if (layout_.profile == OusterProfile::legacy)
    put(column(c) + layout_.column_bytes - 4, valid ? 0xFFFFFFFFU : 0U, 4);
  else
    put(column(c) + 10, valid ? 1 : 0, 2);
  return *this;
}

OusterPacketEncoder& OusterPacketEncoder::encoder_count(int c, std::uint32_t count) {
  if (layout_.profile == OusterProfile::legacy) put(column(c) + 12, count, 4);
  return *this;
}

OusterPacketEncoder& OusterPacketEncoder::pixel_bytes(int c, int row, std::size_t offset, std::uint64_t value, int n) {
  put(column(c) + layout_.column_header_bytes + static_cast<std::size_t>(row) * layout_.pixel_bytes + offset, value, n);
  return *this;
}

OusterPacketEncoder& OusterPacketEncoder::pixel(int c, int row, std::uint32_t range_mm, std::uint8_t reflectivity,
                                                std::uint16_t signal, std::uint16_t near_ir) {
  switch (layout_.profile) {
    case OusterProfile::legacy:
    case OusterProfile::rng19_rfl8_sig16_nir16:
      pixel_bytes(c, row, 0, range_mm, 3);
      pixel_bytes(c, row, 4, reflectivity, 1);
      pixel_bytes(c, row, 6, signal, 2);
      pixel_bytes(c, row, 8, near_ir, 2);
      break;
    case OusterProfile::rng15_rfl8_nir8:
      pixel_bytes(c, row, 0, range_mm / 8, 2);
      pixel_bytes(c, row, 2, reflectivity, 1);
      pixel_bytes(c, row, 3, near_ir / 16, 1);
      break;
    case OusterProfile::rng19_rfl8_sig16_nir16_dual:
      pixel_bytes(c, row, 0, range_mm, 3);
      pixel_bytes(c, row, 3, reflectivity, 1);
      pixel_bytes(c, row, 8, signal, 2);
      pixel_bytes(c, row, 12, near_ir, 2);
      break;
  }
  return *this;
}

std::size_t OusterPacketEncoder::column(int c) const {
  return layout_.packet_header_bytes + static_cast<std::size_t>(c) * layout_.column_bytes;
}

void OusterPacketEncoder::put(std::size_t at, std::uint64_t value, int n) {
  for (int i = 0; i < n; ++i) packet_[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(value >> (8 * i));
}

OusterMetadata ouster_os1_64_nominal_metadata() {
  OusterMetadata m;
  m.legacy_layout = true;
  m.prod_line = "OS-1-64";
  m.prod_sn = "000000000000";
  m.firmware = "v2.2.0";  // the first with udp_profile_lidar
  m.lidar_mode = "1024x10";
  m.frame_rate_hz = 10;
  m.columns_per_frame = 1024;
  m.columns_per_packet = 16;
  m.pixels_per_column = 64;
  constexpr double kTop = 16.6;  // the datasheet's 33.2° vertical field of view
  constexpr double kStagger[4] = {3.13, 1.03, -1.08, -3.17};
  // Columns to shift each row by to line the beams up (the SDK's destaggering),
  // as firmware 2.1 reports them for an OS1-64 in 1024 columns.
  constexpr int kShift[4] = {19, 13, 7, 1};
  for (int i = 0; i < m.pixels_per_column; ++i) {
    m.beam_altitude_deg.push_back(std::round((kTop - 2.0 * kTop * i / (m.pixels_per_column - 1)) * 1000.0) / 1000.0);
    m.beam_azimuth_deg.push_back(kStagger[i % 4]);
    m.pixel_shift_by_row.push_back(kShift[i % 4]);
  }
  m.lidar_origin_to_beam_origin_mm = 12.163;
  m.beam_to_lidar = {1, 0, 0, m.lidar_origin_to_beam_origin_mm, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m.lidar_to_sensor = {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1};
  m.imu_to_sensor = {1, 0, 0, 6.253, 0, 1, 0, -11.775, 0, 0, 1, 7.645, 0, 0, 0, 1};
  m.column_window = {0, m.columns_per_frame - 1};
  m.lidar_profile = OusterProfile::legacy;
  return m;
}

std::string format_ouster_metadata(const OusterMetadata& m) {
  nlohmann::ordered_json j;
  j["prod_line"] = m.prod_line;
  j["prod_sn"] = m.prod_sn;
  j["build_rev"] = m.firmware;
  j["lidar_mode"] = m.lidar_mode;
  j["beam_altitude_angles"] = m.beam_altitude_deg;
  j["beam_azimuth_angles"] = m.beam_azimuth_deg;
  j["lidar_origin_to_beam_origin_mm"] = m.lidar_origin_to_beam_origin_mm;
  j["lidar_to_sensor_transform"] = m.lidar_to_sensor;
  j["imu_to_sensor_transform"] = m.imu_to_sensor;
  j["data_format"] = {{"columns_per_frame", m.columns_per_frame},
                      {"columns_per_packet", m.columns_per_packet},
                      {"pixels_per_column", m.pixels_per_column},
                      {"pixel_shift_by_row", m.pixel_shift_by_row},
                      {"column_window", m.column_window},
                      {"udp_profile_lidar", std::string(to_string(m.lidar_profile))},
                      {"udp_profile_imu", m.imu_profile}};
  j["udp_port_lidar"] = m.udp_port_lidar;
  j["udp_port_imu"] = m.udp_port_imu;
  return j.dump(4) + "\n";
}

}  // namespace adit::drivers
