// Frames kept in a spill file: read back as written, freed on disk when the
// last holder lets go, kept in RAM by the assembler when the disk refuses.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <numeric>

#include "adit/common/error.hpp"
#include "adit/protocol/frame_spill.hpp"
#include "adit/protocol/tile_assembler.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_segment_t.hpp"

namespace adit::protocol {
namespace {

std::vector<std::uint8_t> bytes(std::size_t n, std::uint8_t seed) {
  std::vector<std::uint8_t> v(n);
  std::iota(v.begin(), v.end(), seed);
  return v;
}

TEST(FrameSpill, FramesReadBackAsWrittenAndTheirBlocksAreFreedWithTheLastHolder) {
  const auto spill = FrameSpill::open(std::filesystem::temp_directory_path());
  const auto a = spill->write(bytes(300'000, 1));
  auto b = spill->write(bytes(200'000, 7));
  ASSERT_TRUE(a && b);
  EXPECT_EQ(spill->live_bytes(), 500'000u);
  EXPECT_GE(spill->disk_bytes(), 500'000u);
  std::vector<std::uint8_t> out;
  ASSERT_TRUE(b->read(out));
  EXPECT_EQ(out, bytes(200'000, 7));
  ASSERT_TRUE(a->read(out));
  EXPECT_EQ(out, bytes(300'000, 1));
  auto copy = b;  // a second holder (the console copies segments to decode them outside its lock)
  b.reset();
  EXPECT_EQ(spill->live_bytes(), 500'000u);
  ASSERT_TRUE(copy->read(out));
  EXPECT_EQ(out, bytes(200'000, 7));
  copy.reset();
  EXPECT_EQ(spill->live_bytes(), 300'000u);
  EXPECT_LT(spill->disk_bytes(), 400'000u);  // the hole punched (a block either side may stay)
  ASSERT_TRUE(a->read(out));
  EXPECT_EQ(out, bytes(300'000, 1));
  EXPECT_EQ(spill->failed_reads(), 0u);
}

TEST(FrameSpill, AFolderThatCannotHoldOneIsNamed) {
  try {
    FrameSpill::open("/nonexistent/adit-spill");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/adit-spill"), std::string::npos) << e.what();
  }
}

// A tile of `n` points as tile_segment_t messages.
std::vector<tile_segment_t> tile_segments(TileKey key, std::size_t n, std::vector<MapPoint>& points) {
  points.clear();
  for (std::size_t i = 0; i < n; ++i)
    points.push_back({key.x * 20.0 + 0.003 * static_cast<double>(i % 5000), key.y * 20.0 + 0.011 * static_cast<double>(i % 1700),
                      1.0 + 0.0007 * static_cast<double>(i), 2.0F, 0});
  std::vector<TileSegment> segments;
  update_segments(key, points, {}, 1, segments);
  std::vector<tile_segment_t> out;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    tile_segment_t m{};
    m.schema = 2;
    m.tile_id = tile_id(key);
    m.version = 1;
    m.segment = static_cast<std::int32_t>(s);
    m.n_segments = static_cast<std::int32_t>(segments.size());
    m.n_points = static_cast<std::int32_t>(n);
    m.tile_size_m = 20.0F;
    m.quantum_m = 0.001F;
    m.data = segments[s].frame;
    m.size = static_cast<std::int32_t>(m.data.size());
    out.push_back(m);
  }
  return out;
}

std::size_t held_points(const TileAssembler& a) { return a.points().size(); }

TEST(FrameSpill, AnAssemblerWithASpillHoldsTheSameMapOnDisk) {
  std::vector<MapPoint> points;
  const auto segments = tile_segments({3, 4, 0}, 9000, points);
  ASSERT_GE(segments.size(), 3u);
  const auto spill = FrameSpill::open(std::filesystem::temp_directory_path());
  TileAssembler on_disk(spill), in_ram;
  for (const auto& m : segments) {
    on_disk.add_segment(m);
    in_ram.add_segment(m);
  }
  const auto a = on_disk.points(), b = in_ram.points();
  ASSERT_EQ(a.size(), 9000u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z) << i;
  std::size_t frame_bytes = 0;
  for (const auto& m : segments) frame_bytes += m.data.size();
  EXPECT_EQ(spill->live_bytes(), frame_bytes);
  const auto held = on_disk.held(segments[0].tile_id);
  ASSERT_TRUE(held);
  for (const HeldSegment& s : held->segments) {
    EXPECT_TRUE(s.frame.empty());  // not in RAM
    EXPECT_TRUE(s.spilled);
  }
  on_disk = TileAssembler(spill);  // a new session: the old one's frames freed
  EXPECT_EQ(spill->live_bytes(), 0u);
}

TEST(FrameSpill, FramesTheDiskRefusesStayInRam) {
  std::vector<MapPoint> points;
  const auto segments = tile_segments({1, 1, 0}, 9000, points);
  const auto spill = FrameSpill::open(std::filesystem::temp_directory_path());
  // A file size limit stands in for a full disk: writes past it fail (EFBIG).
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  TileAssembler a(spill);
  for (const auto& m : segments) a.add_segment(m);
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_GE(spill->failed_writes(), 1u);
  std::size_t in_ram = 0;
  const auto held = a.held(segments[0].tile_id);
  ASSERT_TRUE(held);
  for (const HeldSegment& s : held->segments) in_ram += !s.frame.empty();
  EXPECT_GE(in_ram, 1u);
  EXPECT_EQ(held_points(a), 9000u);  // nothing lost
}

}  // namespace
}  // namespace adit::protocol
