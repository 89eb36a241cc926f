#pragma once
// Test support: writes small classic pcap files frame by frame, so the reader
// is tested on captures whose every byte the test controls.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

namespace adit::test {

using Bytes = std::vector<std::uint8_t>;

inline void put16be(Bytes& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v >> 8));
  b.push_back(static_cast<std::uint8_t>(v));
}
inline void put32be(Bytes& b, std::uint32_t v) {
  put16be(b, static_cast<std::uint16_t>(v >> 16));
  put16be(b, static_cast<std::uint16_t>(v));
}
inline void put32le(Bytes& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

struct Ipv4Fields {
  std::uint32_t src = 0xC0A80164;  // 192.168.1.100
  std::uint32_t dst = 0xFFFFFFFF;
  std::uint16_t id = 1;
  std::uint8_t protocol = 17;
  bool more_fragments = false;
  std::uint16_t fragment_offset = 0;  // bytes, a multiple of 8
};

// IPv4 header + `payload` (checksum left zero: readers of captures do not check it).
inline Bytes ipv4_packet(const Ipv4Fields& f, std::span<const std::uint8_t> payload) {
  Bytes b;
  b.push_back(0x45);
  b.push_back(0);
  put16be(b, static_cast<std::uint16_t>(20 + payload.size()));
  put16be(b, f.id);
  put16be(b, static_cast<std::uint16_t>((f.more_fragments ? 0x2000 : 0) | (f.fragment_offset / 8)));
  b.push_back(64);
  b.push_back(f.protocol);
  put16be(b, 0);
  put32be(b, f.src);
  put32be(b, f.dst);
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

inline Bytes udp_segment(std::uint16_t src_port, std::uint16_t dst_port, std::span<const std::uint8_t> payload) {
  Bytes b;
  put16be(b, src_port);
  put16be(b, dst_port);
  put16be(b, static_cast<std::uint16_t>(8 + payload.size()));
  put16be(b, 0);
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

// Ethernet II frame around an IPv4 packet, with an optional 802.1Q tag.
inline Bytes ethernet_frame(std::span<const std::uint8_t> ip, bool vlan = false, std::uint16_t ether_type = 0x0800) {
  Bytes b(12, 0xAB);
  if (vlan) {
    put16be(b, 0x8100);
    put16be(b, 42);
  }
  put16be(b, ether_type);
  b.insert(b.end(), ip.begin(), ip.end());
  return b;
}

// Linux cooked capture v1 header (LINKTYPE_LINUX_SLL) around an IPv4 packet.
inline Bytes sll_frame(std::span<const std::uint8_t> ip) {
  Bytes b;
  put16be(b, 0);  // packet type: to us
  put16be(b, 1);  // ARPHRD_ETHER
  put16be(b, 6);
  for (int i = 0; i < 8; ++i) b.push_back(0x11);
  put16be(b, 0x0800);
  b.insert(b.end(), ip.begin(), ip.end());
  return b;
}

class PcapBuilder {
 public:
  explicit PcapBuilder(std::uint32_t link_type = 1) {
    put32le(bytes_, 0xA1B2C3D4);  // microsecond magic, little-endian file
    put32le(bytes_, 0x00040002);  // version 2.4
    put32le(bytes_, 0);
    put32le(bytes_, 0);
    put32le(bytes_, 65535);
    put32le(bytes_, link_type);
  }
  void add(std::uint32_t sec, std::uint32_t usec, std::span<const std::uint8_t> frame) {
    put32le(bytes_, sec);
    put32le(bytes_, usec);
    put32le(bytes_, static_cast<std::uint32_t>(frame.size()));
    put32le(bytes_, static_cast<std::uint32_t>(frame.size()));
    bytes_.insert(bytes_.end(), frame.begin(), frame.end());
  }
  const Bytes& bytes() const { return bytes_; }
  void write(const std::filesystem::path& path, std::size_t cut_bytes = 0) const {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) throw std::runtime_error("cannot write " + path.string());
    std::fwrite(bytes_.data(), 1, bytes_.size() - cut_bytes, f);
    std::fclose(f);
  }

 private:
  Bytes bytes_;
};

// A unique path in the build tree for a test's scratch file.
inline std::filesystem::path scratch_file(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "adit-tests";
  std::filesystem::create_directories(dir);
  return dir / (std::to_string(::getpid()) + "-" + name);
}

}  // namespace adit::test
