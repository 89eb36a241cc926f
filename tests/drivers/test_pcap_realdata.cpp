// The reader on the real captures: every record is accounted for, and large
// Ouster packets come back whole. (These captures hold no IP fragments: the
// reassembly is covered by the synthetic captures of test_pcap_reader.)
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "adit/drivers/lidar/scan_directory.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

std::map<std::uint16_t, std::size_t> datagrams_per_port(const std::filesystem::path& file, PcapStats& stats,
                                                        std::map<std::uint16_t, std::size_t>* sizes = nullptr) {
  PcapReader reader(file);
  std::map<std::uint16_t, std::size_t> counts;
  UdpDatagram d;
  while (reader.next(d)) {
    ++counts[d.dst_port];
    if (sizes != nullptr) (*sizes)[d.dst_port] = d.payload.size();
  }
  stats = reader.stats();
  return counts;
}

TEST(PcapRealdata, VelodyneCapturesHoldTheDocumentedPackets) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  PcapStats stats;
  std::map<std::uint16_t, std::size_t> sizes;
  const auto counts = datagrams_per_port(dir / "capture.pcap", stats, &sizes);
  EXPECT_EQ(counts.at(2368), 876u);
  EXPECT_EQ(counts.at(8308), 100u);
  EXPECT_EQ(sizes.at(2368), 1206u);
  EXPECT_EQ(sizes.at(8308), 512u);
  EXPECT_EQ(stats.damaged, 0u);

  const auto vlp16 = datagrams_per_port(dir.parent_path() / "velodyne-vlp16-dual" / "capture.pcap", stats);
  EXPECT_EQ(vlp16.at(2368), 603u);
}

TEST(PcapRealdata, OusterPacketsComeBackWhole) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  PcapStats stats;
  std::map<std::uint16_t, std::size_t> sizes;
  const auto counts = datagrams_per_port(dir / "OS-1-32-G_v2.1.1_1024x10.pcap", stats, &sizes);
  EXPECT_GT(counts.at(7502), 0u);
  EXPECT_EQ(stats.damaged, 0u);
  EXPECT_EQ(stats.fragments_dropped, 0u);
  // LEGACY profile, 32 beams: 16 columns × (16 + 32·12 + 4) bytes.
  EXPECT_EQ(sizes.at(7502), 16u * (16 + 32 * 12 + 4));
}

TEST(ScanDirectoryRealdata, ReadsTheHdl64Sequence) {
  ADIT_REQUIRE_SHARED_DATA(dir, "sequences/hdl64-urban-22");
  ScanDirectorySource source(dir);
  EXPECT_EQ(source.size(), 22u);
  LidarScan scan;
  ASSERT_TRUE(source.next(scan));
  EXPECT_GT(scan.points.size(), 100'000u);
  float farthest = 0.0F;
  for (const LidarPoint& p : scan.points) farthest = std::max(farthest, p.range_m);
  EXPECT_LE(farthest, 80.5F);  // the README: range cut at 80 m
}

}  // namespace
}  // namespace adit::drivers
