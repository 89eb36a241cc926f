#pragma once
// Synthetic Hesai and RoboSense packets for unit tests, written from the user
// manuals' layouts independently of the decoders' model table.

#include <cstdint>
#include <string>
#include <vector>

namespace adit::test {

struct HesaiLayout {
  std::string model;
  int framing;  // 0: pre-header 12 bytes, 1: 8-byte header (Pandar64), 2: 0xFFEE blocks (Pandar40P)
  int protocol_major;
  int lasers, blocks, unit_bytes, after_body;
  int tail_bytes, t_return_mode, t_date, t_timestamp, t_sequence;  // -1: none
  int year_base;
  int protocol_minor = 1;
  int header_flags = 1;  // header byte 11: bit 0 UDP sequence (QT128: also 0x04 safety, 0x08 signature, 0x10 confidence)
};

inline std::vector<HesaiLayout> hesai_layouts() {
  return {
      {"PandarXT16", 0, 6, 16, 8, 4, 0, 28, 10, 13, 19, 24, 1900},
      {"PandarXT32", 0, 6, 32, 8, 4, 0, 28, 10, 13, 19, 24, 1900},
      {"PandarXT32M", 0, 6, 32, 6, 4, 0, 28, 10, 13, 19, 24, 1900},
      {"PandarQT64", 0, 3, 64, 4, 4, 0, 28, 16, 18, 12, 24, 1900},
      // QT128C2X, protocol 3.2 (Hesai SDK 2.0 udp_protocol_v3_2.h; QT128C2X manual "Point Cloud Data Packet"):
      // 12-byte head, 2 x (azimuth + 128 x 4-byte units), body CRC 4, functional safety 17, tail 26,
      // sequence 4, tail CRC 4, signature 32 = 1127 bytes with every header flag set (0x1D).
      {"PandarQT128", 0, 3, 128, 2, 4, 4 + 17, 26 + 4 + 4 + 32, 12, 15, 21, 26, 1900, 2, 0x1D},
      {"Pandar40P", 2, 0, 40, 10, 3, 0, 22, 14, 16, 10, -1, 2000},
      {"Pandar64", 1, 0, 64, 6, 3, 0, 22, 14, 16, 10, -1, 2000},
  };
}

struct HesaiContent {
  std::uint8_t return_mode = 0x37;
  int year = 2023, month = 1, day = 11, hour = 1, minute = 2, second = 3;
  std::uint32_t micros = 123456;
  std::uint16_t first_azimuth = 1000;  // 0.01 degree
  std::uint16_t azimuth_step = 18;
  std::uint32_t sequence = 77;
  std::uint8_t dis_unit_mm = 4;
};

inline void put_le16(std::vector<std::uint8_t>& p, std::size_t at, unsigned v) {
  p[at] = static_cast<std::uint8_t>(v);
  p[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_le32(std::vector<std::uint8_t>& p, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// Channel c of block b: distance 1000 + c units (unless zero_channel matches), reflectivity c.
inline std::vector<std::uint8_t> hesai_packet(const HesaiLayout& l, const HesaiContent& c = {}) {
  const int header = l.framing == 0 ? 12 : l.framing == 1 ? 8 : 0;
  const int block_bytes = (l.framing == 2 ? 2 : 0) + 2 + l.lasers * l.unit_bytes;
  const int tail = header + l.blocks * block_bytes + l.after_body;
  std::vector<std::uint8_t> p(static_cast<std::size_t>(tail + l.tail_bytes), 0);
  if (l.framing == 0) {
    p[0] = 0xEE, p[1] = 0xFF, p[2] = static_cast<std::uint8_t>(l.protocol_major);
    p[3] = static_cast<std::uint8_t>(l.protocol_minor);
    p[6] = static_cast<std::uint8_t>(l.lasers), p[7] = static_cast<std::uint8_t>(l.blocks);
    p[9] = c.dis_unit_mm, p[10] = 1, p[11] = static_cast<std::uint8_t>(l.header_flags);
  } else if (l.framing == 1) {
    p[0] = 0xEE, p[1] = 0xFF, p[2] = static_cast<std::uint8_t>(l.lasers), p[3] = static_cast<std::uint8_t>(l.blocks);
    p[5] = c.dis_unit_mm;
  }
  const bool dual = c.return_mode >= 0x39;
  for (int b = 0; b < l.blocks; ++b) {
    std::size_t at = static_cast<std::size_t>(header + b * block_bytes);
    if (l.framing == 2) p[at] = 0xFF, p[at + 1] = 0xEE, at += 2;
    const int firing = dual ? b / 2 : b;
    put_le16(p, at, static_cast<unsigned>(c.first_azimuth + firing * c.azimuth_step) & 0xFFFFU);
    for (int ch = 0; ch < l.lasers; ++ch) {
      const std::size_t u = at + 2 + static_cast<std::size_t>(ch * l.unit_bytes);
      put_le16(p, u, 1000 + ch + (dual && b % 2 ? 500 : 0));
      p[u + 2] = static_cast<std::uint8_t>(ch);
    }
  }
  p[tail + l.t_return_mode] = c.return_mode;
  const int d = tail + l.t_date;
  p[d] = static_cast<std::uint8_t>(c.year - l.year_base), p[d + 1] = static_cast<std::uint8_t>(c.month);
  p[d + 2] = static_cast<std::uint8_t>(c.day), p[d + 3] = static_cast<std::uint8_t>(c.hour);
  p[d + 4] = static_cast<std::uint8_t>(c.minute), p[d + 5] = static_cast<std::uint8_t>(c.second);
  put_le32(p, static_cast<std::size_t>(tail + l.t_timestamp), c.micros);
  if (l.t_sequence >= 0) put_le32(p, static_cast<std::size_t>(tail + l.t_sequence), c.sequence);
  return p;
}

// RoboSense MSOP: 42-byte header, 12 blocks of (0xFFEE, azimuth BE, 32 x (distance BE, reflectivity)), 6-byte tail.
inline std::vector<std::uint8_t> robosense_msop(bool helios, std::uint16_t first_azimuth, std::uint16_t step) {
  std::vector<std::uint8_t> p(1248, 0);
  if (helios) {
    const std::uint8_t magic[] = {0x55, 0xAA, 0x05, 0x5A};
    std::copy(std::begin(magic), std::end(magic), p.begin());
    p[17] = 0x01;                              // 0.25 cm range resolution
    const std::uint64_t seconds = 1673398923;  // 2023-01-11 01:02:03 UTC
    for (int i = 0; i < 6; ++i) p[20 + i] = static_cast<std::uint8_t>(seconds >> (8 * (5 - i)));
    const std::uint32_t micros = 123456;
    for (int i = 0; i < 4; ++i) p[26 + i] = static_cast<std::uint8_t>(micros >> (8 * (3 - i)));
  } else {
    const std::uint8_t magic[] = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
    std::copy(std::begin(magic), std::end(magic), p.begin());
    p[20] = 23, p[21] = 1, p[22] = 11, p[23] = 1, p[24] = 2, p[25] = 3;  // 2023-01-11 01:02:03
    p[26] = 0, p[27] = 123, p[28] = 1, p[29] = 200;                       // 123 ms, 456 us
  }
  for (int b = 0; b < 12; ++b) {
    const std::size_t at = 42 + static_cast<std::size_t>(b) * 100;
    p[at] = 0xFF, p[at + 1] = 0xEE;
    const unsigned az = (first_azimuth + b * step) % 36000;
    p[at + 2] = static_cast<std::uint8_t>(az >> 8), p[at + 3] = static_cast<std::uint8_t>(az);
    for (int c = 0; c < 32; ++c) {
      const std::size_t u = at + 4 + static_cast<std::size_t>(c) * 3;
      const unsigned dist = 2000 + c;
      p[u] = static_cast<std::uint8_t>(dist >> 8), p[u + 1] = static_cast<std::uint8_t>(dist), p[u + 2] = static_cast<std::uint8_t>(c);
    }
  }
  p[1246] = 0x00, p[1247] = 0xFF;
  return p;
}

}  // namespace adit::test
