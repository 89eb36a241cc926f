// The session's stored tiles (daemon/tile_spill.hpp): a tile written and read
// back keeps its points, to the codec's 1 mm, and each point the time of the
// scans around it (its segment's median), which the loop closure's correction
// through time needs to move an evicted tile's points: a tile seen again long
// after it was left keeps its first pass's times.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <map>
#include <tuple>

#include "adit/daemon/tile_spill.hpp"
#include "temp_file.hpp"

namespace adit::daemon {
namespace {

using Mm = std::tuple<long, long, long>;
Mm mm_of(const Eigen::Vector3f& p) { return {std::lround(p.x() * 1000), std::lround(p.y() * 1000), std::lround(p.z() * 1000)}; }

constexpr double kStart = 1'764'000'000.0;

// Point i of tile (1, -2, 0) at a distinct place, with time `time_s`.
slam::MapSample sample(int i, double time_s) {
  return {Eigen::Vector3f(20.05F + 0.1F * static_cast<float>(i % 190), -39.95F + 0.1F * static_cast<float>((i / 190) % 190),
                          0.05F + 0.1F * static_cast<float>(i / 36100)),
          static_cast<float>(i % 256), time_s};
}

TEST(TileSpill, ATileSeenAgainLaterKeepsItsFirstPassTimes) {
  const test::TempFolder dir;
  const protocol::TileParams params = stored_tile_params(20.0);
  TileSpill spill(dir.path() / "tiles", params);
  const slam::TileCoord coord{1, -2, 0};
  // A first pass of two whole segments (64 scans at 10 Hz), then 100 s later
  // a second pass of 1000 points (10 scans).
  const int first = 2 * static_cast<int>(params.segment_points);
  std::vector<slam::MapSample> written;
  for (int i = 0; i < first; ++i) written.push_back(sample(i, kStart + 0.1 * (i / 128)));
  for (int j = 0; j < 1000; ++j) written.push_back(sample(first + j, kStart + 100.0 + 0.1 * (j / 100)));
  std::map<Mm, double> time_of;
  for (const slam::MapSample& s : written) time_of[mm_of(s.position)] = s.time_s;
  ASSERT_EQ(time_of.size(), written.size());

  ASSERT_EQ(spill.write(coord, written), "");
  std::vector<slam::MapSample> back;
  ASSERT_EQ(spill.read(coord, back), "");
  ASSERT_EQ(back.size(), written.size());
  for (const slam::MapSample& s : back) {
    const auto it = time_of.find(mm_of(s.position));
    ASSERT_NE(it, time_of.end()) << "a point read back that was not written";
    const bool first_pass = it->second < kStart + 50.0;
    // Within its pass: the segment's median, 6.4 s or 1 s of scans.
    EXPECT_GE(s.time_s, first_pass ? kStart : kStart + 100.0);
    EXPECT_LT(s.time_s, first_pass ? kStart + 6.4 : kStart + 101.0);
  }

  // Another run's spill over the same folder knows no times: 0, not a guess.
  const TileSpill other(dir.path() / "tiles", params);
  ASSERT_EQ(other.read(coord, back), "");
  ASSERT_EQ(back.size(), written.size());
  EXPECT_EQ(back.back().time_s, 0.0);
}

}  // namespace
}  // namespace adit::daemon

namespace adit::daemon {
namespace {

// A tile is written one segment at a time (decision 074): the file holds the
// bytes the whole-tile encoder gives, partial last segment and empty tile too.
TEST(TileSpill, ATileWrittenSegmentBySegmentIsTheWholeTilesEncoding) {
  const test::TempFolder dir;
  const protocol::TileParams params = stored_tile_params(20.0);
  TileSpill spill(dir.path() / "tiles", params);
  const slam::TileCoord coord{1, -2, 0};
  for (const int n : {0, 1, 4096, 10000}) {
    std::vector<slam::MapSample> written;
    for (int i = 0; i < n; ++i) written.push_back(sample(i, kStart + 0.01 * i));
    ASSERT_EQ(spill.write(coord, written), "") << n;
    std::ifstream in(spill.file_of(coord), std::ios::binary);
    const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT_EQ(bytes, protocol::encode_tile({1, -2, 0}, map_points_of(written), params)) << n << " points";
  }
}

}  // namespace
}  // namespace adit::daemon
