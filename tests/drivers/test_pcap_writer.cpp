// PcapWriter's captures read back by PcapReader: small datagrams in one
// record, large ones split into IPv4 fragments and reassembled.
#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "adit/drivers/pcap_reader.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

TEST(PcapWriter, DatagramsComeBackWholeThroughFragmentation) {
  const auto file = ::adit::test::binary_dir() / "test-pcap-writer.pcap";
  std::vector<std::vector<std::uint8_t>> sent;
  for (const std::size_t size : {1206u, 1472u, 1473u, 8000u, 0u}) {
    std::vector<std::uint8_t> payload(size);
    for (std::size_t i = 0; i < size; ++i) payload[i] = static_cast<std::uint8_t>(i * 7 + size);
    sent.push_back(payload);
  }
  UdpEndpoints e;
  e.src_port = 7502;
  e.dst_port = 7502;
  {
    PcapWriter writer(file);
    std::int64_t t = 1'767'225'600'000'000'000;
    for (const auto& p : sent) EXPECT_TRUE(writer.write_udp(t += 1'000'000, e, p));
    EXPECT_FALSE(writer.write_udp(t, e, std::vector<std::uint8_t>(70000)));
    writer.flush();
    EXPECT_EQ(writer.datagrams(), sent.size());
    // 1472 bytes fit one 1500-byte frame with the IP and UDP headers; 1473 do not; 8000 take 6.
    EXPECT_EQ(writer.records(), 1u + 1u + 2u + 6u + 1u);
  }
  PcapReader reader(file);
  UdpDatagram d;
  std::size_t i = 0;
  while (reader.next(d)) {
    ASSERT_LT(i, sent.size());
    EXPECT_EQ(std::vector<std::uint8_t>(d.payload.begin(), d.payload.end()), sent[i]) << "datagram " << i;
    EXPECT_EQ(d.dst_port, 7502);
    EXPECT_EQ(d.src_ip, e.src_ip);
    EXPECT_EQ(d.capture_time_ns, 1'767'225'600'000'000'000 + static_cast<std::int64_t>(i + 1) * 1'000'000);
    ++i;
  }
  EXPECT_EQ(i, sent.size());
  EXPECT_EQ(reader.stats().damaged, 0u);
  EXPECT_EQ(reader.stats().reassembled, 2u);
}

}  // namespace
}  // namespace adit::drivers
