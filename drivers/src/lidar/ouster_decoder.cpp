#include "adit/drivers/lidar/ouster_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace adit::drivers {
namespace {

using namespace ouster_le;

// Row index -> beam index counted from the lowest altitude (LidarPoint::ring).
std::vector<std::uint16_t> rings_by_altitude(const std::vector<double>& altitude_deg) {
  std::vector<std::uint16_t> order(altitude_deg.size());
  std::iota(order.begin(), order.end(), std::uint16_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint16_t a, std::uint16_t b) { return altitude_deg[a] < altitude_deg[b]; });
  std::vector<std::uint16_t> ring(altitude_deg.size());
  for (std::size_t i = 0; i < order.size(); ++i) ring[order[i]] = static_cast<std::uint16_t>(i);
  return ring;
}

// Decodes the columns of one size-checked packet; templated on the profile so
// the pixel layout is a compile-time constant in the inner loop.
template <OusterProfile kProfile>
struct ColumnDecoder {
  static std::size_t run(const OusterPacketLayout& layout, const std::uint8_t* packet, int width, int height,
                         const auto* rays, const float* azimuth_deg, const std::uint16_t* ring,
                         DecodedPoint* points, std::uint64_t& invalid_columns) {
    constexpr int kReturns = kProfile == OusterProfile::rng19_rfl8_sig16_nir16_dual ? 2 : 1;
    constexpr float kMetresPerMm = 0.001F;
    std::size_t n = 0;
    for (int c = 0; c < layout.columns_per_packet; ++c) {
      const std::uint8_t* col = layout.column(packet, c);
      const OusterColumnHeader h = read_column_header(layout, col);
      if (!h.valid || h.measurement_id >= width) {
        ++invalid_columns;
        continue;
      }
      const auto* ray = rays + static_cast<std::size_t>(h.measurement_id) * static_cast<std::size_t>(height);
      const float azimuth = azimuth_deg[h.measurement_id];
      const auto time_ns = static_cast<std::int64_t>(h.timestamp_ns);
      for (int row = 0; row < height; ++row) {
        const std::uint8_t* px = layout.pixel(col, row);
        for (int ret = 0; ret < kReturns; ++ret) {
          const OusterReturn r = read_return(kProfile, px, ret);
          if (r.range_mm == 0) continue;  // no return
          const float range = static_cast<float>(r.range_mm);
          DecodedPoint& dp = points[n];
          dp.point.x = range * ray[row].dx + ray[row].ox;
          dp.point.y = range * ray[row].dy + ray[row].oy;
          dp.point.z = range * ray[row].dz + ray[row].oz;
          dp.point.intensity = r.reflectivity;
          dp.point.range_m = range * kMetresPerMm;
          dp.point.time_offset_ns = 0;
          dp.point.ring = ring[row];
          dp.point.return_index = static_cast<std::uint8_t>(ret);
          dp.point.signal = r.signal;
          dp.point.near_ir = r.near_ir;
          dp.azimuth_deg = azimuth;
          dp.sensor_time_ns = time_ns;
          ++n;
        }
      }
    }
    return n;
  }
};

}  // namespace

OusterDecoder::OusterDecoder(const OusterMetadata& m)
    : layout_(OusterPacketLayout::of(m)),
      model_(m.prod_line.empty() ? std::string("Ouster") : m.prod_line),
      port_(m.udp_port_lidar),
      width_(m.columns_per_frame),
      height_(m.pixels_per_column),
      packets_per_frame_(static_cast<std::uint32_t>((m.columns_per_frame + m.columns_per_packet - 1) /
                                                    m.columns_per_packet)),
      packet_period_ns_(m.frame_rate_hz > 0 ? 1'000'000'000LL / m.frame_rate_hz / packets_per_frame_ : 0),
      rings_(rings_by_altitude(m.beam_altitude_deg)) {
  // The lookup table of the header comment, in double, stored as float.
  const auto& b2l = m.beam_to_lidar;
  const auto& l2s = m.lidar_to_sensor;
  const double n = std::hypot(b2l[3], b2l[11]);
  const double two_pi = 2.0 * std::numbers::pi;
  rays_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  column_azimuth_deg_.resize(static_cast<std::size_t>(width_));
  for (int col = 0; col < width_; ++col) {
    const double theta_e = two_pi * (1.0 - static_cast<double>(col) / width_);
    column_azimuth_deg_[static_cast<std::size_t>(col)] = static_cast<float>(360.0 * col / width_);
    for (int row = 0; row < height_; ++row) {
      const double theta_a = -two_pi * m.beam_azimuth_deg[static_cast<std::size_t>(row)] / 360.0;
      const double phi = two_pi * m.beam_altitude_deg[static_cast<std::size_t>(row)] / 360.0;
      // Lidar frame: p = r·u + (b·e - n·u), u the unit ray, e the encoder direction.
      const double u[3] = {std::cos(theta_e + theta_a) * std::cos(phi), std::sin(theta_e + theta_a) * std::cos(phi),
                           std::sin(phi)};
      const double o[3] = {b2l[3] * std::cos(theta_e) - n * u[0], b2l[3] * std::sin(theta_e) - n * u[1],
                           b2l[11] - n * u[2]};
      // Sensor frame: rotate both, translate the offset; then mm -> m.
      double d_s[3];
      double o_s[3];
      for (int i = 0; i < 3; ++i) {
        d_s[i] = l2s[4 * i] * u[0] + l2s[4 * i + 1] * u[1] + l2s[4 * i + 2] * u[2];
        o_s[i] = l2s[4 * i] * o[0] + l2s[4 * i + 1] * o[1] + l2s[4 * i + 2] * o[2] + l2s[4 * i + 3];
      }
      rays_[static_cast<std::size_t>(col) * height_ + row] = {
          static_cast<float>(d_s[0] * 1e-3), static_cast<float>(d_s[1] * 1e-3), static_cast<float>(d_s[2] * 1e-3),
          static_cast<float>(o_s[0] * 1e-3), static_cast<float>(o_s[1] * 1e-3), static_cast<float>(o_s[2] * 1e-3)};
    }
  }
  const std::size_t capacity =
      static_cast<std::size_t>(layout_.columns_per_packet) * static_cast<std::size_t>(height_) * layout_.returns;
  points_.resize(capacity);
}

std::size_t OusterDecoder::max_packet_bytes() const { return std::max(layout_.packet_bytes, kOusterImuPacketBytes); }

DecodedPacket OusterDecoder::decode(std::span<const std::uint8_t> payload, std::int64_t /*host_time_ns*/) {
  DecodedPacket out;
  std::size_t count = 0;
  const std::uint8_t* p = payload.data();
  if (payload.size() == kOusterImuPacketBytes && layout_.packet_bytes != kOusterImuPacketBytes) {
    decode_ouster_imu(payload, imu_);
    ++counters_.imu_packets;
    out.status = PacketStatus::auxiliary;
    out.sensor_time_ns = static_cast<std::int64_t>(imu_.system_time_ns);
    return out;
  }
  const bool legacy = layout_.profile == OusterProfile::legacy;
  // Ouster packets carry no magic: the size, the packet type (new profiles)
  // and a plausible first measurement id are what identify them.
  const auto ours = [&](std::size_t size) {
    if (legacy) return size >= 10 && u16(p + 8) < width_;
    return size >= 2 && u16(p) == 1;
  };
  if (payload.size() != layout_.packet_bytes) {
    out.status = payload.size() < layout_.packet_bytes && ours(payload.size()) ? PacketStatus::truncated
                                                                              : PacketStatus::foreign;
    return out;
  }
  if (!ours(payload.size())) {
    out.status = legacy ? PacketStatus::malformed : PacketStatus::foreign;
    return out;
  }
  const OusterColumnHeader first = read_column_header(layout_, layout_.column(p, 0));
  if (first.measurement_id >= width_) {
    out.status = PacketStatus::malformed;
    return out;
  }
  ++counters_.lidar_packets;
  const std::uint16_t frame_id = read_packet_frame_id(layout_, p);
  out.sequence = static_cast<std::uint32_t>(frame_id) * packets_per_frame_ +
                 static_cast<std::uint32_t>(first.measurement_id / layout_.columns_per_packet);
  out.sensor_time_ns = static_cast<std::int64_t>(first.timestamp_ns);

  const auto run = [&](auto decoder) {
    return decltype(decoder)::run(layout_, p, width_, height_, rays_.data(), column_azimuth_deg_.data(),
                                  rings_.data(), points_.data(), counters_.invalid_columns);
  };
  switch (layout_.profile) {
    case OusterProfile::legacy: count = run(ColumnDecoder<OusterProfile::legacy>{}); break;
    case OusterProfile::rng19_rfl8_sig16_nir16:
      count = run(ColumnDecoder<OusterProfile::rng19_rfl8_sig16_nir16>{});
      break;
    case OusterProfile::rng15_rfl8_nir8: count = run(ColumnDecoder<OusterProfile::rng15_rfl8_nir8>{}); break;
    case OusterProfile::rng19_rfl8_sig16_nir16_dual:
      count = run(ColumnDecoder<OusterProfile::rng19_rfl8_sig16_nir16_dual>{});
      break;
  }
  out.status = PacketStatus::ok;
  out.points = {points_.data(), count};
  return out;
}

}  // namespace adit::drivers
