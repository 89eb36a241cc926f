#include "adit/drivers/pcap_reader.hpp"

#include <gtest/gtest.h>

#include <numeric>

#include "adit/common/error.hpp"
#include "adit/drivers/ipv4_reassembly.hpp"
#include "pcap_builder.hpp"

namespace adit::drivers {
namespace {

using test::Bytes;

Bytes counting_payload(std::size_t size, std::uint8_t start = 0) {
  Bytes b(size);
  std::iota(b.begin(), b.end(), start);
  return b;
}

std::vector<Bytes> read_payloads(const std::filesystem::path& file, PcapStats& stats,
                                 std::vector<std::uint16_t>* ports = nullptr) {
  PcapReader reader(file);
  std::vector<Bytes> out;
  UdpDatagram datagram;
  while (reader.next(datagram)) {
    out.emplace_back(datagram.payload.begin(), datagram.payload.end());
    if (ports != nullptr) ports->push_back(datagram.dst_port);
  }
  stats = reader.stats();
  return out;
}

TEST(PcapReader, ReadsEthernetVlanAndSkipsOtherTraffic) {
  test::PcapBuilder pcap;
  const Bytes a = counting_payload(1206);
  const Bytes b = counting_payload(512, 7);
  pcap.add(100, 5, test::ethernet_frame(test::ipv4_packet({}, test::udp_segment(2368, 2368, a))));
  pcap.add(100, 6, test::ethernet_frame(test::ipv4_packet({}, test::udp_segment(8308, 8308, b)), true));
  test::Ipv4Fields tcp;
  tcp.protocol = 6;
  pcap.add(100, 7, test::ethernet_frame(test::ipv4_packet(tcp, a)));
  pcap.add(100, 8, test::ethernet_frame(Bytes(28, 0), false, 0x0806));  // ARP
  const auto file = test::scratch_file("eth.pcap");
  pcap.write(file);

  PcapReader reader(file);
  UdpDatagram d;
  ASSERT_TRUE(reader.next(d));
  EXPECT_EQ(d.capture_time_ns, 100'000'005'000);
  EXPECT_EQ(d.dst_port, 2368);
  EXPECT_EQ(d.src_ip, 0xC0A80164u);
  EXPECT_EQ(Bytes(d.payload.begin(), d.payload.end()), a);
  ASSERT_TRUE(reader.next(d));
  EXPECT_EQ(d.dst_port, 8308);
  EXPECT_EQ(Bytes(d.payload.begin(), d.payload.end()), b);
  EXPECT_FALSE(reader.next(d));
  EXPECT_EQ(reader.stats().records, 4u);
  EXPECT_EQ(reader.stats().datagrams, 2u);
  EXPECT_EQ(reader.stats().non_udp, 2u);
  EXPECT_EQ(reader.stats().damaged, 0u);
  std::filesystem::remove(file);
}

TEST(PcapReader, ReadsLinuxCookedCaptures) {
  test::PcapBuilder pcap(113);
  const Bytes a = counting_payload(300);
  pcap.add(1, 0, test::sll_frame(test::ipv4_packet({}, test::udp_segment(1, 7502, a))));
  const auto file = test::scratch_file("sll.pcap");
  pcap.write(file);
  PcapStats stats;
  std::vector<std::uint16_t> ports;
  const auto payloads = read_payloads(file, stats, &ports);
  ASSERT_EQ(payloads.size(), 1u);
  EXPECT_EQ(payloads[0], a);
  EXPECT_EQ(ports[0], 7502);
  std::filesystem::remove(file);
}

// Splits one UDP datagram into IPv4 fragments of `chunk` bytes (a multiple of 8).
std::vector<Bytes> fragments(std::uint16_t id, const Bytes& udp, std::size_t chunk) {
  std::vector<Bytes> out;
  for (std::size_t offset = 0; offset < udp.size(); offset += chunk) {
    test::Ipv4Fields f;
    f.id = id;
    f.fragment_offset = static_cast<std::uint16_t>(offset);
    f.more_fragments = offset + chunk < udp.size();
    const std::size_t n = std::min(chunk, udp.size() - offset);
    out.push_back(test::ethernet_frame(test::ipv4_packet(f, std::span(udp).subspan(offset, n))));
  }
  return out;
}

TEST(PcapReader, ReassemblesInterleavedOutOfOrderFragments) {
  const Bytes big1 = counting_payload(8000, 1);
  const Bytes big2 = counting_payload(5000, 9);
  const auto f1 = fragments(10, test::udp_segment(7502, 7502, big1), 1480);
  const auto f2 = fragments(11, test::udp_segment(7502, 7502, big2), 1480);
  test::PcapBuilder pcap;
  // Interleave the two datagrams, the first one's fragments in reverse order.
  for (std::size_t i = 0; i < std::max(f1.size(), f2.size()); ++i) {
    if (i < f1.size()) pcap.add(1, static_cast<std::uint32_t>(i), f1[f1.size() - 1 - i]);
    if (i < f2.size()) pcap.add(1, static_cast<std::uint32_t>(100 + i), f2[i]);
  }
  // A datagram whose first fragment never came.
  auto lost = fragments(12, test::udp_segment(7502, 7502, big2), 1480);
  for (std::size_t i = 1; i < lost.size(); ++i) pcap.add(2, 0, lost[i]);
  const auto file = test::scratch_file("frag.pcap");
  pcap.write(file);

  PcapStats stats;
  const auto payloads = read_payloads(file, stats);
  ASSERT_EQ(payloads.size(), 2u);
  EXPECT_EQ(payloads[0], big2);  // completes first: its last fragment arrives before big1's first
  EXPECT_EQ(payloads[1], big1);
  EXPECT_EQ(stats.reassembled, 2u);
  EXPECT_EQ(stats.fragments_dropped, lost.size() - 1);
  EXPECT_EQ(stats.damaged, 0u);
  std::filesystem::remove(file);
}

TEST(PcapReader, CountsDamagedRecordsAndStopsAtATruncatedRecord) {
  test::PcapBuilder pcap;
  const Bytes a = counting_payload(100);
  Bytes bad_len = test::ethernet_frame(test::ipv4_packet({}, test::udp_segment(1, 2, a)));
  bad_len[14 + 2] = 0xFF;  // IP total length beyond the frame
  Bytes bad_udp = test::ethernet_frame(test::ipv4_packet({}, test::udp_segment(1, 2, a)));
  bad_udp[14 + 20 + 4] = 0xFF;  // UDP length beyond the IP packet
  pcap.add(1, 0, bad_len);
  pcap.add(1, 1, bad_udp);
  pcap.add(1, 2, Bytes(10, 0));  // shorter than an Ethernet header
  pcap.add(1, 3, test::ethernet_frame(test::ipv4_packet({}, test::udp_segment(1, 2, a))));
  pcap.add(1, 4, test::ethernet_frame(test::ipv4_packet({}, test::udp_segment(1, 2, a))));
  const auto file = test::scratch_file("damaged.pcap");
  pcap.write(file, 30);  // the last record is cut short

  PcapStats stats;
  const auto payloads = read_payloads(file, stats);
  EXPECT_EQ(payloads.size(), 1u);
  EXPECT_EQ(stats.damaged, 4u);
  std::filesystem::remove(file);
}

TEST(PcapReader, RejectsFilesThatAreNotCaptures) {
  const auto file = test::scratch_file("not.pcap");
  {
    test::PcapBuilder pcap;
    Bytes junk(64, 0x42);
    std::FILE* f = std::fopen(file.c_str(), "wb");
    std::fwrite(junk.data(), 1, junk.size(), f);
    std::fclose(f);
  }
  try {
    PcapReader reader(file);
    FAIL() << "a non-capture was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), file.string());
  }
  EXPECT_THROW(PcapReader(file.string() + ".missing"), InputError);
  std::filesystem::remove(file);
}

TEST(Ipv4Reassembler, EvictsTheOldestWhenEverySlotIsBusy) {
  Ipv4Reassembler reassembler(2);
  const Bytes chunk(16, 1);
  for (std::uint16_t id = 0; id < 3; ++id) {
    const auto r = reassembler.add({1, 2, id, 17}, 0, true, chunk);
    EXPECT_EQ(r.status, Ipv4Reassembler::Status::pending);
  }
  EXPECT_EQ(reassembler.dropped_fragments(), 1u);
  EXPECT_EQ(reassembler.pending_fragments(), 2u);
  const auto done = reassembler.add({1, 2, 2, 17}, 16, false, Bytes(3, 2));
  ASSERT_EQ(done.status, Ipv4Reassembler::Status::complete);
  EXPECT_EQ(done.datagram.size(), 19u);
  // A non-final fragment that is not a multiple of 8 bytes is invalid.
  EXPECT_EQ(reassembler.add({1, 2, 9, 17}, 0, true, Bytes(5, 0)).status, Ipv4Reassembler::Status::invalid);
  // Past the largest IPv4 payload.
  EXPECT_EQ(reassembler.add({1, 2, 9, 17}, 65528, false, Bytes(16, 0)).status, Ipv4Reassembler::Status::invalid);
}

}  // namespace
}  // namespace adit::drivers
