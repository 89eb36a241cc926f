// Zero heap allocations per packet for the Hesai and RoboSense decoders in the
// live path (decode + assemble through DecodeStream). This binary replaces the
// global operator new to count every allocation.
#include <gtest/gtest.h>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/hesai.hpp"
#include "adit/drivers/lidar/robosense.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "allocation_counter.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

struct Datagram {
  std::vector<std::uint8_t> payload;
  std::int64_t time_ns;
};

// Warm up on the first `warm_up` packets (one revolution), count allocations over the rest.
void expect_no_allocation(const std::filesystem::path& capture, LidarDecoder& decoder, std::size_t warm_up) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  std::vector<Datagram> packets;
  {
    PcapReader reader(capture);
    UdpDatagram d;
    while (reader.next(d)) packets.push_back({{d.payload.begin(), d.payload.end()}, d.capture_time_ns});
  }
  ScanAssembler assembler(assembler_config_for(decoder, 0, 0.0F));
  std::uint64_t scans = 0;
  DecodeStream stream(decoder, assembler, [&](LidarScan&) { ++scans; });
  for (std::size_t i = 0; i < warm_up; ++i) stream.push(packets[i].payload, packets[i].time_ns);
  const std::uint64_t before = adit::test::allocations();
  const std::uint64_t scans_before = scans;
  for (std::size_t i = warm_up; i < packets.size(); ++i) stream.push(packets[i].payload, packets[i].time_ns);
  EXPECT_EQ(adit::test::allocations() - before, 0u) << "over " << packets.size() - warm_up << " packets";
  EXPECT_GE(scans - scans_before, 2u);
}

TEST(HesaiRoboSenseNoAllocation, PandarXT32) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/hesai-xt32");
  auto decoder = make_hesai_decoder("PandarXT32", dir / "PandarXT32.csv");
  expect_no_allocation(dir / "capture.pcap", *decoder, 600);
}

TEST(HesaiRoboSenseNoAllocation, PandarQT64) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/hesai-qt64");
  auto decoder = make_hesai_decoder("PandarQT64", dir / "PandarQT64.csv");
  expect_no_allocation(dir / "capture.pcap", *decoder, 350);
}

TEST(HesaiRoboSenseNoAllocation, Helios16PWithItsDifop) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/robosense-helios16p");
  auto decoder = make_robosense_decoder("Helios16P", dir / "RobosenseHelios16P.csv", RoboSenseReturnMode::single);
  expect_no_allocation(dir / "capture.pcap", *decoder, 200);  // the DIFOP (#543) comes after
}

}  // namespace
}  // namespace adit::drivers
