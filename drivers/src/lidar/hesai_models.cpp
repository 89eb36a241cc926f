// The Hesai model table: packet layouts and firing-time tables, from Hesai's
// user manuals (chapters "Data Structure" and "Laser Firing Time"; PandarXT16/
// XT32 and XT32M protocol 6.1, PandarQT64 3.x, QT128C2X 1.4, Pandar64, Pandar40P),
// cross-checked against the public nebula driver's documentation.
// Only XT32 and QT64 are verified against real captures (tests/drivers).

#include <array>
#include <cctype>
#include <cmath>

#include "hesai_spec.hpp"

namespace adit::drivers {
namespace {

// PandarQT64 manual, firing time of channels 1..64 within a block, ns.
// (Entry 56 is 129.60 us: the series steps by ~2.05 us.)
constexpr std::array<std::int32_t, 64> kQt64Channel = {
    12310,  14370,  16430,  18490,  20540,  22600,  24660,  26710,  29160,  31220,  33280,
    35340,  37390,  39450,  41500,  43560,  46610,  48670,  50730,  52780,  54840,  56900,
    58950,  61010,  63450,  65520,  67580,  69630,  71690,  73740,  75800,  77860,  80900,
    82970,  85020,  87080,  89140,  91190,  93250,  95300,  97750,  99820,  101870, 103930,
    105980, 108040, 110100, 112150, 115200, 117260, 119320, 121380, 123430, 125490, 127540,
    129600, 132050, 134110, 136170, 138220, 140280, 142340, 144390, 146450};

// Pandar40P manual, firing time of channels 1..40 before the block's end, ns.
constexpr std::array<std::int32_t, 40> kP40Channel = {
    -42220, -28470, -16040, -3620,  -45490, -31740, -47460, -54670, -20620, -33710,
    -40910, -8190,  -20620, -27160, -50730, -8190,  -14740, -36980, -45490, -52700,
    -23890, -31740, -38950, -11470, -18650, -25190, -48760, -6230,  -12770, -35010,
    -21920, -9500,  -43520, -29770, -17350, -4920,  -42220, -28470, -16040, -3620};

// Pandar64 manual, firing time of channels 1..64 before the block's end, ns.
constexpr std::array<std::int32_t, 64> kP64Channel = {
    -23180, -21876, -20572, -19268, -17964, -16660, -11444, -46796, -7532,  -36956, -50732,
    -54668, -40892, -44828, -31052, -34988, -48764, -52700, -38924, -42860, -29084, -33020,
    -46796, -25148, -36956, -50732, -27116, -40892, -44828, -31052, -34988, -48764, -25148,
    -38924, -42860, -29084, -33020, -52700, -6228,  -54668, -15356, -27116, -10140, -23180,
    -4924,  -21876, -14052, -17964, -8836,  -19268, -3620,  -20572, -12748, -16660, -7532,
    -11444, -6228,  -15356, -10140, -4924,  -3620,  -14052, -8836,  -12748};

// QT128C2X manual: the 128 channels fire in two alternating loops; a channel
// that does not fire in a loop has no entry there (0). Loop 1 fires channels 33..128.
constexpr std::array<std::int32_t, 128> kQt128Loop1 = {
    0,     0,     0,     0,     0,     0,     0,     0,     0,      0,     0,     0,     0,
    0,     0,     0,     0,     0,     0,     0,     0,     0,      0,     0,     0,     0,
    0,     0,     0,     0,     0,     0,     27656, 53000, 2312,   78344, 81512, 5480,  56168,
    30824, 33992, 59336, 8648,  84680, 87848, 11816, 62504, 37160,  40328, 65672, 14984, 91016,
    94184, 18152, 68840, 43496, 46664, 72008, 21320, 97352, 100520, 24488, 75176, 49832, 1456,
    77488, 26800, 52144, 55312, 29968, 80656, 4624,  7792,  83824,  33136, 58480, 61648, 36304,
    86992, 10960, 14128, 90160, 39472, 64816, 67984, 42640, 93328,  17296, 20464, 96496, 45808,
    71152, 74320, 48976, 99664, 23632, 25944, 51288, 600,   76632,  79800, 3768,  54456, 29112,
    32280, 57624, 6936,  82968, 86136, 10104, 60792, 35448, 38616,  63960, 13272, 89304, 92472,
    16440, 67128, 41784, 44952, 70296, 19608, 95640, 98808, 22776,  73464, 48120};
// Loop 2 fires channels 1..32 and 65..128.
constexpr std::array<std::int32_t, 128> kQt128Loop2 = {
    2312,  78344, 27656, 53000, 56168,  30824, 81512, 5480,  8648,  84680, 33992, 59336, 62504,
    37160, 87848, 11816, 14984, 91016,  40328, 65672, 68840, 43496, 94184, 18152, 21320, 97352,
    46664, 72008, 75176, 49832, 100520, 24488, 0,     0,     0,     0,     0,     0,     0,
    0,     0,     0,     0,     0,      0,     0,     0,     0,     0,     0,     0,     0,
    0,     0,     0,     0,     0,      0,     0,     0,     0,     0,     0,     0,     600,
    76632, 25944, 51288, 54456, 29112,  79800, 3768,  6936,  82968, 32280, 57624, 60792, 35448,
    86136, 10104, 13272, 89304, 38616,  63960, 67128, 41784, 92472, 16440, 19608, 95640, 44952,
    70296, 73464, 48120, 98808, 22776,  26800, 52144, 1456,  77488, 80656, 4624,  55312, 29968,
    33136, 58480, 7792,  83824, 86992,  10960, 61648, 36304, 39472, 64816, 14128, 90160, 93328,
    17296, 67984, 42640, 45808, 71152,  20464, 96496, 99664, 23632, 74320, 48976};

using Spec = HesaiDecoder::Spec;

// Protocol 6.1 tail (XT series): reserved[10], return mode, motor speed u16,
// date-time[6], timestamp u32, factory info, then the UDP sequence u32.
constexpr Spec xt_series(HesaiModel model, std::string_view name, std::uint16_t lasers,
                         std::uint16_t blocks, std::int32_t channel_step_ns, std::uint16_t modulo) {
  return Spec{model, name, HesaiFraming::preheader12, 6, lasers, blocks, 4, 0, 0,
              /*return_mode*/ 10, /*motor*/ 11, /*date*/ 13, /*timestamp*/ 19, kNoField,
              /*sequence*/ 24, /*tail_bytes*/ 28, 1900, /*optional*/ 0, true, false, false,
              // XT manuals: block m ends 50 us apart, the tail time is 5.632 us after the
              // last block's start; channel i fires 0.368 us + step * i after its block.
              5632, -50000.0, true, {{}, {}}, 368, channel_step_ns, modulo};
}

constexpr std::array<Spec, 7> kSpecs = {
    xt_series(HesaiModel::pandar_xt16, "PandarXT16", 16, 8, 3024, 16),
    xt_series(HesaiModel::pandar_xt32, "PandarXT32", 32, 8, 1512, 32),
    // XT32M fires its 32 channels as two banks of 16 in parallel.
    xt_series(HesaiModel::pandar_xt32m, "PandarXT32M", 32, 6, 2888, 16),
    // QT64 3.x tail: reserved[10], motor speed, timestamp, return mode, factory, date-time, sequence.
    // Blocks are 1/3 ms apart (600 rpm, 0.6 deg); the first fires 25.71 us after the tail time.
    Spec{HesaiModel::pandar_qt64, "PandarQT64", HesaiFraming::preheader12, 3, 64, 4, 4, 0, 0,
         16, 10, 18, 12, kNoField, 24, 28, 1900, 0, false, false, false,
         25710, 500000.0 / 3.0, false, {kQt64Channel, {}}, 0, 0, 64},
    // QT128C2X, protocol 3.2 (not 1.4: that is the Pandar128E3X, whose header also says
    // 128 lasers x 2 blocks). Hesai SDK 2.0 udp_protocol_v3_2.h and udp_parser.cc
    // ("case 3 / minor 2: QT128"); nebula pandar_qt128.hpp. Body: blocks of azimuth u16 and
    // 128 units of distance u16, reflectivity u8 [, confidence u8 when header flag 0x10], body
    // CRC u32, [functional safety, 17 bytes, flag 0x04], then the 26-byte tail: reserved[5],
    // mode flag, reserved[3], azimuth flag u16, working mode, return mode, motor speed u16,
    // date-time[6], timestamp u32, factory; [UDP sequence u32, flag 0x01], tail CRC u32,
    // [signature 32 bytes, flag 0x08]. The numbers below are the full packet (flags 0x1D:
    // 1127 bytes); hesai_packet_layout() follows the flags of each packet.
    Spec{HesaiModel::pandar_qt128, "PandarQT128", HesaiFraming::preheader12, 3, 128, 2, 4, 0, 21,
         12, 13, 15, 21, 5, 26, 34, 1900, 32, false, true, true,
         9000, 111110.0, true, {kQt128Loop1, kQt128Loop2}, 0, 0, 128},
    // Pandar40P: 10 blocks of (0xFFEE, azimuth, 40 x 3 bytes), then reserved[5], high-temperature
    // flag, reserved[2], motor speed, timestamp, return mode, factory, date-time (year - 2000),
    // optional UDP sequence. Blocks are 55.56 us apart; the tail time is after the last block.
    Spec{HesaiModel::pandar_40p, "Pandar40P", HesaiFraming::sob_blocks, 0, 40, 10, 3, 4, 0,
         14, 8, 16, 10, kNoField, kNoField, 22, 2000, 4, false, false, false,
         -28580, -55560.0, true, {kP40Channel, {}}, 0, 0, 40},
    // Pandar64: 8-byte header, 6 blocks of (azimuth, 64 x 3 bytes), the Pandar40P tail.
    Spec{HesaiModel::pandar_64, "Pandar64", HesaiFraming::header8, 0, 64, 6, 3, 0, 0,
         14, 8, 16, 10, kNoField, kNoField, 22, 2000, 4, false, false, false,
         -42580, -55560.0, true, {kP64Channel, {}}, 0, 0, 64},
};

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) {
      return false;
    }
  }
  return true;
}

}  // namespace

const HesaiDecoder::Spec& hesai_spec(HesaiModel model) {
  for (const auto& spec : kSpecs) {
    if (spec.model == model) return spec;
  }
  return kSpecs[1];  // unreachable: every enumerator has a row
}

std::optional<HesaiModel> hesai_model_from_name(std::string_view name) {
  for (const auto& spec : kSpecs) {
    if (iequals(spec.name, name)) return spec.model;
  }
  if (iequals(name, "PandarQT128C2X")) return HesaiModel::pandar_qt128;
  return std::nullopt;
}

std::string_view hesai_model_name(HesaiModel model) { return hesai_spec(model).name; }

HesaiPacketLayout hesai_packet_layout(const Spec& s, std::span<const std::uint8_t> p) {
  HesaiPacketLayout l;
  if (!s.flag_driven_layout || p.size() < s.header_bytes()) {
    l.unit_bytes = s.unit_bytes;
    l.block_bytes = s.block_bytes();
    l.tail = s.tail_offset();
    l.min_bytes = s.min_packet_bytes();
    l.max_bytes = s.max_packet_bytes();
    l.sequence_at = s.tail_sequence != kNoField ? l.tail + s.tail_sequence : 0;
    return l;
  }
  const std::uint8_t flags = p[11];
  constexpr std::size_t kBodyCrc = 4, kSafety = 17, kTail = 26, kSequence = 4, kTailCrc = 4, kSignature = 32;
  l.unit_bytes = (flags & kHesaiFlagConfidence) != 0 ? 4 : 3;
  l.block_bytes = 2 + s.lasers * l.unit_bytes;
  l.tail = s.header_bytes() + s.blocks * l.block_bytes + kBodyCrc + ((flags & kHesaiFlagFunctionalSafety) != 0 ? kSafety : 0);
  const bool sequence = (flags & kHesaiFlagSequence) != 0;
  l.sequence_at = sequence ? l.tail + kTail : 0;
  l.min_bytes = l.tail + kTail + (sequence ? kSequence : 0) + kTailCrc +
                ((flags & kHesaiFlagSignature) != 0 ? kSignature : 0);
  l.max_bytes = l.min_bytes;
  return l;
}

std::optional<HesaiModel> hesai_model_from_packet(std::span<const std::uint8_t> p) {
  for (const auto& s : kSpecs) {
    const HesaiPacketLayout layout = hesai_packet_layout(s, p);
    if (p.size() < layout.min_bytes || p.size() > layout.max_bytes) continue;
    const bool ours = s.framing == HesaiFraming::preheader12
                          ? p[0] == 0xEE && p[1] == 0xFF && p[2] == s.protocol_major && p[6] == s.lasers && p[7] == s.blocks
                      : s.framing == HesaiFraming::header8 ? p[0] == 0xEE && p[1] == 0xFF && p[2] == s.lasers && p[3] == s.blocks
                                                          : p[0] == 0xFF && p[1] == 0xEE && p[s.block_bytes()] == 0xFF;
    if (ours) return s.model;
  }
  return std::nullopt;
}

std::int64_t hesai_packet_period_ns(HesaiModel model, std::span<const std::uint8_t> p) {
  const Spec& s = hesai_spec(model);
  const HesaiPacketLayout layout = hesai_packet_layout(s, p);
  if (p.size() < layout.min_bytes) return 0;
  const std::uint8_t mode = p[layout.tail + s.tail_return_mode];
  const int returns = mode >= 0x33 && mode <= 0x38 ? 1 : mode >= 0x39 && mode <= 0x3C ? 2 : mode == 0x3D ? 3 : 0;
  if (returns == 0) return 0;
  return static_cast<std::int64_t>(std::llround(s.blocks / returns * std::abs(s.block_step_ns)));
}
std::uint16_t hesai_laser_count(HesaiModel model) { return hesai_spec(model).lasers; }
std::uint16_t hesai_block_count(HesaiModel model) { return hesai_spec(model).blocks; }

std::int32_t hesai_firing_ns(HesaiModel model, std::size_t returns, std::size_t loop, std::size_t block,
                             std::size_t channel) {
  const Spec& s = hesai_spec(model);
  const std::size_t k = (s.block_from_last ? s.blocks - 1 - block : block) / returns;
  const auto block_ns = s.block_base_ns + static_cast<std::int32_t>(std::lround(s.block_step_ns * static_cast<double>(k)));
  const auto& table = s.channel_loop[s.two_loops() ? loop : 0];
  const std::int32_t channel_ns =
      table.empty() ? s.channel_base_ns + s.channel_step_ns * static_cast<std::int32_t>(channel % s.channel_modulo)
                    : table[channel];
  return block_ns + channel_ns;
}

}  // namespace adit::drivers
