#pragma once
// Reading UDP datagrams out of classic libpcap capture files (Ethernet or
// Linux cooked, IPv4, optional VLAN tag), through libpcap, with IPv4 fragment
// reassembly (RFC 791 §3.2): large Ouster packets are fragmented in captures.
// Damaged records are counted and skipped; nothing throws after opening.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>

namespace adit::drivers {

struct UdpDatagram {
  std::int64_t capture_time_ns = 0;  // the capture's timestamp of the last fragment
  std::uint32_t src_ip = 0;          // host byte order
  std::uint32_t dst_ip = 0;
  std::uint16_t src_port = 0;
  std::uint16_t dst_port = 0;
  std::span<const std::uint8_t> payload;  // valid until the next call to next()
};

struct PcapStats {
  std::uint64_t records = 0;            // capture records read
  std::uint64_t datagrams = 0;          // UDP datagrams returned
  std::uint64_t non_udp = 0;            // records that are not IPv4/UDP (ARP, TCP, IPv6, ...)
  std::uint64_t damaged = 0;            // truncated or inconsistent headers, bad lengths
  std::uint64_t reassembled = 0;        // datagrams rebuilt from IPv4 fragments
  std::uint64_t fragments_dropped = 0;  // fragments of datagrams that never completed
};

class PcapReader {
 public:
  // Throws adit::InputError naming the file when it cannot be opened or is not a capture.
  explicit PcapReader(const std::filesystem::path& file);
  ~PcapReader();
  PcapReader(PcapReader&&) noexcept;
  PcapReader& operator=(PcapReader&&) noexcept;

  // The next UDP datagram; false at the end of the file (or when the rest is damaged).
  bool next(UdpDatagram& out);
  const PcapStats& stats() const;
  const std::filesystem::path& file() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace adit::drivers
