// Livox packet headers and IMU packets (layouts: livox_packet.hpp).
#include "adit/drivers/lidar/livox_packet.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "bytes.hpp"
#include "civil_time.hpp"

namespace adit::drivers {
namespace {

std::uint64_t le64(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint64_t>(bytes::le32(b, at)) | static_cast<std::uint64_t>(bytes::le32(b, at + 4)) << 32;
}

float le_f32(std::span<const std::uint8_t> b, std::size_t at) { return std::bit_cast<float>(bytes::le32(b, at)); }

// SDK1 timestamp: u64 ns for types 0 (no sync), 1 (PTP), 2 (reserved), 4 (PPS); type 3 (GPS) is
// UTC year-2000, month, day, hour and u32 µs within the hour.
std::optional<std::int64_t> sdk1_time_ns(std::span<const std::uint8_t> p, std::uint8_t type) {
  constexpr std::size_t kAt = 10;
  if (type == 3) {
    const std::uint32_t micros = bytes::le32(p, kAt + 4);
    const auto hour = seconds_since_epoch(CivilTime{2000 + p[kAt], p[kAt + 1], p[kAt + 2], p[kAt + 3], 0, 0});
    if (!hour || micros >= 3'600'000'000U) return std::nullopt;
    return *hour * 1'000'000'000LL + static_cast<std::int64_t>(micros) * 1000;
  }
  if (type > 4) return std::nullopt;
  const std::uint64_t ns = le64(p, kAt);
  if (ns > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max() / 2)) return std::nullopt;
  return static_cast<std::int64_t>(ns);
}

}  // namespace

std::optional<LivoxDataFormat> livox_data_format(LivoxProtocol protocol, std::uint8_t data_type) {
  if (protocol == LivoxProtocol::sdk2) {
    switch (data_type) {
      case kLivoxSdk2Imu: return LivoxDataFormat{kLivoxImuBytes, 1, 1, false, true};
      case kLivoxSdk2CartesianHigh: return LivoxDataFormat{14, 0, 1, false, false};
      case kLivoxSdk2CartesianLow: return LivoxDataFormat{8, 0, 1, false, false};
      case kLivoxSdk2Spherical: return LivoxDataFormat{10, 0, 1, true, false};
      default: return std::nullopt;
    }
  }
  switch (data_type) {
    case kLivoxSdk1Cartesian: return LivoxDataFormat{13, 100, 1, false, false};
    case kLivoxSdk1Spherical: return LivoxDataFormat{9, 100, 1, true, false};
    case kLivoxSdk1ExtendCartesian: return LivoxDataFormat{14, 96, 1, false, false};
    case kLivoxSdk1ExtendSpherical: return LivoxDataFormat{10, 96, 1, true, false};
    case kLivoxSdk1DualCartesian: return LivoxDataFormat{28, 48, 2, false, false};
    case kLivoxSdk1DualSpherical: return LivoxDataFormat{16, 48, 2, true, false};
    case kLivoxSdk1Imu: return LivoxDataFormat{kLivoxImuBytes, 1, 1, false, true};
    case kLivoxSdk1TripleCartesian: return LivoxDataFormat{42, 30, 3, false, false};
    case kLivoxSdk1TripleSpherical: return LivoxDataFormat{22, 30, 3, true, false};
    default: return std::nullopt;
  }
}

LivoxHeaderResult parse_livox_header(LivoxProtocol protocol, std::span<const std::uint8_t> p) {
  LivoxHeaderResult r;
  LivoxHeader& h = r.header;
  h.protocol = protocol;
  const auto fail = [&r](LivoxHeaderStatus status) {
    r.status = status;
    return r;
  };
  if (p.empty()) return fail(LivoxHeaderStatus::foreign);
  if (protocol == LivoxProtocol::sdk2) {
    if (p[0] != kLivoxSdk2Version) return fail(LivoxHeaderStatus::foreign);
    if (p.size() < kLivoxSdk2HeaderBytes) return fail(LivoxHeaderStatus::truncated);
    const std::size_t length = bytes::le16(p, 1);
    if (length > p.size()) return fail(LivoxHeaderStatus::truncated);
    if (length < p.size()) return fail(LivoxHeaderStatus::malformed);
    h.data_type = p[10];
    const auto format = livox_data_format(protocol, h.data_type);
    if (!format) return fail(LivoxHeaderStatus::malformed);
    h.format = *format;
    h.records = bytes::le16(p, 5);
    if (h.records == 0 || kLivoxSdk2HeaderBytes + h.records * format->record_bytes != p.size() ||
        (format->imu && h.records != 1)) {
      return fail(LivoxHeaderStatus::malformed);
    }
    h.record_interval_ns = static_cast<std::uint32_t>(std::uint32_t{bytes::le16(p, 3)} * 100U / h.records);
    h.sequence = bytes::le16(p, 7);
    h.time_type = p[11];
    const std::uint64_t ns = le64(p, 28);
    if (ns > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max() / 2)) {
      return fail(LivoxHeaderStatus::malformed);
    }
    h.timestamp_ns = static_cast<std::int64_t>(ns);
    r.status = LivoxHeaderStatus::ok;
    return r;
  }
  if (p[0] != kLivoxSdk1Version) return fail(LivoxHeaderStatus::foreign);
  if (p.size() < kLivoxSdk1HeaderBytes) return fail(LivoxHeaderStatus::truncated);
  h.data_type = p[9];
  const auto format = livox_data_format(protocol, h.data_type);
  if (!format) return fail(LivoxHeaderStatus::malformed);
  h.format = *format;
  h.records = format->records;
  const std::size_t size = kLivoxSdk1HeaderBytes + h.records * format->record_bytes;
  if (p.size() < size) return fail(LivoxHeaderStatus::truncated);
  if (p.size() > size) return fail(LivoxHeaderStatus::malformed);
  h.time_type = p[8];
  const auto t = sdk1_time_ns(p, h.time_type);
  if (!t) return fail(LivoxHeaderStatus::malformed);
  h.timestamp_ns = *t;
  r.status = LivoxHeaderStatus::ok;
  return r;
}

std::optional<LivoxImuReading> decode_livox_imu(std::span<const std::uint8_t> p) {
  for (const LivoxProtocol protocol : {LivoxProtocol::sdk2, LivoxProtocol::sdk1}) {
    const LivoxHeaderResult r = parse_livox_header(protocol, p);
    if (r.status != LivoxHeaderStatus::ok || !r.header.format.imu) continue;
    const std::size_t at = protocol == LivoxProtocol::sdk2 ? kLivoxSdk2HeaderBytes : kLivoxSdk1HeaderBytes;
    LivoxImuReading imu;
    imu.sensor_time_ns = r.header.timestamp_ns;
    for (std::size_t k = 0; k < 3; ++k) {
      imu.gyro_rad_s[k] = le_f32(p, at + 4 * k);
      imu.accel_m_s2[k] = le_f32(p, at + 12 + 4 * k) * static_cast<float>(kLivoxStandardGravity);  // in float: no overflow
    }
    for (std::size_t k = 0; k < 3; ++k) {
      // NaN or absurd values (a damaged packet): no reading.
      if (!(std::abs(imu.gyro_rad_s[k]) < 1e4F) || !(std::abs(imu.accel_m_s2[k]) < 1e4F)) return std::nullopt;
    }
    return imu;
  }
  return std::nullopt;
}

}  // namespace adit::drivers
