// Zero heap allocations per packet in the live path: receive (recvmmsg),
// decode, assemble, hand over the scan. This binary replaces the global
// operator new to count every allocation.
#include <gtest/gtest.h>

#include <cstring>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/drivers/udp.hpp"
#include "allocation_counter.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

std::vector<std::vector<std::uint8_t>> payloads(const std::filesystem::path& capture) {
  std::vector<std::vector<std::uint8_t>> out;
  PcapReader reader(capture);
  UdpDatagram d;
  while (reader.next(d)) out.emplace_back(d.payload.begin(), d.payload.end());
  return out;
}

TEST(NoAllocation, DecodeAndAssembleAllocateNothingPerPacket) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp16-dual");
  // Four passes over the capture, each later by the capture's length, so sensor time keeps going forward.
  const auto one_pass = payloads(dir / "capture.pcap");
  std::vector<std::vector<std::uint8_t>> packets;
  for (std::uint32_t pass = 0; pass < 4; ++pass) {
    for (auto p : one_pass) {
      std::uint32_t us;
      std::memcpy(&us, p.data() + 1200, 4);
      us += pass * 400'000;
      std::memcpy(p.data() + 1200, &us, 4);
      packets.push_back(std::move(p));
    }
  }
  VelodyneDecoder decoder(VelodyneModel::vlp16, load_velodyne_calibration(dir / "VLP16.yaml"));
  ScanAssembler assembler(
      assembler_config_for(decoder, velodyne_packet_period_ns(VelodyneModel::vlp16, VelodyneReturnMode::dual), 0.0F));
  std::uint64_t scans = 0;
  std::uint64_t points = 0;
  DecodeStream stream(decoder, assembler, [&](LidarScan& scan) {
    ++scans;
    points += scan.points.size();
  });
  // Warm up with one pass, then count over three more (time keeps going forward).
  std::int64_t host = 1'673'400'471'737'000'000;
  const std::size_t warm_up = one_pass.size();
  for (std::size_t i = 0; i < warm_up; ++i) stream.push(packets[i], host += 663'000);
  const std::uint64_t before = adit::test::allocations();
  for (std::size_t i = warm_up; i < packets.size(); ++i) stream.push(packets[i], host += 663'000);
  const std::uint64_t allocations = adit::test::allocations() - before;
  EXPECT_EQ(allocations, 0u) << "over " << packets.size() - warm_up << " packets";
  EXPECT_EQ(assembler.totals().missing_packets + assembler.totals().out_of_order_packets, 0u);
  EXPECT_GT(scans, 10u);
  EXPECT_GT(points, 100'000u);
}

TEST(NoAllocation, ReceivingAllocatesNothing) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  UdpReceiverConfig config;
  config.bind_address = "127.0.0.1";
  config.batch = 16;
  UdpReceiver receiver(config);
  UdpSender sender("127.0.0.1", receiver.port());
  const std::vector<std::uint8_t> payload(1206, 0x11);
  const std::uint64_t before = adit::test::allocations();
  std::uint64_t received = 0;
  for (int round = 0; round < 20; ++round) {
    for (int i = 0; i < 16; ++i) sender.send(payload);
    for (auto batch = receiver.receive(100); !batch.empty(); batch = receiver.receive(0)) received += batch.size();
  }
  EXPECT_EQ(adit::test::allocations() - before, 0u);
  EXPECT_EQ(received, 320u);
}

}  // namespace
}  // namespace adit::drivers
