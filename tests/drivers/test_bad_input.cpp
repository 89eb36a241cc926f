// Damaged, truncated, foreign and random packets, and a truncated capture:
// counted, skipped, never a crash.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "pcap_builder.hpp"
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

TEST(BadInput, DamagedPacketsAreCountedAndSkipped) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp16-strongest");
  const auto good = payloads(dir / "capture.pcap");
  ASSERT_EQ(good.size(), 84u);
  VelodyneDecoder decoder(VelodyneModel::vlp16, load_velodyne_calibration(dir / "VLP16.yaml"));
  ScanAssembler assembler(assembler_config_for(
      decoder, velodyne_packet_period_ns(VelodyneModel::vlp16, VelodyneReturnMode::strongest), 0.0F));
  std::size_t scans = 0;
  DecodeStream stream(decoder, assembler, [&](LidarScan&) { ++scans; });
  std::mt19937 random(42);
  std::size_t sent = 0;
  std::int64_t host = 1'525'347'606'000'000'000;
  for (const auto& packet : good) {
    stream.push(packet, host += 1'000'000);
    ++sent;
    // A random-byte packet of a random size, a truncated copy, an oversized copy, a copy with a
    // damaged block flag, and one whose azimuth is out of range.
    std::vector<std::uint8_t> noise(random() % 2000);
    for (auto& b : noise) b = static_cast<std::uint8_t>(random());
    std::vector<std::uint8_t> truncated(packet.begin(), packet.begin() + static_cast<long>(random() % packet.size()));
    std::vector<std::uint8_t> oversized = packet;
    oversized.resize(packet.size() + 1 + random() % 100);
    std::vector<std::uint8_t> flag = packet;
    flag[100 * (1 + random() % 11)] ^= 0x5A;
    std::vector<std::uint8_t> azimuth = packet;
    azimuth[100 * (random() % 12) + 3] = 0xF0;
    for (const auto* bad : {&noise, &truncated, &oversized, &flag, &azimuth}) {
      stream.push(*bad, host);
      ++sent;
    }
  }
  stream.finish();
  const PacketCounters& c = stream.counters();
  EXPECT_EQ(c.total(), sent);
  EXPECT_EQ(c.count(PacketStatus::ok), 84u);
  EXPECT_EQ(c.count(PacketStatus::malformed), 2u * 84u);  // the damaged flag and azimuth copies
  EXPECT_EQ(stream.bad_packets(), sent - 84u - c.count(PacketStatus::auxiliary));
  EXPECT_GE(c.count(PacketStatus::truncated), 1u);
  EXPECT_EQ(assembler.totals().missing_packets, 0u);  // the good stream was not disturbed
  EXPECT_GT(scans, 0u);
}

TEST(BadInput, TruncatedCaptureKeepsWhatCameBeforeTheCut) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp16-strongest");
  const auto source = dir / "capture.pcap";
  const auto size = std::filesystem::file_size(source);
  const auto cut = test::scratch_file("cut.pcap");
  {
    std::ifstream in(source, std::ios::binary);
    std::vector<char> bytes(size / 2 + 100);
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  PcapReader reader(cut);
  UdpDatagram d;
  std::size_t n = 0;
  while (reader.next(d)) ++n;
  EXPECT_GT(n, 30u);
  EXPECT_LT(n, 84u);
  EXPECT_EQ(reader.stats().damaged, 1u);
  EXPECT_FALSE(reader.next(d));  // stays at the end
  std::filesystem::remove(cut);
}

}  // namespace
}  // namespace adit::drivers
