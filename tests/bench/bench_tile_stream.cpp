// Bandwidth of the tile stream: the old scheme (every changed tile re-sent
// whole each second, format 1) against segments (only the segments changed
// since the last broadcast), measured in the same run on the same map growth.
//
// BM_TileStreamTunnel: a robot drives through a 4 m x 3 m mine tunnel at
// 1 m/s; the map (5 cm voxels, surfaces with 1 cm roughness) grows by one
// metre of tunnel per second, i.e. 14 m^2 of new surface = 5 600 points/s,
// appended to the frontier tile (20 m tiles: it grows from 0 to 112 000
// points). The argument is the segment size in points.
//
// BM_TileStreamDemoSession: the real thing. Runs the daemon's pipeline on a
// recorded session (ADIT_TILE_BENCH_SESSION=<session.yaml>, at the replay
// speed it configures; skipped without it) and feeds every tile the mapper
// hands over to both schemes: TilePublisher (what aditd sends now) and the
// old whole-tile broadcast at most once a second. Bytes are LCM message bytes
// plus the LCM packet header and channel name.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <mutex>
#include <thread>
#include <vector>

#include "adit/config/load.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/daemon/tile_publisher.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_segment_t.hpp"

namespace {

using adit::protocol::MapPoint;

constexpr std::size_t kPayloadId = 8;   // "drone-01"
constexpr std::size_t kSessionId = 16;  // "20260101T120000Z"
// LCM's small-message header (magic, sequence number) and the channel name
// ("ADIT/drone-01/TILE" + NUL).
constexpr std::size_t kPacketOverhead = 8 + 19;

// The old scheme: a format-1 blob cut into 48 000-byte pieces, each a
// tile_chunk_t (hash 8, utime 8, schema 2, two strings (4 + n + 1), tile id 8,
// version, chunk, n_chunks, size 4 each, data).
std::size_t old_scheme_bytes(adit::protocol::TileKey key, std::span<const MapPoint> points,
                             const adit::protocol::TileParams& params) {
  const std::size_t blob = adit::protocol::encode_tile_format1(key, points, params).size();
  const std::size_t n_chunks = std::max<std::size_t>(1, (blob + adit::protocol::kChunkPayloadBytes - 1) /
                                                            adit::protocol::kChunkPayloadBytes);
  const std::size_t header = 8 + 8 + 2 + (5 + kPayloadId) + (5 + kSessionId) + 8 + 16;
  return blob + n_chunks * (header + kPacketOverhead);
}

std::size_t segment_message_bytes(const adit::protocol::TileSegment& segment) {
  adit::tile_segment_t m{};
  m.payload_id = std::string(kPayloadId, 'p');
  m.session_id = std::string(kSessionId, 's');
  m.size = static_cast<std::int32_t>(segment.frame.size());
  m.data = segment.frame;
  return static_cast<std::size_t>(m.getEncodedSize()) + kPacketOverhead;
}

// Points of tunnel metre `m` (x in [m, m+1)) on the floor, ceiling and walls.
void add_metre(int m, std::vector<MapPoint>& out, std::uint32_t& rng) {
  const auto rough = [&] {
    rng = rng * 1664525u + 1013904223u;
    return static_cast<int>((rng >> 16) % 21) * 0.001 - 0.010;
  };
  for (int i = 0; i < 20; ++i) {
    const double x = m + 0.025 + i * 0.05;
    for (int j = 0; j < 80; ++j) {  // floor and ceiling, 4 m wide
      const double y = -2.0 + 0.025 + j * 0.05;
      out.push_back({x, y, rough(), static_cast<float>(40 + j % 30), 0});
      out.push_back({x, y, 3.0 + rough(), static_cast<float>(60 + j % 20), 0});
    }
    for (int k = 0; k < 60; ++k) {  // walls, 3 m high
      const double z = 0.025 + k * 0.05;
      out.push_back({x, -2.0 + rough(), z, static_cast<float>(k), 0});
      out.push_back({x, 2.0 + rough(), z, static_cast<float>(k + 5), 0});
    }
  }
}

void BM_TileStreamTunnel(benchmark::State& state) {
  const int seconds = 60;  // three 20 m tiles
  adit::protocol::TileParams params;
  params.segment_points = static_cast<std::uint32_t>(state.range(0));
  double old_wire = 0, new_wire = 0, new_raw = 0;
  std::size_t points_total = 0;
  for (auto _ : state) {
    old_wire = new_wire = new_raw = 0;
    std::uint32_t rng = 1;
    std::vector<MapPoint> tile;
    std::vector<adit::protocol::TileSegment> segments;
    for (int s = 0; s < seconds; ++s) {
      if (s % 20 == 0) {  // the robot entered the next tile
        tile.clear();
        segments.clear();
      }
      const std::size_t before = tile.size();
      add_metre(s, tile, rng);  // appended, as the mapper does
      const auto key = adit::protocol::tile_of(s + 0.5, 0.0, 0.5, params.tile_size_m);
      old_wire += static_cast<double>(old_scheme_bytes(key, tile, params));
      const std::size_t first = adit::protocol::update_segments(key, tile, params, s + 1, segments);
      for (std::size_t i = first; i < segments.size(); ++i)
        new_wire += static_cast<double>(segment_message_bytes(segments[i]));
      new_raw += 16.0 * static_cast<double>(tile.size() - before);
      points_total += tile.size();
    }
    benchmark::DoNotOptimize(new_wire);
  }
  state.counters["old_whole_tiles_bytes_per_s"] = old_wire / seconds;
  state.counters["segments_bytes_per_s"] = new_wire / seconds;
  state.counters["ratio_old_over_segments"] = old_wire / new_wire;
  state.counters["raw_new_points_bytes_per_s"] = new_raw / seconds;
  state.counters["new_points_per_s"] = new_raw / 16.0 / seconds;
  state.counters["encoded_points_per_s"] =
      benchmark::Counter(static_cast<double>(points_total), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TileStreamTunnel)->Arg(256)->Arg(512)->Arg(1024)->Arg(2048)->Arg(4096)->Unit(benchmark::kMillisecond);

struct ByteCounter : adit::daemon::TileSink {
  std::size_t segment_bytes = 0, segments = 0, index_bytes = 0;
  void send(const adit::tile_segment_t& m) override {
    segment_bytes += static_cast<std::size_t>(m.getEncodedSize()) + kPacketOverhead;
    ++segments;
  }
  void send(const adit::tile_index_t& m) override {
    index_bytes += static_cast<std::size_t>(m.getEncodedSize()) + kPacketOverhead;
  }
};

struct Update {
  adit::protocol::TileKey key;
  std::vector<MapPoint> points;
  std::size_t first = 0;  // the tile's points from this one on
};

void BM_TileStreamDemoSession(benchmark::State& state) {
  const char* file = std::getenv("ADIT_TILE_BENCH_SESSION");
  if (file == nullptr) {
    state.SkipWithError("set ADIT_TILE_BENCH_SESSION to a session.yaml (e.g. build/sessions/demo/session.yaml)");
    return;
  }
  const adit::config::Config config = adit::config::load_config(file);
  adit::protocol::TileParams params;
  params.tile_size_m = config.map.tile_size_m;
  using Clock = adit::daemon::TilePublisher::Clock;
  for (auto _ : state) {
    // The mapper's hand-overs, taken by this thread (as aditd's endpoint does).
    std::mutex mutex;
    std::condition_variable wake;
    std::deque<Update> queue;
    bool done = false;
    adit::daemon::PipelineOptions options;
    options.sinks.tile = [&](const adit::slam::TileCoord& c, std::size_t first,
                             std::span<const adit::slam::MapSample> samples) {
      Update u{{c.x, c.y, c.z}, {}, first};
      u.points.reserve(samples.size());
      for (const auto& s : samples)
        u.points.push_back({s.position.x(), s.position.y(), s.position.z(), s.intensity, s.time_s});
      const std::lock_guard lock(mutex);
      queue.push_back(std::move(u));
      wake.notify_one();
      return true;
    };
    // The default segment size and others, on the same hand-overs.
    const std::vector<std::uint32_t> sizes{params.segment_points, 256, 512, 2048, 4096};
    std::vector<ByteCounter> sinks(sizes.size());
    std::vector<std::unique_ptr<adit::daemon::TilePublisher>> publishers;
    for (std::size_t i = 0; i < sizes.size(); ++i) {
      adit::protocol::TileParams p = params;
      p.segment_points = sizes[i];
      publishers.push_back(std::make_unique<adit::daemon::TilePublisher>(
          adit::daemon::TilePublisherOptions{"drone-01", p, 1.0, 1e12, 0.0, 1, {}}, sinks[i]));
      publishers.back()->reset(std::string(kSessionId, 's'));
    }
    std::size_t old_bytes = 0, updates = 0;
    std::map<adit::protocol::TileKey, std::vector<MapPoint>> old_dirty;
    std::map<adit::protocol::TileKey, std::vector<MapPoint>> whole;  // each tile's content, for the old scheme
    Clock::time_point old_last{};
    const auto old_broadcast = [&](Clock::time_point now) {
      old_last = now;
      for (const auto& [key, points] : old_dirty) old_bytes += old_scheme_bytes(key, points, params);
      old_dirty.clear();
    };
    std::thread consumer([&] {
      std::unique_lock lock(mutex);
      while (true) {
        wake.wait_for(lock, std::chrono::milliseconds(20), [&] { return done || !queue.empty(); });
        if (queue.empty() && done) break;
        std::deque<Update> batch;
        batch.swap(queue);
        lock.unlock();
        for (Update& u : batch) {
          ++updates;
          for (auto& publisher : publishers) publisher->update(u.key, u.first, u.points, 0);
          std::vector<MapPoint>& content = whole[u.key];
          content.resize(u.first);
          content.insert(content.end(), u.points.begin(), u.points.end());
          old_dirty[u.key] = content;
        }
        const Clock::time_point now = Clock::now();
        for (auto& publisher : publishers) publisher->tick(now);
        if (!old_dirty.empty() && now - old_last >= std::chrono::seconds(1)) old_broadcast(now);
        lock.lock();
      }
    });
    const auto start = Clock::now();
    adit::daemon::Pipeline pipeline(config, options);
    pipeline.start();
    pipeline.join();
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    {
      const std::lock_guard lock(mutex);
      done = true;
      wake.notify_one();
    }
    consumer.join();
    const Clock::time_point end = Clock::now() + std::chrono::seconds(2);  // the last changes go out
    for (auto& publisher : publishers) publisher->tick(end);
    old_broadcast(end);
    const auto bytes_of = [](const ByteCounter& c) { return c.segment_bytes + c.index_bytes; };
    const std::size_t new_bytes = bytes_of(sinks[0]);
    state.counters["session_s"] = seconds;
    state.counters["tile_updates"] = static_cast<double>(updates);
    state.counters["map_points"] = static_cast<double>(pipeline.map().size());
    state.counters["dropped_map_scans"] = static_cast<double>(pipeline.stats().dropped_map_scans.load());
    state.counters["old_whole_tiles_bytes_per_s"] = static_cast<double>(old_bytes) / seconds;
    state.counters["segments_bytes_per_s"] = static_cast<double>(new_bytes) / seconds;
    state.counters["segments_index_bytes_per_s"] = static_cast<double>(sinks[0].index_bytes) / seconds;
    for (std::size_t i = 1; i < sizes.size(); ++i)
      state.counters["segments" + std::to_string(sizes[i]) + "_bytes_per_s"] =
          static_cast<double>(bytes_of(sinks[i])) / seconds;
    state.counters["ratio_old_over_segments"] = static_cast<double>(old_bytes) / static_cast<double>(new_bytes);
    state.counters["raw_map_points_bytes_per_s"] = 16.0 * static_cast<double>(pipeline.map().size()) / seconds;
  }
}
BENCHMARK(BM_TileStreamDemoSession)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
