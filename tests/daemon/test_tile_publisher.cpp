// The tile stream's daemon side on a simulated clock: rate limit, answers with
// only what was asked for, pacing.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "adit/daemon/tile_publisher.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;
using Clock = TilePublisher::Clock;

struct RecordingSink : TileSink {
  std::vector<tile_chunk_t> chunks;
  std::vector<tile_index_t> indexes;
  void send(const tile_chunk_t& c) override { chunks.push_back(c); }
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
    publisher.update({0, 0, 0}, random_points(100 + i, 1), i);
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
  publisher.update({0, 0, 0}, random_points(40000, 2), 1);  // ~320 kB: 7 chunks
  publisher.update({1, 0, 0}, random_points(10, 3), 1);
  run_for(now, 1.0);
  const std::int64_t big = protocol::tile_id({0, 0, 0});
  const std::int32_t n_chunks = publisher.store().find(big)->n_chunks;
  ASSERT_GE(n_chunks, 5);
  ASSERT_EQ(sink.chunks.size(), static_cast<std::size_t>(n_chunks) + 1);
  sink.chunks.clear();
  sink.indexes.clear();

  tile_request_t r{};
  r.request_id = 77;
  r.session_id = "s1";
  r.tile_ids = {big, big, protocol::tile_id({5, 5, 5})};
  r.versions = {1, 1, 1};
  r.chunks = {2, 4, -1};  // two chunks, and a tile the daemon does not have
  r.n_entries = 3;
  publisher.answer(r);
  run_for(now, 0.5);
  ASSERT_EQ(sink.chunks.size(), 2u);
  EXPECT_EQ(sink.chunks[0].chunk, 2);
  EXPECT_EQ(sink.chunks[1].chunk, 4);
  EXPECT_TRUE(sink.indexes.empty());

  sink.chunks.clear();
  publisher.update({0, 0, 0}, random_points(40000, 4), 2);  // version 2 now
  r.tile_ids = {big};
  r.versions = {1};
  r.chunks = {3};
  r.n_entries = 1;
  r.want_index = true;
  publisher.answer(r);  // asks for an outdated version: gets version 2 whole
  ASSERT_EQ(sink.indexes.size(), 1u);
  EXPECT_TRUE(sink.indexes[0].full);
  EXPECT_EQ(sink.indexes[0].request_id, 77) << "an answer names its request";
  EXPECT_EQ(sink.indexes[0].n_tiles, 2);
  run_for(now, 0.5);  // (the broadcast of version 2 is merged with the answer)
  std::set<std::int32_t> chunks;
  for (const auto& c : sink.chunks) {
    EXPECT_EQ(c.version, 2);
    chunks.insert(c.chunk);
  }
  EXPECT_EQ(chunks.size(), static_cast<std::size_t>(publisher.store().find(big)->n_chunks));
  EXPECT_EQ(sink.chunks.size(), chunks.size()) << "no chunk twice";

  r.session_id = "s0";
  sink.indexes.clear();
  publisher.answer(r);
  ASSERT_EQ(sink.indexes.size(), 1u);
  EXPECT_NE(sink.indexes[0].error.find("'s0' is not held"), std::string::npos);
  EXPECT_EQ(sink.indexes[0].request_id, 77);
}

TEST_F(TilePublisherTest, ChunksArePaced) {
  RecordingSink paced_sink;
  TilePublisher paced({"rig1", {}, 1.0, 96000.0, 0.0, 1, {}}, paced_sink);  // two chunks per second
  paced.reset("s1");
  paced.update({0, 0, 0}, random_points(60000, 5), 1);  // ~480 kB: 10 chunks
  Clock::time_point now = t0;
  paced.tick(now);
  EXPECT_LE(paced_sink.chunks.size(), 2u);  // the burst allowance
  for (int i = 0; i < 20; ++i) paced.tick(now += 100ms);
  EXPECT_GE(paced_sink.chunks.size(), 5u);
  EXPECT_LE(paced_sink.chunks.size(), 6u);  // 2 + 2 s x 2 chunks/s
}

}  // namespace
}  // namespace adit::daemon

namespace adit::daemon {
namespace {

TEST(TilePublisherStored, AnotherSessionIsServedFromTheLoaderOrRefusedWithItsReason) {
  RecordingSink sink;
  const std::vector<std::uint8_t> blob = protocol::encode_tile({0, 0, 0}, random_points(500, 9), {});
  std::vector<std::string> asked;
  TilePublisherOptions options{"rig1", {}, 1.0, 4.0e6, 0.0, 1, {}};
  options.load_session = [&](const std::string& session, TileStore& into) -> std::string {
    asked.push_back(session);
    if (session != "old") return "no stored tiles for session '" + session + "'";
    EXPECT_TRUE(into.insert_encoded(protocol::tile_id({0, 0, 0}), blob, 1));
    EXPECT_FALSE(into.insert_encoded(protocol::tile_id({1, 0, 0}), {1, 2, 3}, 1));  // not a tile
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
  EXPECT_EQ(sink.indexes[1].n_tiles, 1);
  EXPECT_EQ(publisher.session_id(), "old");
  EXPECT_EQ(publisher.store().total_points(), 500);
  EXPECT_EQ(asked, (std::vector<std::string>{"nope", "old"}));
}

}  // namespace
}  // namespace adit::daemon
