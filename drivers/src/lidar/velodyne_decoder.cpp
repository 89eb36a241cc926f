#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/velodyne.hpp"

namespace adit::drivers {
namespace {

constexpr std::size_t kBlockSize = 100;
constexpr std::size_t kTimestampAt = 1200;
constexpr std::size_t kReturnModeAt = 1204;
constexpr std::size_t kProductAt = 1205;
constexpr std::size_t kPositionTimestampAt = 198;
constexpr std::size_t kPositionPpsAt = 202;
constexpr std::size_t kPositionNmeaAt = 206;
constexpr std::size_t kPositionNmeaSize = 306;  // to the end of the packet; the sentence ends at its "\r\n"
constexpr int kAzimuthSteps = 36000;             // 0.01° units
constexpr int kGapCentideg = 300;                // an advance this large between firing groups is a field-of-view gap

// Everything that distinguishes the models, from their manuals' packet and
// firing-timing chapters. Times in ns.
struct ModelSpec {
  VelodyneModel model;
  std::string_view name;
  std::uint8_t product_id;
  std::size_t lasers;
  float distance_resolution_m;
  std::size_t blocks_per_group;  // blocks that share one azimuth and time base
  std::uint32_t group_ns;        // one firing group (sequence) to the next
  // The packet's timestamp is this much after the first firing of its first group.
  std::int32_t timestamp_after_first_firing_ns;
  std::uint8_t other_product_id;  // a second product byte the model sends (0: none)
};

constexpr std::array<ModelSpec, 4> kModels{{
    // VLP-16: a block holds two 16-laser firing sequences of 55.296 µs; lasers 2.304 µs apart.
    {VelodyneModel::vlp16, "VLP-16", 0x22, 16, 0.002F, 1, 110'592, 0, 0x24},  // 0x24: Puck Hi-Res
    // VLP-32C: one 55.296 µs sequence per block; lasers fire in pairs, 2.304 µs apart; 4 mm unit.
    {VelodyneModel::vlp32c, "VLP-32C", 0x28, 32, 0.004F, 1, 55'296, 0, 0},
    // HDL-32E: one 46.08 µs sequence per block; lasers fire one by one, 1.152 µs apart.
    {VelodyneModel::hdl32e, "HDL-32E", 0x21, 32, 0.002F, 1, 46'080, 0, 0},
    // VLS-128: a 53.3 µs sequence spans 4 blocks (banks of 32 lasers, flags FFEE/FFDD/FFCC/FFBB);
    // 8 lasers fire together every 2.665 µs, with one idle slot after each 8 groups; 4 mm unit
    // (manual 63-9483 §9.3.1.3, whatever a calibration file says: ROS velodyne and nebula also
    // use a fixed 0.004). "ExactPointTime = Timestamp + TimeOffset - 8.7 µs" (§9.5; nebula's
    // offset_packet_time = 8.7 µs). Product byte 0xA1 (ROS velodyne VLS128_MODEL_ID = 161,
    // Alpha Prime) or 0x63 (VLP-16/VLS-128 manuals' table 9-2 "Factory Byte Values").
    {VelodyneModel::vls128, "VLS-128", 0xA1, 128, 0.004F, 4, 53'300, 8'700, 0x63},
}};

const ModelSpec& spec(VelodyneModel model) { return kModels[static_cast<std::size_t>(model)]; }

// How a packet's blocks hold firing groups in one return mode.
struct BlockLayout {
  std::size_t blocks;  // blocks carrying data, from the first
  std::size_t step;    // blocks per firing group
  std::size_t pair;    // blocks per bank: 2 in dual mode (last, strongest), else 1
};

// Dual mode doubles every block of a group into a (last, strongest) pair. A
// firing sequence may not span two packets (VLS-128 manual §9.3.1.1), so a
// VLS-128 dual packet holds one sequence in 8 blocks (FFEE, FFEE, FFDD, FFDD,
// FFCC, FFCC, FFBB, FFBB) and its last 4 blocks are padding.
BlockLayout block_layout(const ModelSpec& m, bool dual) {
  const std::size_t pair = dual ? 2 : 1;
  const std::size_t step = pair * m.blocks_per_group;
  return {VelodyneDecoder::kBlocks / step * step, step, pair};
}

// When channel `c` of block `g` (of its group) fires, after the group start, and which laser it is.
std::pair<std::uint16_t, std::uint32_t> slot_timing(VelodyneModel model, std::size_t g, std::size_t c) {
  switch (model) {
    case VelodyneModel::vlp16:
      return {static_cast<std::uint16_t>(c % 16), static_cast<std::uint32_t>((c / 16) * 55'296 + (c % 16) * 2'304)};
    case VelodyneModel::vlp32c:
      return {static_cast<std::uint16_t>(c), static_cast<std::uint32_t>((c / 2) * 2'304)};
    case VelodyneModel::hdl32e:
      return {static_cast<std::uint16_t>(c), static_cast<std::uint32_t>(c * 1'152)};
    case VelodyneModel::vls128: {
      const std::size_t laser = g * 32 + c;
      const std::size_t group = laser / 8;
      return {static_cast<std::uint16_t>(laser), static_cast<std::uint32_t>((group + group / 8) * 2'665)};
    }
  }
  return {0, 0};
}

std::uint16_t le16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
std::uint32_t le32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}

std::string lower_alnum(std::string_view s) {
  std::string out;
  for (const char c : s) {
    if (std::isalnum(static_cast<unsigned char>(c)) != 0) out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

}  // namespace

std::string_view to_string(VelodyneModel model) { return spec(model).name; }

std::optional<VelodyneModel> velodyne_model_from_name(std::string_view name) {
  const std::string n = lower_alnum(name);
  if (n == "vlp16" || n == "puck" || n == "puckhires" || n == "pucklite") return VelodyneModel::vlp16;
  if (n == "vlp32c" || n == "vlp32" || n == "ultrapuck") return VelodyneModel::vlp32c;
  if (n == "hdl32e" || n == "hdl32") return VelodyneModel::hdl32e;
  if (n == "vls128" || n == "alphaprime" || n == "vlp128") return VelodyneModel::vls128;
  return std::nullopt;
}

std::optional<VelodyneModel> velodyne_model_from_packet(std::span<const std::uint8_t> payload) {
  if (payload.size() != kVelodyneDataPacketSize || payload[0] != 0xFF || payload[1] != 0xEE) return std::nullopt;
  const std::uint8_t product = payload[kProductAt];
  for (const ModelSpec& m : kModels) {
    if (m.product_id == product || (m.other_product_id != 0 && m.other_product_id == product)) return m.model;
  }
  return std::nullopt;
}

std::optional<VelodyneReturnMode> velodyne_return_mode_from_packet(std::span<const std::uint8_t> payload) {
  if (payload.size() != kVelodyneDataPacketSize) return std::nullopt;
  switch (payload[kReturnModeAt]) {
    case 0x37: return VelodyneReturnMode::strongest;
    case 0x38: return VelodyneReturnMode::last;
    case 0x39: return VelodyneReturnMode::dual;
    default: return std::nullopt;
  }
}

std::int64_t velodyne_packet_period_ns(VelodyneModel model, VelodyneReturnMode mode) {
  const ModelSpec& m = spec(model);
  const BlockLayout layout = block_layout(m, mode == VelodyneReturnMode::dual);
  return static_cast<std::int64_t>(layout.blocks / layout.step) * m.group_ns;
}

std::size_t velodyne_lasers(VelodyneModel model) { return spec(model).lasers; }

VelodyneFiring velodyne_firing(VelodyneModel model, std::size_t block_in_group, std::size_t channel) {
  const auto [laser, time_ns] = slot_timing(model, block_in_group, channel);
  return {laser, time_ns};
}
std::uint32_t velodyne_group_ns(VelodyneModel model) { return spec(model).group_ns; }
std::size_t velodyne_blocks_per_group(VelodyneModel model) { return spec(model).blocks_per_group; }
float velodyne_distance_resolution_m(VelodyneModel model) { return spec(model).distance_resolution_m; }
std::uint8_t velodyne_product_id(VelodyneModel model) { return spec(model).product_id; }

VelodyneDecoder::VelodyneDecoder(VelodyneModel model, VelodyneCalibration calibration, VelodyneDecoderConfig config)
    : model_(model), calibration_(std::move(calibration)), config_(config) {
  const ModelSpec& m = spec(model);
  if (calibration_.lasers.size() != m.lasers) {
    throw InputError(calibration_.source, "lasers",
                     "lists " + std::to_string(calibration_.lasers.size()) + " lasers, the " + std::string(m.name) +
                         " has " + std::to_string(m.lasers));
  }
  // The VLS-128's unit is fixed by its protocol; older models' files may state theirs.
  distance_resolution_m_ = calibration_.distance_resolution_m > 0 && model != VelodyneModel::vls128
                               ? static_cast<float>(calibration_.distance_resolution_m)
                               : m.distance_resolution_m;
  blocks_per_group_ = m.blocks_per_group;
  group_ns_ = m.group_ns;

  // Rings count up from the lowest elevation (ties by laser id).
  std::vector<std::size_t> order(m.lasers);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return calibration_.lasers[a].vert_correction < calibration_.lasers[b].vert_correction;
  });
  lasers_.resize(m.lasers);
  for (std::size_t ring = 0; ring < order.size(); ++ring) {
    const VelodyneLaser& c = calibration_.lasers[order[ring]];
    Laser& l = lasers_[order[ring]];
    l.cos_vert = static_cast<float>(std::cos(c.vert_correction));
    l.sin_vert = static_cast<float>(std::sin(c.vert_correction));
    l.rot_centideg = c.rot_correction * 18000.0 / std::numbers::pi;
    l.cos_rot = static_cast<float>(std::cos(c.rot_correction));
    l.sin_rot = static_cast<float>(std::sin(c.rot_correction));
    l.dist_correction = static_cast<float>(c.dist_correction);
    l.vert_offset = static_cast<float>(c.vert_offset_correction);
    l.horiz_offset = static_cast<float>(c.horiz_offset_correction);
    l.ring = static_cast<std::uint16_t>(ring);
  }

  slots_.resize(blocks_per_group_ * kChannels);
  for (std::size_t g = 0; g < blocks_per_group_; ++g) {
    for (std::size_t c = 0; c < kChannels; ++c) {
      const auto [laser, time_ns] = slot_timing(model, g, c);
      slots_[g * kChannels + c] = {laser, time_ns, static_cast<float>(time_ns) / static_cast<float>(group_ns_)};
    }
  }

  cos_table_.resize(kAzimuthSteps);
  sin_table_.resize(kAzimuthSteps);
  for (int i = 0; i < kAzimuthSteps; ++i) {
    const double a = i * std::numbers::pi / 18000.0;
    cos_table_[i] = static_cast<float>(std::cos(a));
    sin_table_[i] = static_cast<float>(std::sin(a));
  }
  points_.resize(kMaxPoints);
}

std::int64_t VelodyneDecoder::min_packet_period_ns() const {
  return velodyne_packet_period_ns(model_, VelodyneReturnMode::dual);
}

std::size_t VelodyneDecoder::max_packet_bytes() const {
  return std::max(kVelodyneDataPacketSize, kVelodynePositionPacketSize);
}

DecodedPacket VelodyneDecoder::decode(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) {
  if (payload.size() == kVelodyneDataPacketSize) return decode_data(payload, host_time_ns);
  if (payload.size() == kVelodynePositionPacketSize) return decode_position(payload);
  DecodedPacket out;
  // A short packet that starts like a data block is ours, cut short.
  const bool looks_ours = payload.size() >= 2 && payload[0] == 0xFF && payload[1] == 0xEE;
  out.status = looks_ours && payload.size() < kVelodyneDataPacketSize ? PacketStatus::truncated : PacketStatus::foreign;
  return out;
}

DecodedPacket VelodyneDecoder::decode_position(std::span<const std::uint8_t> payload) {
  DecodedPacket out;
  VelodynePosition position;
  position.us_past_hour = le32(payload.data() + kPositionTimestampAt);
  position.pps_status = payload[kPositionPpsAt];
  if (position.us_past_hour >= 3'600'000'000u) {
    out.status = PacketStatus::malformed;
    return out;
  }
  const std::string_view nmea(reinterpret_cast<const char*>(payload.data() + kPositionNmeaAt), kPositionNmeaSize);
  const auto end = nmea.find('\n');
  position.rmc = parse_nmea_rmc(nmea.substr(0, end == std::string_view::npos ? 0 : end + 1));
  if (position.rmc && position.rmc->valid) clock_.anchor(position.us_past_hour, position.rmc->utc_ns);
  position_ = position;
  out.status = PacketStatus::auxiliary;
  return out;
}

int VelodyneDecoder::reference_azimuth(const std::array<int, kBlocks>& azimuth, std::size_t b, std::size_t c,
                                       bool dual, const Laser& laser, bool& rot_applied) const {
  // Base azimuth and advance per block as those decoders take them (see VelodyneAzimuthModel).
  int base = azimuth[b];
  float diff = 0.0F;
  if (!dual) {
    if (b + 1 < kBlocks) diff = static_cast<float>((azimuth[b + 1] - azimuth[b] + kAzimuthSteps) % kAzimuthSteps);
  } else if (b % 2 == 0) {
    if (b + 2 < kBlocks - 1) diff = static_cast<float>((azimuth[b + 2] - azimuth[b] + kAzimuthSteps) % kAzimuthSteps);
  } else {
    base = azimuth[std::min(b + 1, kBlocks - 1)];
  }
  rot_applied = false;
  switch (model_) {
    case VelodyneModel::vlp16: {
      const auto firing = static_cast<float>(c / 16);
      const auto dsr = static_cast<float>(c % 16);
      const float f = static_cast<float>(base) + (diff * (dsr * 2.304F + firing * 55.296F)) / 110.592F;
      return static_cast<int>(std::round(f)) % kAzimuthSteps;
    }
    case VelodyneModel::vlp32c: {
      const float f = static_cast<float>(base) + diff * 2.304F / 55.296F * static_cast<float>(c);
      double g = f - laser.rot_centideg;
      if (g < 0) g += kAzimuthSteps;
      rot_applied = true;
      return static_cast<int>(std::round(g)) % kAzimuthSteps;
    }
    default: return -1;  // same as manual
  }
}

int VelodyneDecoder::advance_from_previous_packet(std::uint32_t us_past_hour, int azimuth) {
  constexpr std::int64_t kHourUs = 3'600'000'000;
  if (previous_group_) {
    const std::int64_t dt_us = us_past_hour - static_cast<std::int64_t>(previous_group_->first);
    const std::int64_t dt_ns = (dt_us + kHourUs) % kHourUs * 1000;  // across the hour too
    const int moved = (azimuth - previous_group_->second + kAzimuthSteps) % kAzimuthSteps;
    // Only from a recent packet (a few lost at most), and not across a field-of-view gap.
    if (dt_ns > 0 && dt_ns <= 8 * static_cast<std::int64_t>(group_ns_)) {
      const long advance = std::lround(static_cast<double>(moved) * group_ns_ / static_cast<double>(dt_ns));
      if (advance <= kGapCentideg) carried_advance_ = static_cast<int>(advance);
    }
  }
  previous_group_ = std::pair{us_past_hour, azimuth};
  return carried_advance_;
}

DecodedPacket VelodyneDecoder::decode_data(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) {
  DecodedPacket out;
  const std::uint8_t* p = payload.data();
  const std::uint32_t us_past_hour = le32(p + kTimestampAt);
  const std::uint8_t mode_byte = p[kReturnModeAt];
  // 0 is what early HDL-32E firmware writes: strongest return.
  if (us_past_hour >= 3'600'000'000u || (mode_byte != 0 && (mode_byte < 0x37 || mode_byte > 0x39))) {
    out.status = PacketStatus::malformed;
    return out;
  }
  const bool dual = mode_byte == 0x39;
  const BlockLayout layout = block_layout(spec(model_), dual);
  // Validate every data block before decoding any: a damaged packet yields no points.
  std::array<int, kBlocks> azimuth{};
  for (std::size_t b = 0; b < layout.blocks; ++b) {
    const std::uint8_t* block = p + b * kBlockSize;
    const std::uint16_t flag = static_cast<std::uint16_t>(block[0] << 8 | block[1]);
    const std::size_t bank = (b % layout.step) / layout.pair;  // VLS-128 banks: FFEE, FFDD, FFCC, FFBB
    const std::uint16_t want = static_cast<std::uint16_t>(0xFFEE - 0x11 * bank);
    azimuth[b] = le16(block + 2);
    if (flag != want || azimuth[b] >= kAzimuthSteps) {
      out.status = b == 0 && flag != want ? PacketStatus::foreign : PacketStatus::malformed;
      return out;
    }
  }
  if (p[kProductAt] != 0 && p[kProductAt] != spec(model_).product_id &&
      !(spec(model_).other_product_id != 0 && p[kProductAt] == spec(model_).other_product_id)) {
    ++model_mismatches_;
  }
  return_mode_ = dual ? VelodyneReturnMode::dual
                      : (mode_byte == 0x38 ? VelodyneReturnMode::last : VelodyneReturnMode::strongest);

  // The first firing of the packet: the stamp less the model's lead (VLS-128: 8.7 µs).
  const std::int64_t packet_ns =
      clock_.resolve(us_past_hour, host_time_ns) - spec(model_).timestamp_after_first_firing_ns;
  out.sensor_time_ns = packet_ns;
  // Blocks of one firing group: 1 or the VLS-128's 4 banks, doubled in dual mode.
  const std::size_t step = layout.step;
  const float min_range = config_.min_range_m;
  const float max_range = config_.max_range_m;
  const bool reference_mode = config_.azimuth_model == VelodyneAzimuthModel::reference_decoders;
  const std::size_t groups = layout.blocks / step;
  // The azimuth advance from each firing group to the next, for interpolating
  // the firings in between. Sensors with a restricted field of view skip the
  // rest of the turn inside a packet: an advance far beyond the usual one is
  // such a gap, so the firings after it are interpolated with the usual
  // advance and timed after the gap at the current rotation rate.
  std::array<int, kBlocks> advance{};
  int smallest = 0;
  for (std::size_t k = 0; k + 1 < groups; ++k) {
    advance[k] = (azimuth[(k + 1) * step] - azimuth[k * step] + kAzimuthSteps) % kAzimuthSteps;
    if (advance[k] > 0 && (smallest == 0 || advance[k] < smallest)) smallest = advance[k];
  }
  const int gap_above = std::max(4 * smallest, kGapCentideg);
  // The usual advance: the mean of those that are not gaps (0.01° per group).
  int regular_sum = 0;
  int regular_count = 0;
  for (std::size_t k = 0; k + 1 < groups; ++k) {
    if (advance[k] <= gap_above) {
      regular_sum += advance[k];
      ++regular_count;
    }
  }
  const double usual = regular_count > 0 ? static_cast<double>(regular_sum) / regular_count : 0.0;
  // A packet of one group (VLS-128 dual) has no next group inside it: the advance comes from the previous packet.
  const int lone_group_advance = groups == 1 ? advance_from_previous_packet(us_past_hour, azimuth[0]) : 0;
  std::array<std::int64_t, kBlocks> group_time{};
  std::int64_t gap_ns = 0;
  for (std::size_t k = 0; k < groups; ++k) {
    group_time[k] = packet_ns + static_cast<std::int64_t>(k) * group_ns_ + gap_ns;
    if (k + 1 == groups) {
      advance[k] = k > 0 ? advance[k - 1] : lone_group_advance;  // the last group: the previous advance
    } else if (usual > 0.0 && advance[k] > gap_above) {
      gap_ns += std::llround((advance[k] - usual) * group_ns_ / usual);
      advance[k] = static_cast<int>(std::lround(usual));
      ++fov_gaps_;
    }
  }
  std::size_t n = 0;
  for (std::size_t b = 0; b < layout.blocks; ++b) {
    const std::size_t group = b / step;
    const int azimuth_diff = advance[group];
    const std::uint8_t* block = p + b * kBlockSize + 4;
    // Dual mode: a pair is (last return, strongest return); the other block of the pair.
    const std::uint8_t* partner = nullptr;
    if (dual) partner = b % 2 == 0 ? block + kBlockSize : block - kBlockSize;
    const bool last_block = dual && b % 2 == 0;
    const Slot* slots = slots_.data() + (b % step) / layout.pair * kChannels;  // the block's bank
    const std::int64_t group_ns = group_time[group];
    for (std::size_t c = 0; c < kChannels; ++c) {
      const std::uint8_t* m = block + 3 * c;
      const std::uint16_t raw = le16(m);
      if (raw == 0) continue;  // no return
      // The same echo reported as both last and strongest is one point, kept from the first block.
      const bool same_echo = partner != nullptr && le16(partner + 3 * c) == raw && partner[3 * c + 2] == m[2];
      if (same_echo && !last_block) continue;
      const Slot& slot = slots[c];
      const Laser& laser = lasers_[slot.laser];
      const float distance = static_cast<float>(raw) * distance_resolution_m_ + laser.dist_correction;
      if (distance < min_range || distance > max_range) continue;
      // Precision azimuth (VLP-16 manual §9.5): the block azimuth advanced by
      // the share of the group's rotation elapsed at this firing, in 0.01°.
      int az = static_cast<int>(std::lround(static_cast<float>(azimuth[b - b % step]) +
                                            static_cast<float>(azimuth_diff) * slot.azimuth_fraction)) %
               kAzimuthSteps;
      bool rot_applied = false;
      if (reference_mode) {
        const int reference = reference_azimuth(azimuth, b, c, dual, laser, rot_applied);
        if (reference >= 0) az = reference;
      }
      const float cos_az = cos_table_[az];
      const float sin_az = sin_table_[az];
      // θ = azimuth − rot_correction; Velodyne's azimuth turns clockwise, so y = −sin θ.
      const float cos_t = rot_applied ? cos_az : cos_az * laser.cos_rot + sin_az * laser.sin_rot;
      const float sin_t = rot_applied ? sin_az : sin_az * laser.cos_rot - cos_az * laser.sin_rot;
      const float xy = distance * laser.cos_vert - laser.vert_offset * laser.sin_vert;
      DecodedPoint& out_point = points_[n++];
      LidarPoint& point = out_point.point;
      point.x = xy * cos_t + laser.horiz_offset * sin_t;
      point.y = -xy * sin_t + laser.horiz_offset * cos_t;
      point.z = distance * laser.sin_vert + laser.vert_offset * laser.cos_vert;
      point.intensity = static_cast<float>(m[2]);
      point.range_m = distance;
      point.ring = laser.ring;
      point.return_index = last_block && !same_echo ? 1 : 0;
      point.time_offset_ns = 0;
      out_point.azimuth_deg = static_cast<float>(az) * 0.01F;
      out_point.sensor_time_ns = group_ns + slot.time_ns;
    }
  }
  out.status = PacketStatus::ok;
  out.points = std::span<const DecodedPoint>(points_.data(), n);
  return out;
}

}  // namespace adit::drivers
