#include "adit/drivers/pcap_writer.hpp"

#include <algorithm>
#include <array>

#include "adit/common/error.hpp"

namespace adit::drivers {
namespace {

constexpr std::size_t kEthernetHeader = 14;
constexpr std::size_t kIpHeader = 20;
constexpr std::size_t kUdpHeader = 8;
constexpr std::size_t kMaxFragmentData = (PcapWriter::kMtu - kIpHeader) / 8 * 8;  // offsets count 8-byte units
constexpr std::size_t kMaxUdpPayload = 65535 - kIpHeader - kUdpHeader;

void put16be(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}
void put32be(std::uint8_t* p, std::uint32_t v) {
  put16be(p, v >> 16);
  put16be(p + 2, v & 0xFFFF);
}
void put32le(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// RFC 791 header checksum: ones' complement of the ones' complement sum of the 16-bit words.
std::uint16_t ip_checksum(const std::uint8_t* header) {
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < kIpHeader; i += 2) sum += static_cast<std::uint32_t>(header[i] << 8 | header[i + 1]);
  while (sum >> 16) sum = (sum & 0xFFFF) + (sum >> 16);
  return static_cast<std::uint16_t>(~sum);
}

}  // namespace

PcapWriter::PcapWriter(const std::filesystem::path& file) : file_(file), out_(file, std::ios::binary | std::ios::trunc) {
  if (!out_) throw InputError(file.string(), "", "cannot create the capture file");
  // Global header: magic, version 2.4, GMT offset 0, accuracy 0, snaplen, LINKTYPE_ETHERNET.
  std::array<std::uint8_t, 24> h{};
  put32le(h.data(), 0xA1B2C3D4);
  h[4] = 2;
  h[6] = 4;
  put32le(h.data() + 16, 65535);
  put32le(h.data() + 20, 1);
  out_.write(reinterpret_cast<const char*>(h.data()), h.size());
}

void PcapWriter::write_record(std::int64_t time_ns, std::span<const std::uint8_t> frame) {
  std::array<std::uint8_t, 16> r{};
  const std::int64_t us = time_ns / 1000;
  put32le(r.data(), static_cast<std::uint32_t>(us / 1'000'000));
  put32le(r.data() + 4, static_cast<std::uint32_t>(us % 1'000'000));
  put32le(r.data() + 8, static_cast<std::uint32_t>(frame.size()));
  put32le(r.data() + 12, static_cast<std::uint32_t>(frame.size()));
  out_.write(reinterpret_cast<const char*>(r.data()), r.size());
  out_.write(reinterpret_cast<const char*>(frame.data()), static_cast<std::streamsize>(frame.size()));
  ++records_;
  bytes_ += r.size() + frame.size();
}

bool PcapWriter::write_udp(std::int64_t time_ns, const UdpEndpoints& e, std::span<const std::uint8_t> payload) {
  if (payload.size() > kMaxUdpPayload || time_ns < 0) return false;
  // The IP payload: UDP header then the datagram; cut into fragments of at most kMaxFragmentData.
  const std::size_t ip_payload = kUdpHeader + payload.size();
  std::array<std::uint8_t, kEthernetHeader + PcapWriter::kMtu> frame{};
  const std::uint16_t id = ip_id_++;
  for (std::size_t offset = 0; offset < ip_payload; offset += kMaxFragmentData) {
    const std::size_t size = std::min(kMaxFragmentData, ip_payload - offset);
    const bool more = offset + size < ip_payload;
    std::uint8_t* eth = frame.data();
    std::fill_n(eth, 6, std::uint8_t{0xFF});  // destination: broadcast
    const std::array<std::uint8_t, 6> src_mac{0x60, 0x76, 0x88, 0x00, 0x00, 0x01};
    std::copy(src_mac.begin(), src_mac.end(), eth + 6);
    put16be(eth + 12, 0x0800);
    std::uint8_t* ip = eth + kEthernetHeader;
    ip[0] = 0x45;
    ip[1] = 0;
    put16be(ip + 2, static_cast<std::uint32_t>(kIpHeader + size));
    put16be(ip + 4, id);
    put16be(ip + 6, static_cast<std::uint32_t>((more ? 0x2000 : 0) | (offset / 8)));
    ip[8] = 64;  // TTL
    ip[9] = 17;  // UDP
    put16be(ip + 10, 0);
    put32be(ip + 12, e.src_ip);
    put32be(ip + 16, e.dst_ip);
    put16be(ip + 10, ip_checksum(ip));
    std::uint8_t* data = ip + kIpHeader;
    std::size_t copied_from = 0;  // payload bytes already placed
    std::size_t at = 0;           // within this fragment's data
    if (offset == 0) {
      put16be(data, e.src_port);
      put16be(data + 2, e.dst_port);
      put16be(data + 4, static_cast<std::uint32_t>(ip_payload));
      put16be(data + 6, 0);  // no checksum
      at = kUdpHeader;
    } else {
      copied_from = offset - kUdpHeader;
    }
    std::copy_n(payload.data() + copied_from, size - at, data + at);
    write_record(time_ns, std::span<const std::uint8_t>(frame.data(), kEthernetHeader + kIpHeader + size));
  }
  ++datagrams_;
  return true;
}

void PcapWriter::flush() {
  out_.flush();
  if (!out_) throw InputError(file_.string(), "", "could not write the capture file (disk full?)");
}

}  // namespace adit::drivers
