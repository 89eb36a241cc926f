// HesaiDecoder: one loop for every model, the layout and timing come from the
// model's row in hesai_models.cpp. Geometry (Hesai user manuals, "Point Cloud
// Data Analysis"): for channel c of a block with azimuth A,
//   azimuth = A + azimuth_correction[c], elevation = elevation_correction[c],
//   Hesai frame: x = r cos(el) sin(az), y = r cos(el) cos(az), z = r sin(el),
// which we rotate to x forward, y left: x = r cos(el) cos(az), y = -r cos(el) sin(az).
// sin/cos come from tables (per raw azimuth step and per channel) combined by
// the angle-addition identities, so decoding does no trigonometry.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/hesai.hpp"
#include "bytes.hpp"
#include "civil_time.hpp"
#include "hesai_spec.hpp"

namespace adit::drivers {
namespace {

constexpr std::size_t kAzimuthSteps = 36000;  // 0.01 degree per step
constexpr double kDegToRad = std::numbers::pi / 180.0;

// Hesai return-mode codes (tail byte): returns per firing, 0 when unknown.
std::uint8_t returns_of(std::uint8_t mode) {
  switch (mode) {
    case 0x33: case 0x34: case 0x37: case 0x38: return 1;  // first, second, strongest, last
    case 0x39: case 0x3A: case 0x3B: case 0x3C: return 2;  // last+strongest, first+second, first+last, first+strongest
    case 0x3D: return 3;                                    // first+last+strongest
    default: return 0;
  }
}

// Our return_index: 0 first/strongest, 1 second/last, from the position of a block in its firing group.
std::uint8_t return_index(std::uint8_t mode, std::size_t position, bool reversed_first_last) {
  if (mode == 0x39) return static_cast<std::uint8_t>(1 - position);  // sent as last, strongest
  if (mode == 0x3B && reversed_first_last) return static_cast<std::uint8_t>(1 - position);
  return static_cast<std::uint8_t>(position);
}

}  // namespace

HesaiDecoder::HesaiDecoder(HesaiModel model, const HesaiAngleCorrection& angles)
    : spec_(hesai_spec(model)) {
  const std::size_t lasers = spec_.lasers;
  if (angles.elevation_deg.size() != lasers || angles.azimuth_deg.size() != lasers) {
    throw InputError("calibration", "channels",
                     fmt::format("{} needs {} channels, the angle correction has {}", spec_.name, lasers,
                                 angles.elevation_deg.size()));
  }
  std::vector<std::uint16_t> order(lasers);
  std::iota(order.begin(), order.end(), std::uint16_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::uint16_t a, std::uint16_t b) {
    return angles.elevation_deg[a] < angles.elevation_deg[b];
  });
  ring_.resize(lasers);
  for (std::size_t rank = 0; rank < lasers; ++rank) ring_[order[rank]] = static_cast<std::uint16_t>(rank);

  for (std::size_t c = 0; c < lasers; ++c) {
    const double el = angles.elevation_deg[c] * kDegToRad;
    const double az = angles.azimuth_deg[c] * kDegToRad;
    cos_el_.push_back(static_cast<float>(std::cos(el)));
    sin_el_.push_back(static_cast<float>(std::sin(el)));
    cos_az_off_.push_back(static_cast<float>(std::cos(az)));
    sin_az_off_.push_back(static_cast<float>(std::sin(az)));
  }
  cos_az_.resize(kAzimuthSteps);
  sin_az_.resize(kAzimuthSteps);
  for (std::size_t a = 0; a < kAzimuthSteps; ++a) {
    const double rad = static_cast<double>(a) * 0.01 * kDegToRad;
    cos_az_[a] = static_cast<float>(std::cos(rad));
    sin_az_[a] = static_cast<float>(std::sin(rad));
  }

  const std::size_t blocks = spec_.blocks;
  for (std::size_t r = 1; r <= 3; ++r) {
    for (std::size_t loop = 0; loop < 2; ++loop) {
      auto& table = firing_ns_[r - 1][loop];
      table.resize(blocks * lasers);
      std::int32_t earliest = std::numeric_limits<std::int32_t>::max();
      for (std::size_t b = 0; b < blocks; ++b) {
        for (std::size_t c = 0; c < lasers; ++c) {
          table[b * lasers + c] = hesai_firing_ns(spec_.model, r, loop, b, c);
          earliest = std::min(earliest, table[b * lasers + c]);
        }
      }
      earliest_ns_[r - 1][loop] = earliest;
    }
  }
  points_.resize(blocks * lasers);
}

HesaiDecoder::~HesaiDecoder() = default;

std::string_view HesaiDecoder::model() const { return spec_.name; }

DecodedPacket HesaiDecoder::decode(std::span<const std::uint8_t> p, std::int64_t /*host_time_ns*/) {
  DecodedPacket out;
  const Spec& s = spec_;
  // 1. Is it ours? Magic, then the header's identity (another Hesai model is foreign too).
  if (p.size() < 2) return out;
  float unit_m = static_cast<float>(s.fixed_distance_unit_mm) * 0.001F;
  switch (s.framing) {
    case HesaiFraming::preheader12:
      if (p[0] != 0xEE || p[1] != 0xFF) return out;
      if (p.size() < 12) return out.status = PacketStatus::truncated, out;
      if (p[2] != s.protocol_major || p[6] != s.lasers || p[7] != s.blocks) return out;
      unit_m = static_cast<float>(p[9]) * 0.001F;
      break;
    case HesaiFraming::header8:
      if (p[0] != 0xEE || p[1] != 0xFF) return out;
      if (p.size() < 8) return out.status = PacketStatus::truncated, out;
      if (p[2] != s.lasers || p[3] != s.blocks) return out;
      unit_m = static_cast<float>(p[5]) * 0.001F;
      break;
    case HesaiFraming::sob_blocks:
      if (p[0] != 0xFF || p[1] != 0xEE) return out;
      // The Velodyne block flag is the same 0xFFEE: the size tells them apart.
      if (p.size() > s.max_packet_bytes() || p.size() == 1206) return out;
      break;
  }
  // 2. Size (QT128: the size the header's flags announce, exactly).
  const HesaiPacketLayout layout = hesai_packet_layout(s, p);
  if (p.size() < layout.min_bytes) return out.status = PacketStatus::truncated, out;
  if (p.size() > layout.max_bytes) return out.status = PacketStatus::malformed, out;

  // 3. Tail: return mode, time.
  const std::size_t tail = layout.tail;
  const std::uint8_t mode = p[tail + s.tail_return_mode];
  const std::size_t returns = returns_of(mode);
  const std::size_t date = tail + s.tail_date_time;
  const int year_byte = p[date];
  const std::uint32_t micros = bytes::le32(p, tail + s.tail_timestamp);
  std::optional<std::int64_t> seconds;
  if (s.year_either_century && year_byte == 0) {
    seconds = static_cast<std::int64_t>(std::uint32_t{p[date + 2]} << 24 | std::uint32_t{p[date + 3]} << 16 |
                                        std::uint32_t{p[date + 4]} << 8 | std::uint32_t{p[date + 5]});
  } else {
    const int year = s.year_either_century && year_byte < 100 ? 2000 + year_byte : s.year_base + year_byte;
    seconds = seconds_since_epoch(CivilTime{year, p[date + 1], p[date + 2], p[date + 3], p[date + 4], p[date + 5]});
  }
  if (returns == 0 || s.blocks % returns != 0 || unit_m <= 0.0F || !seconds || micros >= 1'000'000U) {
    return out.status = PacketStatus::malformed, out;
  }
  const std::int64_t packet_ns = *seconds * 1'000'000'000LL + static_cast<std::int64_t>(micros) * 1000;
  // QT128 firing loop of block b (Hesai SDK 2.0, udp3_2_parser.cc): (mode flag + b / returns + 1) % 2,
  // 0 = loop 1. nebula's pandar_qt128.hpp agrees for multi-return and for mode flag 1 in single return.
  const unsigned mode_flag = s.tail_mode_flag != kNoField ? p[tail + s.tail_mode_flag] & 0x01U : 0U;
  const std::size_t loop_of_packet = (mode_flag + 1U) % 2U;
  if (layout.sequence_at != 0) out.sequence = bytes::le32(p, layout.sequence_at);
  else if (p.size() >= layout.min_bytes + 4) out.sequence = bytes::le32(p, layout.min_bytes);
  info_ = {mode, static_cast<std::uint8_t>(returns), bytes::le16(p, tail + s.tail_motor_speed), unit_m};

  // 4. Blocks. All blocks of one firing group share the first block's azimuth.
  const std::size_t lasers = s.lasers;
  const std::size_t block_bytes = layout.block_bytes;
  const std::size_t unit_bytes = layout.unit_bytes;
  const std::size_t body = s.header_bytes();
  std::size_t n = 0;
  for (std::size_t b = 0; b < s.blocks; ++b) {
    const std::size_t at = body + b * block_bytes;
    if (s.framing == HesaiFraming::sob_blocks && (p[at] != 0xFF || p[at + 1] != 0xEE)) {
      return out.status = PacketStatus::malformed, out;
    }
    const std::size_t group_at = body + (b - b % returns) * block_bytes + s.block_prefix_bytes();
    const std::uint16_t raw_az = bytes::le16(p, group_at);
    if (raw_az >= kAzimuthSteps) return out.status = PacketStatus::malformed, out;
    // QT128 alternates loops firing by firing, starting from the one the tail's mode flag names.
    const std::size_t loop = s.two_loops() ? (loop_of_packet + b / returns) % 2 : 0;
    const std::int32_t* firing = firing_ns_[returns - 1][loop].data() + b * lasers;
    const float ca = cos_az_[raw_az];
    const float sa = sin_az_[raw_az];
    // The encoder azimuth of the firing, not the beam's corrected direction: scans are cut
    // between firings, as the sensor's own tools do, so per-channel corrections of up to
    // ~9 deg (QT64) cannot split one firing across two scans.
    const float az_deg = static_cast<float>(raw_az) * 0.01F;
    const std::uint8_t ret = return_index(mode, b % returns, s.reversed_first_last);
    const std::uint8_t* unit = p.data() + at + s.block_prefix_bytes() + 2;
    for (std::size_t c = 0; c < lasers; ++c, unit += unit_bytes) {
      const std::uint16_t raw = static_cast<std::uint16_t>(unit[0] | (unit[1] << 8));
      if (raw == 0) continue;  // no return
      const float r = static_cast<float>(raw) * unit_m;
      const float xy = r * cos_el_[c];
      const float cos_az = ca * cos_az_off_[c] - sa * sin_az_off_[c];
      const float sin_az = sa * cos_az_off_[c] + ca * sin_az_off_[c];
      DecodedPoint& d = points_[n++];
      d.point.x = xy * cos_az;
      d.point.y = -xy * sin_az;
      d.point.z = r * sin_el_[c];
      d.point.intensity = unit[2];
      d.point.range_m = r;
      d.point.time_offset_ns = 0;
      d.point.ring = ring_[c];
      d.point.return_index = ret;
      d.azimuth_deg = az_deg;
      d.sensor_time_ns = packet_ns + firing[c];
    }
  }
  out.status = PacketStatus::ok;
  out.sensor_time_ns = packet_ns + earliest_ns_[returns - 1][s.two_loops() ? loop_of_packet : 0];
  out.points = std::span<const DecodedPoint>(points_.data(), n);
  return out;
}

std::unique_ptr<LidarDecoder> make_hesai_decoder(std::string_view model,
                                                 const std::filesystem::path& calibration_csv) {
  const auto which = hesai_model_from_name(model);
  if (!which) {
    throw InputError(calibration_csv.string(), "model",
                     fmt::format("'{}' is not a Hesai model this decoder knows", model));
  }
  return std::make_unique<HesaiDecoder>(*which, load_hesai_angle_csv(calibration_csv));
}

}  // namespace adit::drivers
