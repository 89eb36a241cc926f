// The tile stream's daemon side on a simulated clock: rate limit, only the
// segments that changed, answers with only what was asked for, pacing.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <set>

#include "adit/daemon/tile_publisher.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;
using Clock = TilePublisher::Clock;

struct RecordingSink : TileSink {
  std::vector<tile_segment_t> chunks;
  std::vector<tile_index_t> indexes;
  void send(const tile_segment_t& c) override { chunks.push_back(c); }
  std::size_t bytes() const {
    std::size_t n = 0;
    for (const auto& c : chunks) n += static_cast<std::size_t>(c.getEncodedSize());
    return n;
  }
  void send(const tile_index_t& i) override { indexes.push_back(i); }
};

std::vector<protocol::MapPoint> random_points(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 20.0);
  std::vector<protocol::MapPoint> points(n);
  for (auto& p : points) p = {u(rng), u(rng), u(rng), 1.0f, 0};
  return points;
}

struct TilePublisherTest : ::testing::Test {
  RecordingSink sink;
  Clock::time_point t0 = Clock::now();
  TilePublisher publisher{{"rig1", {}, 1.0, 4.0e6, 0.0, 1, {}}, sink};
  // Ticks for `seconds` in 10 ms steps, sending everything that is queued.
  void run_for(Clock::time_point& now, double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 100); ++i) publisher.tick(now += 10ms);
  }
};

TEST_F(TilePublisherTest, ChangedTilesGoOutAtMostOncePerPeriod) {
  publisher.reset("s1");
  Clock::time_point now = t0;
  for (int i = 0; i < 10; ++i) {  // the mapper changes the tile at 10 Hz
    publisher.update({0, 0, 0}, 0, random_points(100 + i, 1), i);
    publisher.tick(now);
    now += 100ms;
  }
  publisher.tick(now);  // one period after the first broadcast
  std::set<std::int32_t> versions;
  for (const auto& c : sink.chunks) versions.insert(c.version);
  EXPECT_EQ(versions, (std::set<std::int32_t>{1, 10}));
  ASSERT_EQ(sink.indexes.size(), 2u);
  EXPECT_FALSE(sink.indexes[0].full);
  EXPECT_EQ(sink.indexes[0].request_id, 0) << "a broadcast answers no request";
  EXPECT_EQ(sink.indexes[1].versions, std::vector<std::int32_t>{10});
}

TEST_F(TilePublisherTest, RequestsAreAnsweredWithOnlyWhatWasAskedFor) {
  publisher.reset("s1");
  Clock::time_point now = t0;
  publisher.update({0, 0, 0}, 0, random_points(40000, 2), 1);  // ~320 kB: 40 segments
  publisher.update({1, 0, 0}, 0, random_points(10, 3), 1);
  run_for(now, 1.0);
  const std::int64_t big = protocol::tile_id({0, 0, 0});
  const std::int32_t n_segments = publisher.store().find(big)->n_segments();
  ASSERT_EQ(n_segments, 40);
  ASSERT_EQ(sink.chunks.size(), static_cast<std::size_t>(n_segments) + 1);
  sink.chunks.clear();
  sink.indexes.clear();

  tile_request_t r{};
  r.request_id = 77;
  r.schema = 2;
  r.session_id = "s1";
  r.tile_ids = {big, big, protocol::tile_id({5, 5, 5}), protocol::tile_id({1, 0, 0})};
  r.versions = {0, 0, 0, 1};
  r.chunks = {2, 4, -1, -1};  // two segments, a tile the daemon does not have, one the client has
  r.n_entries = 4;
  publisher.answer(r);
  run_for(now, 0.5);
  ASSERT_EQ(sink.chunks.size(), 2u);
  EXPECT_EQ(sink.chunks[0].segment, 2);
  EXPECT_EQ(sink.chunks[1].segment, 4);
  EXPECT_EQ(sink.chunks[0].base_version, 0);
  EXPECT_TRUE(sink.indexes.empty());

  sink.chunks.clear();
  publisher.update({0, 0, 0}, 0, random_points(40000, 4), 2);  // version 2: every point differs
  r.tile_ids = {big};
  r.versions = {1};
  r.chunks = {-1};
  r.n_entries = 1;
  r.want_index = true;
  publisher.answer(r);  // holds version 1: gets every segment changed since, i.e. all
  ASSERT_EQ(sink.indexes.size(), 1u);
  EXPECT_TRUE(sink.indexes[0].full);
  EXPECT_EQ(sink.indexes[0].request_id, 77) << "an answer names its request";
  EXPECT_EQ(sink.indexes[0].n_tiles, 2);
  run_for(now, 0.5);  // (the broadcast of version 2 is merged with the answer)
  std::set<std::int32_t> segments;
  for (const auto& c : sink.chunks) {
    EXPECT_EQ(c.version, 2);
    EXPECT_EQ(c.base_version, 1);
    EXPECT_EQ(c.first_segment, 0);
    segments.insert(c.segment);
  }
  EXPECT_EQ(segments.size(), static_cast<std::size_t>(publisher.store().find(big)->n_segments()));
  EXPECT_EQ(sink.chunks.size(), segments.size()) << "no segment twice";

  r.session_id = "s0";
  sink.indexes.clear();
  publisher.answer(r);
  ASSERT_EQ(sink.indexes.size(), 1u);
  EXPECT_NE(sink.indexes[0].error.find("'s0' is not held"), std::string::npos);
  EXPECT_EQ(sink.indexes[0].request_id, 77);
}

// Points on a 5 cm grid over a floor and a wall, in the order a mapper
// appends them: what a tunnel's tile looks like (compressible, unlike random
// points).
std::vector<protocol::MapPoint> surface_points(std::size_t from, std::size_t n) {
  std::vector<protocol::MapPoint> points;
  for (std::size_t i = from; i < from + n; ++i) {
    const double a = 0.025 + 0.05 * static_cast<double>(i % 300);
    const double b = 0.025 + 0.05 * static_cast<double>(i / 300 % 300);
    if (i % 2 == 0) points.push_back({a, b, 0.5, 40.0f, 0});
    else points.push_back({a, 2.0, b, 60.0f, 0});
  }
  return points;
}

TEST_F(TilePublisherTest, AnAppendedTileCostsOnlyItsNewSegments) {
  publisher.reset("s1");
  Clock::time_point now = t0;
  auto points = surface_points(0, 50'000);
  publisher.update({0, 0, 0}, 0, points, 1);
  run_for(now, 1.0);
  const std::size_t whole = sink.bytes();
  const std::int64_t id = protocol::tile_id({0, 0, 0});
  const EncodedTile& v1 = *publisher.store().find(id);
  ASSERT_EQ(v1.n_segments(), 49);  // 48 full segments of 1024 and one of 848
  ASSERT_EQ(sink.chunks.size(), 49u);
  std::size_t frames = 0;
  for (const auto& s : v1.segments) frames += s.frame.size();
  sink.chunks.clear();

  const auto more = surface_points(50'000, 300);  // the mapper appends 300 points
  points.insert(points.end(), more.begin(), more.end());
  publisher.update({0, 0, 0}, 0, points, 2);
  run_for(now, 1.0);
  // The partial segment 48 is now full (1024) and segment 49 holds 124:
  // those two go out, nothing else.
  ASSERT_EQ(sink.chunks.size(), 2u);
  EXPECT_EQ(sink.chunks[0].segment, 48);
  EXPECT_EQ(sink.chunks[1].segment, 49);
  for (const auto& c : sink.chunks) {
    EXPECT_EQ(c.version, 2);
    EXPECT_EQ(c.base_version, 1);
    EXPECT_EQ(c.first_segment, 48);
    EXPECT_EQ(c.n_segments, 50);
  }
  const std::size_t delta = sink.bytes();
  const EncodedTile& v2 = *publisher.store().find(id);
  const std::size_t new_frames = v2.segments[48].frame.size() + v2.segments[49].frame.size();
  std::printf("whole tile: %zu B on the wire (%zu B of frames); after appending 300 points: %zu B (%.1f %%)\n", whole,
              frames, delta, 100.0 * static_cast<double>(delta) / static_cast<double>(whole));
  EXPECT_LT(delta, new_frames + 2 * 200) << "the two segments' frames plus message headers";
  EXPECT_LT(delta * 20, whole) << "an append of 0.6 % of the points costs well under 5 % of the tile";

  // A client holding version 1 that missed version 2 asks and gets the same
  // two segments; one holding nothing gets everything.
  sink.chunks.clear();
  tile_request_t r{};
  r.request_id = 9;
  r.schema = 2;
  r.session_id = "s1";
  r.tile_ids = {id};
  r.versions = {1};
  r.chunks = {-1};
  r.n_entries = 1;
  publisher.answer(r);
  run_for(now, 0.5);
  ASSERT_EQ(sink.chunks.size(), 2u);
  EXPECT_EQ(sink.chunks[0].segment, 48);
  sink.chunks.clear();
  r.versions = {0};
  publisher.answer(r);
  run_for(now, 0.5);
  EXPECT_EQ(sink.chunks.size(), 50u);
  EXPECT_EQ(sink.chunks[0].base_version, 0);
  EXPECT_EQ(sink.chunks[0].first_segment, 0);

  // Handing over the same content again is no new version.
  sink.chunks.clear();
  publisher.update({0, 0, 0}, 0, points, 3);
  run_for(now, 1.0);
  EXPECT_TRUE(sink.chunks.empty());
  EXPECT_EQ(publisher.store().find(id)->version, 2);
}

TEST_F(TilePublisherTest, SegmentsArePaced) {
  RecordingSink paced_sink;
  TilePublisher paced({"rig1", {}, 1.0, 96000.0, 0.0, 1, {}}, paced_sink);  // 96 kB/s
  paced.reset("s1");
  paced.update({0, 0, 0}, 0, random_points(60000, 5), 1);  // ~480 kB in 59 segments of ~8 kB
  Clock::time_point now = t0;
  paced.tick(now);
  const auto frame_bytes = [&] {
    std::size_t n = 0;
    for (const auto& c : paced_sink.chunks) n += c.data.size();
    return n;
  };
  EXPECT_LE(frame_bytes(), 96000u + 8300u);  // the burst allowance (two 48 kB payloads)
  EXPECT_GE(frame_bytes(), 96000u);
  for (int i = 0; i < 20; ++i) paced.tick(now += 100ms);
  EXPECT_GE(frame_bytes(), 96000u + 2 * 96000u - 8300u);
  EXPECT_LE(frame_bytes(), 96000u + 2 * 96000u + 8300u);  // + 2 s x 96 kB/s
}

}  // namespace
}  // namespace adit::daemon

namespace adit::daemon {
namespace {

TEST(TilePublisherStored, AnotherSessionIsServedFromTheLoaderOrRefusedWithItsReason) {
  RecordingSink sink;
  const std::vector<std::uint8_t> blob = protocol::encode_tile({0, 0, 0}, random_points(500, 9), {});
  std::vector<protocol::MapPoint> old_points = random_points(1500, 10);
  for (auto& p : old_points) p.x += 40.0;  // tile (2, 0, 0)
  const std::vector<std::uint8_t> old_blob = protocol::encode_tile_format1({2, 0, 0}, old_points, {});
  std::vector<std::string> asked;
  TilePublisherOptions options{"rig1", {}, 1.0, 4.0e6, 0.0, 1, {}};
  options.load_session = [&](const std::string& session, TileStore& into) -> std::string {
    asked.push_back(session);
    if (session != "old") return "no stored tiles for session '" + session + "'";
    EXPECT_EQ(into.insert_encoded(protocol::tile_id({0, 0, 0}), blob, 1), "");
    EXPECT_EQ(into.insert_encoded(protocol::tile_id({2, 0, 0}), old_blob, 1), "");  // format 1: still served
    EXPECT_EQ(into.insert_encoded(protocol::tile_id({1, 0, 0}), std::vector<std::uint8_t>{1, 2, 3}, 1),
              "tile shorter than its header");
    auto future = blob;
    future[4] = 4;  // a format this daemon does not know
    EXPECT_EQ(into.insert_encoded(protocol::tile_id({3, 0, 0}), future, 1), "tile format 4 is not 1, 2 or 3");
    return "";
  };
  TilePublisher publisher(options, sink);
  publisher.reset("current");

  tile_request_t r{};
  r.request_id = 5;
  r.session_id = "nope";
  r.want_index = true;
  publisher.answer(r);
  ASSERT_EQ(sink.indexes.size(), 1u);
  EXPECT_EQ(sink.indexes[0].error, "no stored tiles for session 'nope'");
  EXPECT_EQ(publisher.session_id(), "current");

  r.session_id = "old";
  publisher.answer(r);
  ASSERT_EQ(sink.indexes.size(), 2u);
  EXPECT_EQ(sink.indexes[1].error, "");
  EXPECT_EQ(sink.indexes[1].session_id, "old");
  EXPECT_EQ(sink.indexes[1].n_tiles, 2);
  EXPECT_EQ(publisher.session_id(), "old");
  EXPECT_EQ(publisher.store().total_points(), 2000);
  EXPECT_EQ(publisher.store().find(protocol::tile_id({2, 0, 0}))->n_segments(), 2);
  EXPECT_EQ(asked, (std::vector<std::string>{"nope", "old"}));
}

}  // namespace
}  // namespace adit::daemon

namespace adit::daemon {
namespace {

// A tile updated by what it gained (decision 074) is broadcast as one
// updated whole; an update from a point the tile does not hold is refused,
// counted, and leaves the tile as it was.
TEST_F(TilePublisherTest, TailsUpdateTheTileAndAnUpdateOutOfStepIsRefused) {
  publisher.reset("s1");
  std::vector<protocol::MapPoint> points = random_points(1500, 8);
  publisher.update({0, 0, 0}, 0, points, 1);
  const auto more = random_points(700, 9);
  publisher.update({0, 0, 0}, points.size(), more, 2);
  points.insert(points.end(), more.begin(), more.end());
  const std::int64_t id = protocol::tile_id({0, 0, 0});
  ASSERT_NE(publisher.store().find(id), nullptr);
  EXPECT_EQ(publisher.store().find(id)->version, 2);
  EXPECT_EQ(publisher.store().find(id)->n_points, 2200);
  TileStore whole({});
  whole.update({0, 0, 0}, points, 2);
  EXPECT_EQ(whole.find(id)->segments.back().content_hash, publisher.store().find(id)->segments.back().content_hash);

  publisher.update({0, 0, 0}, 5000, more, 3);  // the tile holds 2200: an update was lost
  EXPECT_EQ(publisher.counts().updates_refused, 1u);
  EXPECT_EQ(publisher.store().find(id)->version, 2);
  EXPECT_EQ(publisher.store().find(id)->n_points, 2200);
  Clock::time_point now = t0;
  run_for(now, 2.0);
  ASSERT_EQ(sink.chunks.size(), 3u) << "one broadcast: the three segments of 2200 points";
  for (const auto& c : sink.chunks) {
    EXPECT_EQ(c.version, 2);
    EXPECT_EQ(c.n_points, 2200);
  }
}

}  // namespace
}  // namespace adit::daemon
