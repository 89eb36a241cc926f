// The tile stream's store with its segments on disk: it serves the same
// bytes as one holding every frame in RAM, keeps in RAM only each tile's last
// partial segment (or nothing for a stored session's files), and reports I/O
// failures naming the file instead of crashing.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>

#include "adit/daemon/tile_publisher.hpp"
#include "adit/daemon/tile_store.hpp"
#include "temp_file.hpp"

namespace adit::daemon {
namespace {

std::vector<protocol::MapPoint> random_points(std::size_t n, unsigned seed, double x0 = 0.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 20.0);
  std::vector<protocol::MapPoint> points(n);
  for (auto& p : points) p = {x0 + u(rng), u(rng), u(rng), 7.0f, 0};
  return points;
}

std::vector<std::uint8_t> frame_of(const TileStore& store, const EncodedTile& tile, std::size_t s) {
  std::vector<std::uint8_t> out;
  EXPECT_EQ(store.read_frame(tile, s, out), "") << "tile " << tile.id << " segment " << s;
  return out;
}

// Every segment of every tile: same versions, same bytes.
void expect_same_tiles(const TileStore& a, const TileStore& b) {
  ASSERT_EQ(a.tiles().size(), b.tiles().size());
  EXPECT_EQ(a.total_points(), b.total_points());
  for (const auto& [id, ta] : a.tiles()) {
    const EncodedTile* tb = b.find(id);
    ASSERT_NE(tb, nullptr);
    EXPECT_EQ(ta.version, tb->version);
    ASSERT_EQ(ta.n_segments(), tb->n_segments());
    for (std::size_t s = 0; s < ta.segments.size(); ++s) {
      EXPECT_EQ(ta.segments[s].version, tb->segments[s].version);
      EXPECT_EQ(ta.frame_bytes(s), tb->frame_bytes(s));
      EXPECT_EQ(frame_of(a, ta, s), frame_of(b, *tb, s));
    }
  }
}

// What a spooled store may keep in RAM: each tile's last segment, if partial.
void expect_only_partial_segments_in_ram(const TileStore& store) {
  std::uint64_t partial = 0;
  for (const auto& [id, tile] : store.tiles()) {
    for (std::size_t s = 0; s < tile.segments.size(); ++s) {
      const bool in_ram = tile.where[s].file == FrameLocation::kInMemory;
      const bool full = tile.segments[s].n_points == tile.params.segment_points;
      EXPECT_EQ(in_ram, !full) << "tile " << id << " segment " << s << " of " << tile.segments.size();
      if (in_ram) {
        EXPECT_EQ(s + 1, tile.segments.size()) << "only the last segment can be partial";
        partial += tile.segments[s].frame.size();
      } else {
        EXPECT_TRUE(tile.segments[s].frame.empty());
      }
    }
  }
  EXPECT_EQ(store.frame_bytes_in_ram(), partial);
}

// The spool's live frames: those of segments whose frame is in file 0.
std::uint64_t spooled_frame_bytes(const TileStore& store) {
  std::uint64_t bytes = 0;
  for (const auto& [id, tile] : store.tiles())
    for (const FrameLocation& where : tile.where)
      if (where.file == 0) bytes += where.bytes;
  return bytes;
}

TEST(TileStore, SegmentsInTheSpoolFileServeTheSameBytesAsSegmentsInRam) {
  test::TempFolder folder;
  TileStore in_ram({});
  TileStore spooled({}, folder.path());
  ASSERT_TRUE(spooled.spooling()) << spooled.spool_problem();
  EXPECT_TRUE(std::filesystem::is_empty(folder.path())) << "the segment file has no name";

  // A tile that grows (the mapper appends), another one, and a tile whose
  // early points move (a tile read back from tiles/ comes reordered): its
  // full segments change and are written again.
  std::vector<protocol::MapPoint> a = random_points(5000, 1);
  const std::vector<protocol::MapPoint> b = random_points(3000, 2, 20.0);
  for (int step = 0; step < 4; ++step) {
    const auto more = random_points(700 + 300 * static_cast<std::size_t>(step), 10 + step);
    a.insert(a.end(), more.begin(), more.end());
    EXPECT_EQ(in_ram.update({0, 0, 0}, a, step), spooled.update({0, 0, 0}, a, step));
    EXPECT_EQ(in_ram.update({1, 0, 0}, b, step), spooled.update({1, 0, 0}, b, step));
    expect_same_tiles(in_ram, spooled);
    expect_only_partial_segments_in_ram(spooled);
  }
  std::reverse(a.begin(), a.begin() + 2048);
  EXPECT_TRUE(in_ram.update({0, 0, 0}, a, 9));
  EXPECT_TRUE(spooled.update({0, 0, 0}, a, 9));
  expect_same_tiles(in_ram, spooled);
  expect_only_partial_segments_in_ram(spooled);
  EXPECT_GT(in_ram.frame_bytes_in_ram(), 4 * spooled.frame_bytes_in_ram()) << "13 segments, two partial";
  EXPECT_EQ(spooled.spool_write_errors(), 0u);
  EXPECT_GE(spooled.spool_bytes(), in_ram.frame_bytes_in_ram() - spooled.frame_bytes_in_ram());
  EXPECT_EQ(spooled.spool_live_bytes(), spooled_frame_bytes(spooled));

  // Moved, it still reads its file.
  TileStore moved = std::move(spooled);
  expect_same_tiles(in_ram, moved);
}

// The mapper sends a tile's new points only (decision 074): a store given
// tails holds what one given each whole content holds, segment for segment,
// whether a tail starts on a segment boundary or inside the last, partial
// segment (decoded from its frame, in RAM).
TEST(TileStore, TailsAppendedGiveTheSegmentsOfTheWholeContent) {
  test::TempFolder folder;
  TileStore whole({});
  TileStore tails({}, folder.path());
  ASSERT_TRUE(tails.spooling()) << tails.spool_problem();
  std::vector<protocol::MapPoint> a;
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::size_t> count(1, 2500);
  for (int step = 0; step < 12; ++step) {
    const std::size_t first = a.size();
    const std::size_t n = step == 3 ? 1024 * 3 - first : count(rng);  // step 3 ends on a segment boundary
    const auto more = random_points(n, 100 + static_cast<unsigned>(step));
    a.insert(a.end(), more.begin(), more.end());
    EXPECT_TRUE(whole.update({0, 0, 0}, a, step));
    bool changed = false;
    ASSERT_EQ(tails.append({0, 0, 0}, first, std::span(a).subspan(first), step, changed), "") << "step " << step;
    EXPECT_TRUE(changed);
    expect_same_tiles(whole, tails);
    expect_only_partial_segments_in_ram(tails);
  }
  bool changed = true;
  EXPECT_EQ(tails.append({0, 0, 0}, a.size(), {}, 20, changed), "");
  EXPECT_FALSE(changed) << "nothing new: the version stays";

  // What does not fit is refused by name and changes nothing.
  const auto more = random_points(10, 99);
  EXPECT_NE(tails.append({0, 0, 0}, a.size() + 1, more, 21, changed).find("starts at point"), std::string::npos);
  EXPECT_NE(tails.append({0, 0, 0}, 10, more, 21, changed).find("shrink"), std::string::npos);
  EXPECT_NE(tails.append({3, 0, 0}, 5, more, 21, changed).find("never sent"), std::string::npos);
  EXPECT_FALSE(changed);
  expect_same_tiles(whole, tails);
}

TEST(TileStore, TheSpoolFileIsRewrittenWithItsLiveFramesOnceGarbageOutgrowsThem) {
  test::TempFolder folder;
  TileStore in_ram({});
  TileStore spooled({}, folder.path(), 0);  // no slack: compact as soon as garbage exceeds the live frames
  std::vector<protocol::MapPoint> a = random_points(8000, 3);
  for (int step = 0; step < 6; ++step) {
    std::reverse(a.begin(), a.begin() + 6000);  // reordered: every full segment changes
    const auto more = random_points(500, 40 + step);
    a.insert(a.end(), more.begin(), more.end());
    ASSERT_TRUE(in_ram.update({0, 0, 0}, a, step));
    ASSERT_TRUE(spooled.update({0, 0, 0}, a, step));
    expect_same_tiles(in_ram, spooled);
    expect_only_partial_segments_in_ram(spooled);
    EXPECT_EQ(spooled.spool_live_bytes(), spooled_frame_bytes(spooled));
    EXPECT_LE(spooled.spool_bytes(), 2 * spooled.spool_live_bytes());
  }
  EXPECT_GE(spooled.spool_compactions(), 2u);
  EXPECT_EQ(spooled.spool_write_errors(), 0u);
  EXPECT_TRUE(std::filesystem::is_empty(folder.path())) << "the rewritten file has no name either";
}

TEST(TileStore, WithoutItsSpoolFolderFramesStayInRamAndTheReasonNamesTheFolder) {
  const std::filesystem::path missing = "/nonexistent-adit-folder/session";
  TileStore store({}, missing);
  EXPECT_FALSE(store.spooling());
  EXPECT_NE(store.spool_problem().find(missing.string()), std::string::npos) << store.spool_problem();
  const auto points = random_points(3000, 4);
  EXPECT_TRUE(store.update({0, 0, 0}, points, 1));
  TileStore in_ram({});
  in_ram.update({0, 0, 0}, points, 1);
  expect_same_tiles(in_ram, store);
  EXPECT_EQ(store.frame_bytes_in_ram(), in_ram.frame_bytes_in_ram());
}

TEST(TileStore, AStoredSessionsFilesAreIndexedNotHeldAndAChangedFileIsReportedNotFatal) {
  test::TempFolder folder;
  const protocol::TileParams stored{20.0, 0.001, 3, protocol::kMaxSegmentPoints};  // as tiles/<id>.adt
  const std::int64_t id2 = protocol::tile_id({0, 0, 0});
  const std::int64_t id1 = protocol::tile_id({2, 0, 0});
  const std::vector<std::uint8_t> blob2 = protocol::encode_tile({0, 0, 0}, random_points(10'000, 5), stored);
  const std::vector<std::uint8_t> blob1 =
      protocol::encode_tile_format1({2, 0, 0}, random_points(1500, 6, 40.0), stored);  // an old session's
  const auto write = [&](std::int64_t id, const std::vector<std::uint8_t>& blob) {
    const std::filesystem::path file = folder.path() / (std::to_string(id) + ".adt");
    std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(blob.data()), static_cast<std::streamsize>(blob.size()));
    return file;
  };
  const std::filesystem::path file2 = write(id2, blob2);
  const std::filesystem::path file1 = write(id1, blob1);

  TileStore from_blobs({});
  ASSERT_EQ(from_blobs.insert_encoded(id2, blob2, 1), "");
  ASSERT_EQ(from_blobs.insert_encoded(id1, blob1, 1), "");
  TileStore from_files({});
  ASSERT_EQ(from_files.insert_file(id2, file2, 1), "");
  ASSERT_EQ(from_files.insert_file(id1, file1, 1), "");
  expect_same_tiles(from_blobs, from_files);
  // Format 2: nothing but the index in RAM; format 1 is re-cut, so its new frames are held.
  const EncodedTile& t2 = *from_files.find(id2);
  for (std::size_t s = 0; s < t2.segments.size(); ++s) EXPECT_EQ(t2.where[s].file, 1u);
  std::uint64_t recut = 0;
  for (const protocol::TileSegment& s : from_blobs.find(id1)->segments) recut += s.frame.size();
  EXPECT_EQ(from_files.frame_bytes_in_ram(), recut);

  // Problems name the file.
  const std::string missing = from_files.insert_file(protocol::tile_id({4, 0, 0}), folder.path() / "nope.adt", 1);
  EXPECT_NE(missing.find("nope.adt"), std::string::npos) << missing;
  const std::filesystem::path junk = write(protocol::tile_id({5, 0, 0}), {1, 2, 3});
  const std::string bad = from_files.insert_file(protocol::tile_id({5, 0, 0}), junk, 1);
  EXPECT_NE(bad.find(junk.string()), std::string::npos) << bad;
  EXPECT_EQ(from_files.find(protocol::tile_id({5, 0, 0})), nullptr);

  // The file shrinks after it was indexed: its last segment cannot be read.
  std::filesystem::resize_file(file2, blob2.size() - 10);
  std::vector<std::uint8_t> out;
  const std::string cut = from_files.read_frame(t2, t2.segments.size() - 1, out);
  EXPECT_NE(cut.find(file2.string()), std::string::npos) << cut;
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(from_files.read_frame(t2, 0, out), "") << "the segments before are intact";
}

struct Sink : TileSink {
  std::vector<tile_segment_t> segments;
  void send(const tile_segment_t& s) override { segments.push_back(s); }
  void send(const tile_index_t&) override {}
};

TEST(TileStore, APublisherWithASpoolSendsWhatOneInRamSendsAndCountsUnreadableSegments) {
  using namespace std::chrono_literals;
  test::TempFolder folder;
  Sink sink_ram;
  Sink sink_spool;
  TilePublisher in_ram({"rig1", {}, 1.0, 4.0e6, 0.0, 1, {}}, sink_ram);
  TilePublisher spooled({"rig1", {}, 1.0, 4.0e6, 0.0, 1, {}}, sink_spool);
  in_ram.reset("s1");
  spooled.reset("s1", folder.path());
  ASSERT_TRUE(spooled.store().spooling());
  auto now = TilePublisher::Clock::now();
  std::vector<protocol::MapPoint> points = random_points(4000, 7);
  for (int step = 0; step < 3; ++step) {
    const auto more = random_points(1500, 20 + step);
    points.insert(points.end(), more.begin(), more.end());
    in_ram.update({0, 0, 0}, 0, points, step);
    spooled.update({0, 0, 0}, 0, points, step);
    for (int i = 0; i < 150; ++i) {
      in_ram.tick(now);
      spooled.tick(now);
      now += 10ms;
    }
  }
  ASSERT_FALSE(sink_ram.segments.empty());
  ASSERT_EQ(sink_ram.segments.size(), sink_spool.segments.size());
  for (std::size_t i = 0; i < sink_ram.segments.size(); ++i) {
    EXPECT_EQ(sink_ram.segments[i].segment, sink_spool.segments[i].segment);
    EXPECT_EQ(sink_ram.segments[i].version, sink_spool.segments[i].version);
    EXPECT_EQ(sink_ram.segments[i].data, sink_spool.segments[i].data);
  }
  EXPECT_EQ(spooled.counts().segment_read_errors, 0u);

  // A stored session whose tile file is cut after loading: the segment is
  // not sent, counted; the rest is.
  const std::int64_t id = protocol::tile_id({0, 0, 0});
  const std::filesystem::path file = folder.path() / (std::to_string(id) + ".adt");
  const auto blob = protocol::encode_tile({0, 0, 0}, random_points(9000, 8), {20.0, 0.001, 3, protocol::kMaxSegmentPoints});
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(blob.data()), static_cast<std::streamsize>(blob.size()));
  Sink sink_stored;
  TilePublisherOptions options{"rig1", {}, 1.0, 4.0e6, 0.0, 1, {}};
  options.load_session = [&](const std::string&, TileStore& into) { return into.insert_file(id, file, 1); };
  TilePublisher stored(options, sink_stored);
  stored.reset("now");
  tile_request_t r{};
  r.schema = 2;
  r.payload_id = "rig1";
  r.session_id = "old";
  r.tile_ids = {id};
  r.versions = {0};
  r.chunks = {-1};
  r.n_entries = 1;
  stored.answer(r);  // loads the session: the file is whole then
  std::filesystem::resize_file(file, blob.size() - 10);
  for (int i = 0; i < 50; ++i) stored.tick(now += 10ms);
  EXPECT_EQ(stored.counts().segment_read_errors, 1u);
  EXPECT_EQ(sink_stored.segments.size(), 2u) << "3 segments of 4096, the last one unreadable";
}

}  // namespace
}  // namespace adit::daemon
