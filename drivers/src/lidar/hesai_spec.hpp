#pragma once
// The per-model table behind HesaiDecoder: where each field sits in the
// packet and when each channel fires. One row per model; no per-model code.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adit/drivers/lidar/hesai.hpp"

namespace adit::drivers {

enum class HesaiFraming : std::uint8_t {
  preheader12,  // 0xEE 0xFF, protocol major/minor, 2 reserved, then 6-byte header
  header8,      // 0xEE 0xFF, lasers, blocks, reserved, distance unit, 2 reserved (Pandar64)
  sob_blocks,   // no header; each block starts with 0xFF 0xEE (Pandar40P)
};

inline constexpr std::uint16_t kNoField = 0xFFFF;

struct HesaiDecoder::Spec {
  HesaiModel model;
  std::string_view name;
  HesaiFraming framing;
  std::uint8_t protocol_major;   // preheader12 only
  std::uint16_t lasers;
  std::uint16_t blocks;
  std::uint8_t unit_bytes;       // distance u16, reflectivity u8[, confidence/reserved u8]
  std::uint8_t fixed_distance_unit_mm;  // for framings without a header (else from the header)
  std::uint16_t after_body_bytes;       // body CRC, functional safety, ... before the tail
  // Tail fields, offsets from the start of the tail.
  std::uint16_t tail_return_mode;
  std::uint16_t tail_motor_speed;
  std::uint16_t tail_date_time;  // year, month, day, hour, minute, second (u8 each)
  std::uint16_t tail_timestamp;  // u32 microseconds within the second
  std::uint16_t tail_mode_flag;  // kNoField unless the model alternates firing loops
  std::uint16_t tail_sequence;   // u32 UDP sequence, kNoField when absent
  std::uint16_t tail_bytes;      // the tail up to the last field we require
  int year_base;                 // the date-time's year is year_base + byte
  std::uint16_t optional_bytes;  // optional trailing fields a packet may carry
  bool reversed_first_last;      // dual first+last sent last-first (XT series)
  // QT128 (protocol 3.2): the header's flag byte says which optional parts the
  // packet carries (confidence byte per unit, functional safety, UDP sequence,
  // signature), so its layout is computed per packet (hesai_packet_layout).
  bool flag_driven_layout;
  // QT128: a year byte under 100 counts from 2000, else from 1900; a zero year
  // byte means bytes 2..5 of the date-time hold Unix seconds, big-endian
  // (Hesai SDK 2.0, udp_protocol_v3_2.h, GetMicroLidarTimeU64).
  bool year_either_century;

  // Firing time of (block b, channel c) relative to the packet's timestamp:
  //   block_base_ns + block_step_ns * k + channel offset, with
  //   k = (blocks - 1 - b) / returns (from_last) or b / returns, integer division,
  // so the returns of one firing share its time.
  std::int32_t block_base_ns;
  double block_step_ns;
  bool block_from_last;
  // Channel offsets: a table per firing loop, or base + step * (c % modulo).
  std::span<const std::int32_t> channel_loop[2];
  std::int32_t channel_base_ns;
  std::int32_t channel_step_ns;
  std::uint16_t channel_modulo;

  std::size_t header_bytes() const {
    return framing == HesaiFraming::preheader12 ? 12U : framing == HesaiFraming::header8 ? 8U : 0U;
  }
  std::size_t block_prefix_bytes() const { return framing == HesaiFraming::sob_blocks ? 2U : 0U; }
  std::size_t block_bytes() const {
    return block_prefix_bytes() + 2U + static_cast<std::size_t>(lasers) * unit_bytes;
  }
  std::size_t tail_offset() const {
    return header_bytes() + blocks * block_bytes() + after_body_bytes;
  }
  std::size_t min_packet_bytes() const { return tail_offset() + tail_bytes; }
  std::size_t max_packet_bytes() const { return min_packet_bytes() + optional_bytes; }
  bool two_loops() const { return !channel_loop[1].empty(); }
};

const HesaiDecoder::Spec& hesai_spec(HesaiModel model);

// Where the parts of one packet are. For a fixed layout it is the spec's; for a
// flag-driven layout (QT128) it follows the header's flag byte. A packet too
// short to hold the header gets the spec's (the size check rejects it).
struct HesaiPacketLayout {
  std::size_t unit_bytes = 0;
  std::size_t block_bytes = 0;
  std::size_t tail = 0;          // offset of the tail
  std::size_t min_bytes = 0;     // the packet's size without optional trailing fields
  std::size_t max_bytes = 0;     // with them
  std::size_t sequence_at = 0;   // offset of the u32 UDP sequence, 0 when absent
};
HesaiPacketLayout hesai_packet_layout(const HesaiDecoder::Spec& spec, std::span<const std::uint8_t> packet);

// QT128 header flag bits (Hesai SDK 2.0, udp_protocol_v3_2.h; QT128C2X manual, header "Flags").
inline constexpr std::uint8_t kHesaiFlagSequence = 0x01;
inline constexpr std::uint8_t kHesaiFlagFunctionalSafety = 0x04;
inline constexpr std::uint8_t kHesaiFlagSignature = 0x08;
inline constexpr std::uint8_t kHesaiFlagConfidence = 0x10;

}  // namespace adit::drivers
