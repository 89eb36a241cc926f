#pragma once
// Writing UDP datagrams into a classic libpcap capture (microsecond records,
// LINKTYPE_ETHERNET), as tcpdump would have captured them on the wire:
// Ethernet II, IPv4 (header checksum filled in) and UDP (checksum 0, "none",
// RFC 768). Datagrams larger than one 1500-byte MTU frame are split into IPv4
// fragments (RFC 791 §3.2) like the network stack sends them, so what reads
// real captures (PcapReader, Wireshark, VeloView) reads these too. Used by the
// simulator and for recording sessions.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>

namespace adit::drivers {

struct UdpEndpoints {
  std::uint32_t src_ip = 0xC0A801C9;  // 192.168.1.201, host byte order (Velodyne's factory address)
  std::uint32_t dst_ip = 0xFFFFFFFF;  // broadcast, as sensors send by default
  std::uint16_t src_port = 2368;
  std::uint16_t dst_port = 2368;
};

class PcapWriter {
 public:
  static constexpr std::size_t kMtu = 1500;
  // Throws adit::InputError naming the file when it cannot be created.
  explicit PcapWriter(const std::filesystem::path& file);

  // One datagram captured at `time_ns` (ns since the Unix epoch); rejects (returns
  // false, writes nothing) payloads that do not fit an IPv4 datagram.
  bool write_udp(std::int64_t time_ns, const UdpEndpoints& endpoints, std::span<const std::uint8_t> payload);
  // Throws adit::InputError when the file could not be written completely.
  void flush();

  std::uint64_t datagrams() const { return datagrams_; }
  std::uint64_t bytes() const { return bytes_; }   // the file's size once flushed
  bool failed() const { return !out_; }            // a write failed (disk full): later ones do nothing
  std::uint64_t records() const { return records_; }

 private:
  void write_record(std::int64_t time_ns, std::span<const std::uint8_t> frame);

  std::filesystem::path file_;
  std::ofstream out_;
  std::uint16_t ip_id_ = 0;
  std::uint64_t datagrams_ = 0;
  std::uint64_t records_ = 0;
  std::uint64_t bytes_ = 24;  // the global header
};

}  // namespace adit::drivers
