// LivoxDecoder: Livox SDK1/SDK2 point packets into points with per-point times
// (layouts in livox_packet.hpp, scan cutting by time phase in livox.hpp).
#include "adit/drivers/lidar/livox.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <string>

#include "adit/common/error.hpp"
#include "bytes.hpp"

namespace adit::drivers {
namespace {

constexpr std::size_t kAngleSteps = 36000;  // 0.01°
constexpr float kLastPhaseDeg = 359.9999F;
constexpr std::size_t kMaxSdk2Points = (1472 - kLivoxSdk2HeaderBytes) / 8;

std::string lower_alnum(std::string_view s) {
  std::string out;
  for (const char c : s) {
    if (std::isalnum(static_cast<unsigned char>(c)) != 0) out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

std::int32_t le_i32(const std::uint8_t* p) {
  return static_cast<std::int32_t>(std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
                                   std::uint32_t{p[3]} << 24);
}
std::int16_t le_i16(const std::uint8_t* p) { return static_cast<std::int16_t>(p[0] | p[1] << 8); }
std::uint16_t le_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
std::uint32_t le_u32(const std::uint8_t* p) { return static_cast<std::uint32_t>(le_i32(p)); }

}  // namespace

std::optional<LivoxModel> livox_model_from_name(std::string_view name) {
  const std::string n = lower_alnum(name);
  if (n == "mid360" || n == "livoxmid360") return LivoxModel::mid360;
  if (n == "avia" || n == "livoxavia") return LivoxModel::avia;
  return std::nullopt;
}

std::string_view livox_model_name(LivoxModel model) { return model == LivoxModel::mid360 ? "Mid-360" : "Avia"; }
LivoxProtocol livox_protocol(LivoxModel model) {
  return model == LivoxModel::mid360 ? LivoxProtocol::sdk2 : LivoxProtocol::sdk1;
}
std::uint16_t livox_lines(LivoxModel model) { return model == LivoxModel::mid360 ? 4 : 6; }
std::uint32_t livox_record_period_ns(LivoxModel model) { return model == LivoxModel::mid360 ? 0 : 4167; }
std::uint16_t livox_imu_port(LivoxModel model) { return model == LivoxModel::mid360 ? kLivoxMid360ImuPort : 0; }
std::array<double, 3> livox_imu_position_m(LivoxModel model) {
  return model == LivoxModel::mid360 ? std::array<double, 3>{0.011, 0.02329, -0.04412}
                                     : std::array<double, 3>{-0.04165, -0.02326, 0.0284};
}

std::optional<LivoxModel> livox_model_from_packet(std::span<const std::uint8_t> payload) {
  for (const LivoxModel model : {LivoxModel::mid360, LivoxModel::avia}) {
    if (parse_livox_header(livox_protocol(model), payload).status == LivoxHeaderStatus::ok) return model;
  }
  return std::nullopt;
}

std::int64_t livox_packet_period_ns(LivoxModel model, std::span<const std::uint8_t> payload) {
  const LivoxHeaderResult r = parse_livox_header(livox_protocol(model), payload);
  if (r.status != LivoxHeaderStatus::ok || r.header.format.imu) return 0;
  const std::uint32_t record_ns =
      r.header.protocol == LivoxProtocol::sdk2 ? r.header.record_interval_ns : livox_record_period_ns(model);
  return static_cast<std::int64_t>(record_ns) * static_cast<std::int64_t>(r.header.records);
}

LivoxDecoder::LivoxDecoder(LivoxModel model, LivoxDecoderConfig config)
    : model_(model),
      protocol_(livox_protocol(model)),
      config_(config),
      lines_(livox_lines(model)),
      record_period_ns_(livox_record_period_ns(model)) {
  if (config_.frame_period_ns <= 0) throw InputError("", "frame_period", "the Livox frame period must be positive");
  sin_.resize(kAngleSteps);
  cos_.resize(kAngleSteps);
  for (std::size_t i = 0; i < kAngleSteps; ++i) {
    const double a = static_cast<double>(i) * std::numbers::pi / 18000.0;
    sin_[i] = static_cast<float>(std::sin(a));
    cos_[i] = static_cast<float>(std::cos(a));
  }
  // SDK2: one Ethernet frame's datagram (1472 bytes) holds at most (1472 - 36) / 8 = 179 points (the
  // Mid-360 sends 96); larger ones are malformed. SDK1: 100 records, or 30 x 3 returns.
  points_.resize(protocol_ == LivoxProtocol::sdk2 ? kMaxSdk2Points : 100);
}

std::uint16_t LivoxDecoder::default_port() const {
  return protocol_ == LivoxProtocol::sdk2 ? kLivoxMid360PointPort : kLivoxAviaDataPort;
}

DecodedPacket LivoxDecoder::decode(std::span<const std::uint8_t> payload, std::int64_t /*host_time_ns*/) {
  DecodedPacket out;
  const LivoxHeaderResult r = parse_livox_header(protocol_, payload);
  switch (r.status) {
    case LivoxHeaderStatus::ok: break;
    case LivoxHeaderStatus::foreign: out.status = PacketStatus::foreign; return out;
    case LivoxHeaderStatus::truncated: out.status = PacketStatus::truncated; return out;
    case LivoxHeaderStatus::malformed: out.status = PacketStatus::malformed; return out;
  }
  const LivoxHeader& h = r.header;
  out.sensor_time_ns = h.timestamp_ns;
  if (h.format.imu) {
    imu_ = decode_livox_imu(payload);
    out.status = imu_ ? PacketStatus::auxiliary : PacketStatus::malformed;
    return out;
  }
  if (h.records * h.format.returns > points_.size()) {
    out.status = PacketStatus::malformed;
    return out;
  }
  out.sequence = h.sequence;
  const bool sdk2 = h.protocol == LivoxProtocol::sdk2;
  const std::int64_t record_ns = sdk2 ? h.record_interval_ns : record_period_ns_;
  const std::uint8_t* data = payload.data() + (sdk2 ? kLivoxSdk2HeaderBytes : kLivoxSdk1HeaderBytes);
  const std::int64_t period = config_.frame_period_ns;
  const float phase_scale = 360.0F / static_cast<float>(period);
  const float min_range = config_.min_range_m;
  const float max_range = config_.max_range_m;
  const std::uint8_t type = h.data_type;
  std::size_t n = 0;
  for (std::size_t i = 0; i < h.records; ++i) {
    const std::uint8_t* rec = data + i * h.format.record_bytes;
    const std::int64_t t = h.timestamp_ns + static_cast<std::int64_t>(i) * record_ns;
    // In float, the last nanoseconds of a window round up to 360°: keep them in this window.
    const float phase = std::min(static_cast<float>(t % period) * phase_scale, kLastPhaseDeg);
    const auto ring = static_cast<std::uint16_t>(i % lines_);
    for (std::size_t k = 0; k < h.format.returns; ++k) {
      float x = 0.0F, y = 0.0F, z = 0.0F, range = 0.0F;
      std::uint8_t reflectivity = 0;
      if (!h.format.spherical) {
        // Cartesian: SDK2 high / SDK1 (extend, dual, triple) i32 mm; SDK2 low i16 cm.
        const bool low = sdk2 && type == kLivoxSdk2CartesianLow;
        const std::size_t ret_bytes = low ? 8 : (sdk2 || type != kLivoxSdk1Cartesian ? 14 : 13);
        const std::uint8_t* q = rec + k * ret_bytes;
        if (low) {
          x = static_cast<float>(le_i16(q)) * 0.01F;
          y = static_cast<float>(le_i16(q + 2)) * 0.01F;
          z = static_cast<float>(le_i16(q + 4)) * 0.01F;
          reflectivity = q[6];
        } else {
          x = static_cast<float>(le_i32(q)) * 0.001F;
          y = static_cast<float>(le_i32(q + 4)) * 0.001F;
          z = static_cast<float>(le_i32(q + 8)) * 0.001F;
          reflectivity = q[12];
        }
        range = std::sqrt(x * x + y * y + z * z);
      } else {
        // Spherical: depth u32 mm, zenith θ and azimuth φ in 0.01°. SDK1 dual/triple share one θ, φ.
        std::uint32_t depth = 0;
        std::uint16_t theta = 0, phi = 0;
        if (sdk2 || type == kLivoxSdk1Spherical || type == kLivoxSdk1ExtendSpherical) {
          depth = le_u32(rec);
          theta = le_u16(rec + 4);
          phi = le_u16(rec + 6);
          reflectivity = rec[8];
        } else {
          theta = le_u16(rec);
          phi = le_u16(rec + 2);
          const std::uint8_t* q = rec + 4 + 6 * k;
          depth = le_u32(q);
          reflectivity = q[4];
        }
        if (theta >= kAngleSteps || phi >= kAngleSteps) {
          out.status = PacketStatus::malformed;
          return out;
        }
        range = static_cast<float>(depth) * 0.001F;
        const float s = sin_[theta];
        x = range * s * cos_[phi];
        y = range * s * sin_[phi];
        z = range * cos_[theta];
      }
      if (range < min_range || range > max_range) continue;  // 0: no return
      DecodedPoint& d = points_[n++];
      d.point.x = x;
      d.point.y = y;
      d.point.z = z;
      d.point.intensity = reflectivity;
      d.point.range_m = range;
      d.point.time_offset_ns = 0;
      d.point.ring = ring;
      d.point.return_index = static_cast<std::uint8_t>(k);
      d.azimuth_deg = phase;
      d.sensor_time_ns = t;
    }
  }
  out.status = PacketStatus::ok;
  out.points = std::span<const DecodedPoint>(points_.data(), n);
  return out;
}

std::unique_ptr<LidarDecoder> make_livox_decoder(std::string_view model) {
  const auto which = livox_model_from_name(model);
  if (!which) throw InputError("", "model", "'" + std::string(model) + "' is not a Livox model this decoder knows");
  return std::make_unique<LivoxDecoder>(*which);
}

}  // namespace adit::drivers
