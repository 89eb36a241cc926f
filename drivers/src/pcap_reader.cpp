#include "adit/drivers/pcap_reader.hpp"

#include <pcap/pcap.h>

#include <array>
#include <optional>
#include <string>

#include "adit/common/error.hpp"
#include "adit/drivers/ipv4_reassembly.hpp"

namespace adit::drivers {
namespace {

// Link types (https://www.tcpdump.org/linktypes.html).
constexpr int kLinkEthernet = DLT_EN10MB;
constexpr int kLinkLinuxSll = 113;   // LINKTYPE_LINUX_SLL
constexpr int kLinkLinuxSll2 = 276;  // LINKTYPE_LINUX_SLL2
constexpr int kLinkRawIp = 101;      // LINKTYPE_RAW
constexpr int kLinkIpv4 = 228;       // LINKTYPE_IPV4

constexpr std::uint16_t kEtherIpv4 = 0x0800;
constexpr std::uint16_t kEtherVlan = 0x8100;
constexpr std::uint16_t kEtherQinQ = 0x88A8;
constexpr std::uint8_t kProtoUdp = 17;
constexpr std::size_t kUdpHeader = 8;

std::uint16_t be16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] << 8 | p[1]); }
std::uint32_t be32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | p[3];
}

// The offset of the IPv4 header in a frame, or nullopt when the frame carries
// something else. `damaged` is set when the link header itself is cut short.
std::optional<std::size_t> ipv4_offset(int link, std::span<const std::uint8_t> frame, bool& damaged) {
  std::size_t offset = 0;
  std::uint16_t ether_type = 0;
  switch (link) {
    case kLinkEthernet: offset = 14; break;
    case kLinkLinuxSll: offset = 16; break;
    case kLinkLinuxSll2: offset = 20; break;
    case kLinkRawIp:
    case kLinkIpv4: return 0;
    default: return std::nullopt;
  }
  if (frame.size() < offset) {
    damaged = true;
    return std::nullopt;
  }
  ether_type = link == kLinkLinuxSll2 ? be16(frame.data()) : be16(frame.data() + offset - 2);
  // 802.1Q / 802.1ad tags (possibly stacked) sit between the header and the payload.
  while (ether_type == kEtherVlan || ether_type == kEtherQinQ) {
    if (frame.size() < offset + 4) {
      damaged = true;
      return std::nullopt;
    }
    ether_type = be16(frame.data() + offset + 2);
    offset += 4;
  }
  if (ether_type != kEtherIpv4) return std::nullopt;
  return offset;
}

}  // namespace

struct PcapReader::Impl {
  std::filesystem::path file;
  pcap_t* handle = nullptr;
  int link = 0;
  bool nanoseconds = false;
  PcapStats stats;
  Ipv4Reassembler reassembler;

  ~Impl() {
    if (handle != nullptr) pcap_close(handle);
  }

  // Returns true with `out` filled when `frame` is (or completes) a UDP datagram.
  bool parse(std::int64_t time_ns, std::span<const std::uint8_t> frame, UdpDatagram& out) {
    bool damaged = false;
    const auto ip_at = ipv4_offset(link, frame, damaged);
    if (!ip_at) {
      ++(damaged ? stats.damaged : stats.non_udp);
      return false;
    }
    const auto ip = frame.subspan(*ip_at);
    if (ip.size() < 20 || (ip[0] >> 4) != 4) {
      ++(ip.size() < 20 ? stats.damaged : stats.non_udp);
      return false;
    }
    const std::size_t header_len = std::size_t{ip[0] & 0x0Fu} * 4;
    const std::size_t total_len = be16(ip.data() + 2);
    // Ethernet pads short frames, so the IP total length wins over the frame's.
    if (header_len < 20 || total_len < header_len || total_len > ip.size()) {
      ++stats.damaged;
      return false;
    }
    if (ip[9] != kProtoUdp) {
      ++stats.non_udp;
      return false;
    }
    const std::uint16_t flags_fragment = be16(ip.data() + 6);
    const bool more_fragments = (flags_fragment & 0x2000u) != 0;
    const std::size_t fragment_offset = std::size_t{flags_fragment & 0x1FFFu} * 8;
    const std::uint32_t src = be32(ip.data() + 12);
    const std::uint32_t dst = be32(ip.data() + 16);
    std::span<const std::uint8_t> udp = ip.subspan(header_len, total_len - header_len);

    if (more_fragments || fragment_offset != 0) {
      const Ipv4Reassembler::Key key{src, dst, be16(ip.data() + 4), kProtoUdp};
      const auto result = reassembler.add(key, fragment_offset, more_fragments, udp);
      if (result.status == Ipv4Reassembler::Status::invalid) {
        ++stats.damaged;
        return false;
      }
      if (result.status != Ipv4Reassembler::Status::complete) return false;
      udp = result.datagram;
      ++stats.reassembled;
    }
    if (udp.size() < kUdpHeader) {
      ++stats.damaged;
      return false;
    }
    const std::size_t udp_len = be16(udp.data() + 4);
    if (udp_len < kUdpHeader || udp_len > udp.size()) {
      ++stats.damaged;
      return false;
    }
    out.capture_time_ns = time_ns;
    out.src_ip = src;
    out.dst_ip = dst;
    out.src_port = be16(udp.data());
    out.dst_port = be16(udp.data() + 2);
    out.payload = udp.subspan(kUdpHeader, udp_len - kUdpHeader);
    ++stats.datagrams;
    return true;
  }
};

PcapReader::PcapReader(const std::filesystem::path& file) : impl_(std::make_unique<Impl>()) {
  impl_->file = file;
  std::array<char, PCAP_ERRBUF_SIZE> error{};
  impl_->handle = pcap_open_offline_with_tstamp_precision(file.c_str(), PCAP_TSTAMP_PRECISION_NANO, error.data());
  if (impl_->handle == nullptr) throw InputError(file.string(), "", std::string("cannot read capture: ") + error.data());
  impl_->link = pcap_datalink(impl_->handle);
  impl_->nanoseconds = pcap_get_tstamp_precision(impl_->handle) == PCAP_TSTAMP_PRECISION_NANO;
  const int link = impl_->link;
  if (link != kLinkEthernet && link != kLinkLinuxSll && link != kLinkLinuxSll2 && link != kLinkRawIp &&
      link != kLinkIpv4) {
    throw InputError(file.string(), "link type",
                     "unsupported link type " + std::to_string(link) + " (want Ethernet, Linux cooked or raw IPv4)");
  }
}

PcapReader::~PcapReader() = default;
PcapReader::PcapReader(PcapReader&&) noexcept = default;
PcapReader& PcapReader::operator=(PcapReader&&) noexcept = default;

bool PcapReader::next(UdpDatagram& out) {
  Impl& impl = *impl_;
  if (impl.handle == nullptr) return false;
  for (;;) {
    pcap_pkthdr* header = nullptr;
    const std::uint8_t* data = nullptr;
    const int rc = pcap_next_ex(impl.handle, &header, &data);
    if (rc == PCAP_ERROR_BREAK) {  // end of file
      impl.reassembler.clear();
      impl.stats.fragments_dropped = impl.reassembler.dropped_fragments();
      return false;
    }
    if (rc != 1) {  // a truncated or corrupt record: libpcap cannot resynchronise after it
      ++impl.stats.damaged;
      impl.reassembler.clear();
      impl.stats.fragments_dropped = impl.reassembler.dropped_fragments();
      pcap_close(impl.handle);
      impl.handle = nullptr;
      return false;
    }
    ++impl.stats.records;
    const std::int64_t sub = impl.nanoseconds ? header->ts.tv_usec : std::int64_t{header->ts.tv_usec} * 1000;
    const std::int64_t time_ns = std::int64_t{header->ts.tv_sec} * 1'000'000'000 + sub;
    // A frame cut by the snapshot length shows up as damaged through the IP length check.
    const bool got = impl.parse(time_ns, {data, header->caplen}, out);
    impl.stats.fragments_dropped = impl.reassembler.dropped_fragments();
    if (got) return true;
  }
}

const PcapStats& PcapReader::stats() const { return impl_->stats; }
const std::filesystem::path& PcapReader::file() const { return impl_->file; }

}  // namespace adit::drivers
