#include "adit/drivers/lidar/livox_encoder.hpp"

#include <algorithm>
#include <array>
#include <bit>

namespace adit::drivers {
namespace {

constexpr std::array<std::uint32_t, 256> crc32_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr auto kCrc32 = crc32_table();

void put16(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put32(std::uint8_t* p, std::uint32_t v) {
  put16(p, v & 0xFFFF);
  put16(p + 2, v >> 16);
}
void put64(std::uint8_t* p, std::uint64_t v) {
  put32(p, static_cast<std::uint32_t>(v));
  put32(p + 4, static_cast<std::uint32_t>(v >> 32));
}
void put_point(std::uint8_t* q, const LivoxRawPoint& pt) {
  put32(q, static_cast<std::uint32_t>(pt.x_mm));
  put32(q + 4, static_cast<std::uint32_t>(pt.y_mm));
  put32(q + 8, static_cast<std::uint32_t>(pt.z_mm));
  q[12] = pt.reflectivity;
  q[13] = pt.tag;
}
void put_imu(std::uint8_t* q, const float (&gyro)[3], const float (&accel)[3]) {
  for (std::size_t k = 0; k < 3; ++k) {
    put32(q + 4 * k, std::bit_cast<std::uint32_t>(gyro[k]));
    put32(q + 12 + 4 * k, std::bit_cast<std::uint32_t>(accel[k]));
  }
}
void sdk2_header(std::uint8_t* p, std::size_t length, std::uint16_t time_interval, std::size_t dots,
                 std::uint16_t udp_cnt, std::uint8_t frame_cnt, std::uint8_t data_type, std::uint8_t time_type,
                 std::int64_t time_ns) {
  p[0] = kLivoxSdk2Version;
  put16(p + 1, static_cast<std::uint32_t>(length));
  put16(p + 3, time_interval);
  put16(p + 5, static_cast<std::uint32_t>(dots));
  put16(p + 7, udp_cnt);
  p[9] = frame_cnt;
  p[10] = data_type;
  p[11] = time_type;
  put64(p + 28, static_cast<std::uint64_t>(time_ns));
}

}  // namespace

std::uint32_t livox_crc32(std::span<const std::uint8_t> data) {
  std::uint32_t c = 0xFFFFFFFFU;
  for (const std::uint8_t b : data) c = kCrc32[(c ^ b) & 0xFFU] ^ (c >> 8);
  return c ^ 0xFFFFFFFFU;
}

void encode_livox_sdk2_points(const LivoxSdk2PointPacket& packet, std::span<std::uint8_t> out) {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  sdk2_header(out.data(), out.size(), packet.time_interval, packet.points.size(), packet.udp_cnt, packet.frame_cnt,
              kLivoxSdk2CartesianHigh, packet.time_type, packet.time_ns);
  for (std::size_t i = 0; i < packet.points.size(); ++i) {
    put_point(out.data() + kLivoxSdk2HeaderBytes + 14 * i, packet.points[i]);
  }
  put32(out.data() + 24, livox_crc32(out.subspan(kLivoxSdk2HeaderBytes)));
}

void encode_livox_sdk2_imu(std::int64_t time_ns, std::uint16_t udp_cnt, const float (&gyro_rad_s)[3],
                           const float (&accel_g)[3], std::span<std::uint8_t> out) {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  sdk2_header(out.data(), out.size(), 0, 1, udp_cnt, 0, kLivoxSdk2Imu, 1, time_ns);
  put_imu(out.data() + kLivoxSdk2HeaderBytes, gyro_rad_s, accel_g);
  put32(out.data() + 24, livox_crc32(out.subspan(kLivoxSdk2HeaderBytes)));
}

void encode_livox_sdk1_points(std::int64_t time_ns, bool dual, std::span<const LivoxRawPoint, 96> points,
                              std::span<std::uint8_t> out) {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  out[0] = kLivoxSdk1Version;
  out[8] = 0;  // no synchronisation: u64 ns
  out[9] = dual ? kLivoxSdk1DualCartesian : kLivoxSdk1ExtendCartesian;
  put64(out.data() + 10, static_cast<std::uint64_t>(time_ns));
  // Dual records are two 14-byte returns back to back, so both layouts are 96 x 14 bytes in order.
  for (std::size_t i = 0; i < points.size(); ++i) put_point(out.data() + kLivoxSdk1HeaderBytes + 14 * i, points[i]);
}

void encode_livox_sdk1_imu(std::int64_t time_ns, const float (&gyro_rad_s)[3], const float (&accel_g)[3],
                           std::span<std::uint8_t> out) {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  out[0] = kLivoxSdk1Version;
  out[9] = kLivoxSdk1Imu;
  put64(out.data() + 10, static_cast<std::uint64_t>(time_ns));
  put_imu(out.data() + kLivoxSdk1HeaderBytes, gyro_rad_s, accel_g);
}

}  // namespace adit::drivers
