// The daemon's LCM endpoint and the `adit` client end to end over real LCM
// UDP multicast on this host (ttl=0), with synthetic poses and tiles.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <set>
#include <thread>
#include <tuple>

#include <fmt/format.h>

#include "adit/command_ack_t.hpp"
#include "adit/command_t.hpp"
#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/daemon/lcm_endpoint.hpp"
#include "adit/products/grid_io.hpp"
#include "adit/protocol/command_auth.hpp"
#include "adit/drivers/lidar/scan_files.hpp"
#include "adit/protocol/channels.hpp"
#include "adit/tile_segment_t.hpp"
#include "adit/file_chunk_t.hpp"
#include "adit/file_request_t.hpp"
#include "map_readers.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;
using protocol::Channel;
using protocol::MapPoint;
using protocol::SessionState;

std::string unique_url() {
  return fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + ::getpid() % 30000);
}

// A floor and two walls of a 40 m x 20 m room on a 5 cm grid with up to 1 cm
// of roughness (in whole millimetres), binned into 20 m tiles: two tiles of
// ~180 000 points, ~180 segments each.
std::map<protocol::TileKey, std::vector<MapPoint>> room() {
  std::map<protocol::TileKey, std::vector<MapPoint>> tiles;
  std::uint32_t state = 1;
  const auto rough = [&] {
    state = state * 1664525u + 1013904223u;
    return static_cast<int>((state >> 16) % 21) * 0.001 - 0.010;
  };
  const auto add = [&](double x, double y, double z, int i) {
    z += rough();
    tiles[protocol::tile_of(x, y, z, 20.0)].push_back({x, y, z, static_cast<float>(i % 200), 0});
  };
  for (int i = 0; i < 800; ++i)
    for (int j = 0; j < 399; ++j) add(0.025 + i * 0.05, 0.025 + j * 0.05, 0.5, i + j);
  for (int i = 0; i < 800; ++i)
    for (int k = 0; k < 60; ++k) {
      add(0.025 + i * 0.05, 0.3, 0.6 + k * 0.05, k);
      add(0.025 + i * 0.05, 19.7, 0.6 + k * 0.05, 2 * k);
    }
  return tiles;
}

// Millimetre integer coordinates: what survives 1 mm quantisation exactly.
using MmPoint = std::tuple<long, long, long>;
MmPoint mm(double x, double y, double z) { return {std::lround(x * 1000), std::lround(y * 1000), std::lround(z * 1000)}; }

struct Harness {
  std::string url = unique_url();
  std::string payload = fmt::format("test-{}", ::getpid());
  std::atomic<int> starts{0};
  std::atomic<int> stops{0};
  std::mutex hints_mutex;
  std::vector<protocol::LocaliseHint> hints;  // HINTs handed to the daemon
  std::unique_ptr<LcmEndpoint> endpoint;

  explicit Harness(double drop = 0.0, const std::filesystem::path& key_file = {}, std::size_t command_window = 1024,
                   const std::filesystem::path& sessions_root = {}) {
    EndpointOptions o;
    o.lcm_url = url;
    o.payload_id = payload;
    o.drop_chunk_fraction = drop;
    o.drop_seed = 7;
    o.key_file = key_file;
    o.key_check_period_s = 0.1;
    o.command_window = command_window;
    o.grid_period_s = 0.2;
    o.grid_refresh_s = 2.0;
    SessionHooks hooks;
    hooks.start = [this] { return fmt::format("s{}", ++starts); };
    // The daemon flushes elsewhere and calls session_stopped() when done
    // (the test does that from its own thread, like the daemon's main loop).
    hooks.stop = [this] { ++stops; };
    hooks.sessions = [] { return std::vector<std::string>{"s0", "s1"}; };
    hooks.hint = [this](const protocol::LocaliseHint& h) {
      const std::lock_guard lock(hints_mutex);
      hints.push_back(h);
      return hints.size() > 1 ? std::string("already localised in the prior map") : std::string();
    };
    if (!sessions_root.empty())
      hooks.session_folder = [sessions_root](const std::string& id) { return sessions_root / id; };
    endpoint = std::make_unique<LcmEndpoint>(o, hooks);
  }

  test::ProgramResult adit(std::vector<std::string> args, double timeout_s = 5) const {
    args.insert(args.begin(), (test::binary_dir() / "bin" / "adit").string());
    for (const std::string& a : {std::string("--payload"), payload, std::string("--lcm-url"), url,
                                 std::string("--timeout"), fmt::format("{}", timeout_s)})
      args.push_back(a);
    return test::run_program(args);
  }

  bool wait_for(SessionState state) const {
    for (int i = 0; i < 200 && endpoint->state() != state; ++i) std::this_thread::sleep_for(10ms);
    return endpoint->state() == state;
  }
};

// Listens to every ADIT/ channel on its own thread: sizes and acks.
struct Sniffer {
  lcm::LCM lcm;
  std::atomic<bool> running{true};
  std::atomic<std::size_t> largest{0};
  std::atomic<std::size_t> messages{0};
  std::mutex mutex;
  std::vector<command_ack_t> acks;
  std::vector<std::pair<std::int64_t, std::int32_t>> chunk_versions;
  std::vector<std::string> file_errors;
  std::string file_error() {
    const std::lock_guard lock(mutex);
    return file_errors.empty() ? "" : file_errors.back();
  }
  std::thread thread;

  explicit Sniffer(const std::string& url) : lcm(url) {
    lcm.subscribe("ADIT/.*", &Sniffer::on, this);
    thread = std::thread([this] {
      while (running) lcm.handleTimeout(10);
    });
  }
  ~Sniffer() {
    running = false;
    thread.join();
  }
  void on(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    ++messages;
    std::size_t seen = largest;
    while (rbuf->data_size > seen && !largest.compare_exchange_weak(seen, rbuf->data_size)) {
    }
    const std::lock_guard lock(mutex);
    if (channel.ends_with("/ACK")) {
      command_ack_t ack;
      if (ack.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) > 0) acks.push_back(ack);
    } else if (channel.ends_with("/FILE")) {
      file_chunk_t c;
      if (c.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) > 0 && !c.error.empty()) file_errors.push_back(c.error);
    } else if (channel.ends_with("/TILE")) {
      tile_segment_t c;
      if (c.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) > 0) chunk_versions.emplace_back(c.tile_id, c.version);
    }
  }
  std::vector<command_ack_t> acks_for(std::int64_t request_id) {
    const std::lock_guard lock(mutex);
    std::vector<command_ack_t> out;
    for (const auto& a : acks)
      if (a.request_id == request_id) out.push_back(a);
    return out;
  }
};

command_t command(const Harness& h, std::int64_t id, const std::string& verb) {
  command_t c;
  c.schema = 1;
  c.request_id = id;
  c.payload_id = h.payload;
  c.verb = verb;
  c.n_args = 0;  // LCM types leave numbers uninitialised
  c.auth_size = 0;
  return c;
}

// Poses at 10 Hz (`position(i)`) and a status every fifth (`status(i, utime)`)
// from a thread of their own while `body` runs.
template <typename Position, typename Status, typename Body>
void feed_while(Harness& h, Position position, Status status, Body body) {
  std::atomic<bool> feeding{true};
  std::thread feeder([&] {
    for (int i = 0; feeding; ++i) {
      PoseSample p;
      p.utime = i * 100'000;
      p.position = position(i);
      p.flags = 1;
      h.endpoint->publish_pose(p);  // scan rate: 10 Hz
      if (i % 5 == 0) h.endpoint->publish_status(status(i, p.utime));  // status: 2 Hz
      std::this_thread::sleep_for(100ms);
    }
  });
  body();
  feeding = false;
  feeder.join();
}

TEST(LcmEndpoint, StartAndStopChangeTheStateWithAcks) {
  Harness h;
  auto r = h.adit({"start"});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("state MAPPING, session s1"), std::string::npos) << r.out;
  EXPECT_EQ(h.endpoint->state(), SessionState::mapping);

  r = h.adit({"start"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("START rejected: already mapping (state MAPPING)"), std::string::npos) << r.err;
  EXPECT_EQ(h.starts, 1);

  r = h.adit({"stop"});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("state STOPPING"), std::string::npos) << r.out;
  EXPECT_EQ(h.endpoint->state(), SessionState::stopping);
  r = h.adit({"start"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("still stopping the last session"), std::string::npos) << r.err;
  h.endpoint->session_stopped();
  EXPECT_TRUE(h.wait_for(SessionState::idle));
  EXPECT_EQ(h.stops, 1);

  r = h.adit({"sessions"});
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(r.out, "s0\ns1\n");
  r = h.adit({"stop"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("not mapping"), std::string::npos) << r.err;
}

TEST(LcmEndpoint, AcksArriveWithin100ms) {
  Harness h;
  Sniffer sniffer(h.url);
  lcm::LCM lcm(h.url);
  std::this_thread::sleep_for(50ms);
  for (std::int64_t id = 100; id < 105; ++id) {
    const auto sent = std::chrono::steady_clock::now();
    const command_t c = command(h, id, "PING");
    lcm.publish(protocol::channel_name(h.payload, Channel::command), &c);
    while (sniffer.acks_for(id).empty() && std::chrono::steady_clock::now() - sent < 1s)
      std::this_thread::sleep_for(1ms);
    const auto latency = std::chrono::steady_clock::now() - sent;
    ASSERT_FALSE(sniffer.acks_for(id).empty());
    EXPECT_LT(latency, 100ms);
  }
}

TEST(LcmEndpoint, PosesAndStatusArriveInWatch) {
  Harness h;
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  test::ProgramResult r;
  feed_while(
      h, [](int i) { return std::array<double, 3>{0.1 * i, 0, 1}; },
      [](int, std::int64_t utime) {
        StatusSample s;
        s.sensors.push_back({"lidar0", 10.0f, 0, utime, 0.0f});
        s.disk_free_bytes = 5'000'000'000;
        return s;
      },
      [&] { r = h.adit({"watch", "--duration", "2"}); });
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("MAPPING s1 | lidar0 10.0 Hz"), std::string::npos) << r.out;
  std::size_t poses = 0;
  const auto at = r.out.rfind('\n', r.out.size() - 2);
  ASSERT_EQ(std::sscanf(r.out.c_str() + at + 1, "%zu poses received", &poses), 1) << r.out;
  EXPECT_GE(poses, 15u);  // 10 Hz for 2 s, minus start-up
  EXPECT_LE(poses, 21u);
  const auto status = h.adit({"status"}, 1);
  EXPECT_EQ(status.exit_status, 1) << "nobody publishes status any more: " << status.out;
  EXPECT_EQ(r.out.find("loops"), std::string::npos) << "no loop closure, no loops: " << r.out;
  EXPECT_EQ(h.endpoint->counters().loop_statuses_published.load(), 0U);
}

// A session's loop closure goes out as loop_status_t with each status;
// `adit watch` shows it on the status's line, `adit status` on a line of its own.
TEST(LcmEndpoint, LoopsGoOutWithTheStatusAndWatchAndStatusShowThem) {
  Harness h;
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  test::ProgramResult r, status;
  feed_while(
      h, [](int i) { return std::array<double, 3>{0.1 * i, 0, 1}; },
      [](int, std::int64_t utime) {
        StatusSample s;
        s.sensors.push_back({"lidar0", 10.0f, 0, utime, 0.0f});
        LoopStatus loops;
        loops.keyframes = 40;
        loops.candidates = 6;
        loops.accepted = 3;
        loops.rejected = 2;
        loops.last_loop_utime = utime;
        loops.correction_m = 0.25F;
        loops.moves_map = true;
        s.loops = loops;
        return s;
      },
      [&] {
        r = h.adit({"watch", "--duration", "2"});
        status = h.adit({"status"});
      });
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("| loops 3 closed, 2 refused, correction 0.25 m"), std::string::npos) << r.out;
  ASSERT_EQ(status.exit_status, 0) << status.err;
  EXPECT_NE(status.out.find("loops     3 closed, 2 refused (6 candidates, 40 keyframes); correction 0.25 m"),
            std::string::npos)
      << status.out;
  EXPECT_GE(h.endpoint->counters().loop_statuses_published.load(), 3U);
}

// Once the session is anchored to a prior map, its frame_t goes out with the
// status, and `adit watch` shows the pose in the prior's frame.
TEST(LcmEndpoint, TheFrameGoesOutWithTheStatusAndWatchShowsThePoseInIt) {
  Harness h;
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  test::ProgramResult r;
  feed_while(
      h, [](int) { return std::array<double, 3>{1.0, 0.0, 1.0}; },
      [](int i, std::int64_t) {
        StatusSample s;
        MapFrame f;  // a quarter turn about z, then 100 m east and 50 m north
        f.source = 1;
        f.position = {100.0, 50.0, 0.0};
        f.orientation = {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
        if (i >= 5) s.frame = f;  // the first status has none yet: identity
        return s;
      },
      [&] { r = h.adit({"watch", "--duration", "2"}); });
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("x 100.00 y 51.00 z 1.00 (prior map)"), std::string::npos) << r.out;
  EXPECT_GE(h.endpoint->counters().frames_published.load(), 3U);
}

// HINT (`adit hint`): refused with the reason while idle or with a bad
// argument; while mapping its arguments reach the daemon's hook whole, and the
// hook's refusal comes back in the ack.
TEST(LcmEndpoint, HintReachesTheSessionWhileMappingWithItsReasonWhenRefused) {
  Harness h;
  auto r = h.adit({"hint", "--x", "12.5", "--y", "-3"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("HINT rejected: no session is mapping"), std::string::npos) << r.err;
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  r = h.adit({"hint", "--x", "12.5", "--y", "-3", "--radius", "3", "--heading", "90"});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("hint taken"), std::string::npos) << r.out;
  {
    const std::lock_guard lock(h.hints_mutex);
    ASSERT_EQ(h.hints.size(), 1U);
    EXPECT_EQ(h.hints[0].x_m, 12.5);
    EXPECT_EQ(h.hints[0].y_m, -3.0);
    EXPECT_EQ(h.hints[0].radius_m, 3.0);
    EXPECT_EQ(h.hints[0].heading_deg, 90.0);
    EXPECT_EQ(h.hints[0].heading_tolerance_deg, 20.0);
  }
  r = h.adit({"hint", "--x", "1", "--y", "2"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("HINT rejected: already localised"), std::string::npos) << r.err;
  // A bad argument from another client is refused before the daemon sees it.
  lcm::LCM lcm(h.url);
  Sniffer sniffer(h.url);
  std::this_thread::sleep_for(50ms);
  command_t c = command(h, 900, "HINT");
  c.args = {"x=1", "y=nan"};
  c.n_args = 2;
  lcm.publish(protocol::channel_name(h.payload, Channel::command), &c);
  for (int i = 0; i < 100 && sniffer.acks_for(900).empty(); ++i) std::this_thread::sleep_for(10ms);
  const auto acks = sniffer.acks_for(900);
  ASSERT_FALSE(acks.empty());
  EXPECT_FALSE(acks[0].accepted);
  EXPECT_NE(acks[0].reason.find("y: 'nan' is not a number"), std::string::npos) << acks[0].reason;
  const std::lock_guard lock(h.hints_mutex);
  EXPECT_EQ(h.hints.size(), 2U);
}

TEST(LcmEndpoint, DownloadAssemblesTheWholeMapDespite20PercentDroppedChunks) {
  Harness h(0.2);
  Sniffer sniffer(h.url);
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  std::set<MmPoint> expected;
  std::size_t expected_count = 0;
  for (auto& [key, points] : room()) {
    for (const auto& p : points) expected.insert(mm(p.x, p.y, p.z));
    expected_count += points.size();
    h.endpoint->publish_tile({1'763'700'000'000'000, key, std::move(points)});
  }
  std::this_thread::sleep_for(1500ms);  // the changed tiles go out once, losing ~20 %
  // Every point handed over was taken by the endpoint's thread (the gauge the
  // mapping thread holds re-sends back by; no wrap below zero).
  EXPECT_EQ(h.endpoint->tile_points_waiting(), 0U);

  const auto dir = std::filesystem::temp_directory_path() / fmt::format("adit-download-{}", ::getpid());
  std::filesystem::create_directories(dir);
  for (const std::string format : {"ply", "pcd", "las"}) {
    const auto file = dir / ("map." + format);
    const auto r = h.adit({"download", "--format", format, "--out", file.string()}, 10);
    ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
    EXPECT_NE(r.err.find("100%"), std::string::npos) << "progress bar: " << r.err;
    std::vector<test::XyzI> points;
    if (format == "ply") points = test::read_ply(file);
    if (format == "las") points = test::read_las_checked(file);
    if (format == "pcd") {
      std::vector<drivers::CloudPoint> cloud;
      drivers::read_pcd(file, cloud);
      for (const auto& c : cloud) points.push_back({c.x, c.y, c.z, c.intensity});
    }
    ASSERT_EQ(points.size(), expected_count) << format;
    std::set<MmPoint> got;
    for (const auto& p : points) got.insert(mm(p.x, p.y, p.z));
    EXPECT_EQ(got, expected) << format;
  }
  std::filesystem::remove_all(dir);
  const auto& c = h.endpoint->counters();
  // The hook drops each segment with p = 0.2: over ~400 sends that is
  // ~80 expected; at least 3 and a fraction near 0.2 show it was exercised.
  const double dropped = static_cast<double>(c.chunks_dropped_by_hook.load());
  const double attempts = dropped + static_cast<double>(c.chunks_published.load());
  EXPECT_GE(dropped, 3.0);
  EXPECT_NEAR(dropped / attempts, 0.2, 0.12) << dropped << " of " << attempts;
  std::printf("chunks: %llu published, %llu dropped by the hook; %llu tile requests\n",
              static_cast<unsigned long long>(c.chunks_published.load()),
              static_cast<unsigned long long>(c.chunks_dropped_by_hook.load()),
              static_cast<unsigned long long>(c.tile_requests.load()));
  EXPECT_GT(c.tile_requests.load(), 3u);
  EXPECT_LT(sniffer.largest.load(), protocol::kMaxMessageBytes);
  EXPECT_LT(c.largest_message_bytes.load(), protocol::kMaxMessageBytes);
  EXPECT_GT(sniffer.messages.load(), 10u);
}

// `adit download` places the map as the session's frame_t places its tiles:
// in the prior map's frame once anchored, as the session's map files are.
TEST(LcmEndpoint, DownloadPlacesTheMapWhereTheSessionsFramePutsItsTiles) {
  Harness h;
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  std::vector<protocol::MapPoint> all;
  for (auto& [key, points] : room()) {
    all.insert(all.end(), points.begin(), points.end());
    h.endpoint->publish_tile({1'763'700'000'000'000, key, std::move(points)});
  }
  // map <- tiles: a quarter turn about z, then 100 m east and 50 m north; the
  // poses' transform differs (a loop correction on top), and is not the map's.
  MapFrame f;
  f.source = 1;
  f.position = {101.0, 50.0, 0.0};
  f.orientation = {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
  f.tiles_position = {100.0, 50.0, 0.0};
  f.tiles_orientation = {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
  const auto file = std::filesystem::temp_directory_path() / fmt::format("adit-download-frame-{}.ply", ::getpid());
  test::ProgramResult r;
  feed_while(
      h, [](int) { return std::array<double, 3>{0, 0, 0}; },
      [&](int, std::int64_t) {
        StatusSample s;
        s.frame = f;
        return s;
      },
      [&] { r = h.adit({"download", "--format", "ply", "--out", file.string(), "--quiet"}, 10); });
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("in the prior map's frame"), std::string::npos) << r.out;
  std::set<MmPoint> expected;
  for (const protocol::MapPoint& p : all) expected.insert(mm(100.0 - p.y, 50.0 + p.x, p.z));
  std::set<MmPoint> got;
  for (const auto& p : test::read_ply(file)) got.insert(mm(p.x, p.y, p.z));
  EXPECT_EQ(got, expected);
  std::filesystem::remove(file);
}

// After a restart the daemon holds no live session: a stored session's tiles
// come from its folder, and its frame (hooks.stored_frame: the prior's anchor,
// the graph's last correction) goes with the answers, so `adit download`
// places them as it did while the session ran; without one they stay put.
TEST(LcmEndpoint, AStoredSessionsDownloadIsPlacedByItsStoredFrame) {
  EndpointOptions o;
  o.lcm_url = unique_url();
  o.payload_id = fmt::format("stored-{}", ::getpid());
  std::vector<MapPoint> all;
  for (const auto& [key, points] : room()) all.insert(all.end(), points.begin(), points.end());
  SessionHooks hooks;
  hooks.load_tiles = [](const std::string& id, TileStore& into) -> std::string {
    if (id != "anchored" && id != "plain") return fmt::format("no session '{}'", id);
    for (const auto& [key, points] : room()) into.update(key, points, 1);
    return "";
  };
  MapFrame f;  // map <- tiles: a quarter turn about z, then 100 m east and 50 m north
  f.source = kFrameSourcePriorMap;
  f.position = {101.0, 50.0, 0.0};
  f.orientation = {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
  f.tiles_position = {100.0, 50.0, 0.0};
  f.tiles_orientation = {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
  hooks.stored_frame = [&f](const std::string& id) { return id == "anchored" ? std::optional(f) : std::nullopt; };
  LcmEndpoint endpoint(o, hooks);
  const auto adit = (test::binary_dir() / "bin" / "adit").string();
  const auto download = [&](const std::string& session, std::set<MmPoint>& got) {
    const auto file = std::filesystem::temp_directory_path() / fmt::format("adit-stored-{}-{}.ply", session, ::getpid());
    const auto r = test::run_program({adit, "download", "--session", session, "--format", "ply", "--out", file.string(),
                                      "--quiet", "--payload", o.payload_id, "--lcm-url", o.lcm_url, "--timeout", "10"});
    for (const auto& p : test::read_ply(file)) got.insert(mm(p.x, p.y, p.z));
    std::filesystem::remove(file);
    return r;
  };
  std::set<MmPoint> got;
  const auto anchored = download("anchored", got);
  ASSERT_EQ(anchored.exit_status, 0) << anchored.out << anchored.err;
  EXPECT_NE(anchored.out.find("in the prior map's frame"), std::string::npos) << anchored.out;
  std::set<MmPoint> expected;
  for (const MapPoint& p : all) expected.insert(mm(100.0 - p.y, 50.0 + p.x, p.z));
  EXPECT_EQ(got, expected);
  EXPECT_GE(endpoint.counters().frames_published.load(), 1U);

  got.clear();
  const auto plain = download("plain", got);
  ASSERT_EQ(plain.exit_status, 0) << plain.out << plain.err;
  EXPECT_NE(plain.out.find("in the session's own frame"), std::string::npos) << plain.out;
  expected.clear();
  for (const MapPoint& p : all) expected.insert(mm(p.x, p.y, p.z));
  EXPECT_EQ(got, expected);
}

TEST(LcmEndpoint, ChangedTilesGoOutAtMostOnceASecond) {
  Harness h;
  Sniffer sniffer(h.url);
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 25; ++i) {  // the mapper changes one tile at 10 Hz
    std::vector<MapPoint> points;
    for (int j = 0; j <= i; ++j) points.push_back({1.0 + j * 0.05, 2.0, 0.5, 1, 0});
    h.endpoint->publish_tile({i, protocol::TileKey{0, 0, 0}, std::move(points)});
    std::this_thread::sleep_for(100ms);
  }
  std::this_thread::sleep_for(1100ms);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::set<std::int32_t> versions;
  {
    const std::lock_guard lock(sniffer.mutex);
    for (const auto& [id, version] : sniffer.chunk_versions) versions.insert(version);
  }
  EXPECT_GE(versions.size(), 2u);
  EXPECT_LE(static_cast<double>(versions.size()), std::ceil(seconds) + 1);
  EXPECT_TRUE(versions.count(25)) << "the last version must go out";
}

// The live grid: patches sent before a client listened reach it by the
// refresh cycle (grid_refresh_s 2 s here), and `adit grid` writes them as a
// map_server grid with every patch in its place.
TEST(LcmEndpoint, ALateClientGetsTheWholeLiveGridWithinARefreshCycle) {
  Harness h;
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  constexpr int kCells = 32;
  const auto patch = [&](int x, int y) {
    GridPatchUpdate u{1, x, y, 1, 6, 0.1F, kCells, std::vector<std::int8_t>(kCells * kCells, -1)};
    for (int i = 0; i < kCells; ++i) u.cells[static_cast<std::size_t>(i * kCells + i)] = 100;  // a diagonal wall
    u.cells[static_cast<std::size_t>((x + 2) * kCells + (y + 3))] = 0;                          // one free cell each
    return u;
  };
  for (int x = -1; x <= 1; ++x)
    for (int y = 0; y <= 1; ++y) ASSERT_TRUE(h.endpoint->publish_grid(patch(x, y)));
  std::this_thread::sleep_for(500ms);  // their first broadcast is over
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / fmt::format("adit-grid-{}", ::getpid());
  std::filesystem::create_directories(dir);
  const test::ProgramResult r = h.adit({"grid", "--out", (dir / "live").string(), "--duration", "3"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("6 patches"), std::string::npos) << r.out;
  const products::Grid2d grid = products::read_grid(dir / "live.yaml");
  EXPECT_NEAR(grid.resolution_m, 0.1, 1e-9);
  EXPECT_NEAR(grid.origin_x, -3.2, 1e-6);
  EXPECT_NEAR(grid.origin_y, 0.0, 1e-9);
  ASSERT_EQ(grid.width, 3 * kCells);
  ASSERT_EQ(grid.height, 2 * kCells);
  for (int x = -1; x <= 1; ++x)
    for (int y = 0; y <= 1; ++y) {
      const int col0 = (x + 1) * kCells, row0 = y * kCells;
      EXPECT_EQ(grid.at(col0 + 5, row0 + 5), products::kOccupied) << x << ", " << y;
      EXPECT_EQ(grid.at(col0 + 5, row0 + 6), products::kUnknown) << x << ", " << y;
      EXPECT_EQ(grid.at(col0 + y + 3, row0 + x + 2), products::kFree) << x << ", " << y;
    }
  EXPECT_GT(h.endpoint->counters().grid_patches_published.load(), 6U);  // refreshed
  std::filesystem::remove_all(dir);
}

TEST(LcmEndpoint, BadCommandsAreRejectedOrIgnoredAndTheStateStays) {
  Harness h;
  Sniffer sniffer(h.url);
  lcm::LCM lcm(h.url);
  const std::string channel = protocol::channel_name(h.payload, Channel::command);
  const auto ack_of = [&](std::int64_t id) {
    for (int i = 0; i < 100 && sniffer.acks_for(id).empty(); ++i) std::this_thread::sleep_for(10ms);
    const auto acks = sniffer.acks_for(id);
    return acks.empty() ? command_ack_t{} : acks.back();
  };
  std::this_thread::sleep_for(50ms);

  command_t c = command(h, 11, "LAUNCH");
  lcm.publish(channel, &c);
  auto ack = ack_of(11);
  EXPECT_FALSE(ack.accepted);
  EXPECT_NE(ack.reason.find("unknown verb 'LAUNCH'"), std::string::npos) << ack.reason;

  c = command(h, 12, "START");
  c.payload_id = "someone-else";
  lcm.publish(channel, &c);
  ack = ack_of(12);
  EXPECT_FALSE(ack.accepted);
  EXPECT_NE(ack.reason.find("addressed to payload 'someone-else'"), std::string::npos) << ack.reason;

  const std::uint8_t junk[] = {0xde, 0xad, 0xbe, 0xef, 1, 2, 3};
  lcm.publish(channel, junk, sizeof junk);
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(h.endpoint->counters().commands_malformed.load(), 1u);
  EXPECT_EQ(h.endpoint->state(), SessionState::idle);
  EXPECT_EQ(h.starts, 0);

  c = command(h, 13, "START");
  lcm.publish(channel, &c);
  const command_ack_t first = ack_of(13);
  ASSERT_TRUE(first.accepted) << first.reason;
  lcm.publish(channel, &c);  // the client's retry, or a replay
  lcm.publish(channel, &c);
  for (int i = 0; i < 100 && sniffer.acks_for(13).size() < 3; ++i) std::this_thread::sleep_for(10ms);
  const auto acks = sniffer.acks_for(13);
  ASSERT_EQ(acks.size(), 3u);
  for (const auto& a : acks) {
    EXPECT_TRUE(a.accepted);
    EXPECT_EQ(a.reason, first.reason);
    EXPECT_EQ(a.utime, first.utime) << "a replay is answered with the stored ack";
  }
  EXPECT_EQ(h.starts, 1) << "a replayed START must not start a second session";
  EXPECT_EQ(h.endpoint->counters().commands_replayed.load(), 2u);
  EXPECT_EQ(h.endpoint->state(), SessionState::mapping);
}

TEST(LcmEndpoint, AFailingStartHookIsRejectedAndLeavesTheStateIdle) {
  EndpointOptions o;
  o.lcm_url = unique_url();
  o.payload_id = fmt::format("fail-{}", ::getpid());
  SessionHooks hooks;
  hooks.start = []() -> std::string { throw std::runtime_error("disk full"); };
  LcmEndpoint endpoint(o, hooks);
  const auto adit = (test::binary_dir() / "bin" / "adit").string();
  const auto r =
      test::run_program({adit, "start", "--payload", o.payload_id, "--lcm-url", o.lcm_url, "--timeout", "3"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("START rejected: START failed: disk full (state IDLE)"), std::string::npos) << r.err;
  EXPECT_EQ(endpoint.state(), SessionState::idle);
}

TEST(LcmEndpoint, DownloadOfASessionTheDaemonDoesNotHoldSaysSo) {
  Harness h;
  ASSERT_EQ(h.adit({"start"}).exit_status, 0);
  // While mapping, the live session's tiles stay; another session must wait.
  const auto busy = h.adit({"download", "--session", "s9", "--format", "ply", "--out", "/nonexistent/x.ply"}, 2);
  EXPECT_EQ(busy.exit_status, 1);
  EXPECT_NE(busy.err.find("download failed: mapping session 's1' is running: download other sessions after STOP"),
            std::string::npos)
      << busy.err;
  // Idle, and no stored-session loader (the harness has none).
  ASSERT_EQ(h.adit({"stop"}).exit_status, 0);
  h.endpoint->session_stopped();
  for (int i = 0; i < 100 && h.endpoint->state() != SessionState::idle; ++i) std::this_thread::sleep_for(10ms);
  const auto r = h.adit({"download", "--session", "s9", "--format", "ply", "--out", "/nonexistent/x.ply"}, 2);
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("download failed: session 's9' is not held by this daemon"), std::string::npos) << r.err;
}

std::string file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The products of a stored session over real LCM: every product file whole
// (one of 3.5 MB: more than one request's 64 chunks), nothing else of the
// session folder, and clear errors.
TEST(LcmEndpoint, DownloadOfProductsFetchesTheProductFilesOnly) {
  const auto root = std::filesystem::temp_directory_path() / fmt::format("adit-products-{}", ::getpid());
  std::filesystem::remove_all(root);
  const auto products = root / "s7" / "products";
  std::filesystem::create_directories(products / "sections");
  std::filesystem::create_directories(root / "s8");
  std::mt19937 rng(3);
  std::string big(3'500'000, '\0');
  for (char& c : big) c = static_cast<char>(rng());
  std::ofstream(products / "top_view.png", std::ios::binary) << big;
  std::ofstream(products / "grid.yaml") << "image: grid.pgm\nresolution: 0.05\n";
  std::ofstream(products / "grid.pgm", std::ios::binary) << "P5\n2 1\n255\n" << std::string("\0\xfe", 2);
  std::ofstream(products / "sections" / "section_001.svg") << "<svg/>";
  std::ofstream(products / "secret.txt") << "not a product";
  std::ofstream(root / "s7" / "map.las") << "LASF";
  Harness h(0.0, {}, 1024, root);

  const auto out = root / "fetched";
  const auto all = h.adit({"download", "--session", "s7", "--products", "--out", out.string()}, 10);
  ASSERT_EQ(all.exit_status, 0) << all.out << all.err;
  EXPECT_NE(all.out.find("4 product files of session s7"), std::string::npos) << all.out;
  for (const char* f : {"top_view.png", "grid.yaml", "grid.pgm", "sections/section_001.svg"})
    EXPECT_EQ(file_bytes(out / f), file_bytes(products / f)) << f;
  EXPECT_FALSE(std::filesystem::exists(out / "secret.txt"));

  const auto one = h.adit({"download", "--session", "s7", "--product", "grid.yaml", "--out", (root / "one").string()});
  ASSERT_EQ(one.exit_status, 0) << one.err;
  EXPECT_EQ(file_bytes(root / "one" / "grid.yaml"), file_bytes(products / "grid.yaml"));

  const auto outside = h.adit({"download", "--session", "s7", "--product", "../map.las", "--out", (root / "x").string()});
  EXPECT_EQ(outside.exit_status, 2);
  EXPECT_NE(outside.err.find("is not a product file"), std::string::npos) << outside.err;
  const auto missing = h.adit({"download", "--session", "s7", "--product", "occupancy.bt", "--out", (root / "x").string()}, 2);
  EXPECT_EQ(missing.exit_status, 1);
  EXPECT_NE(missing.err.find("session 's7' has no products/occupancy.bt"), std::string::npos) << missing.err;
  const auto none = h.adit({"download", "--session", "s8", "--products", "--out", (root / "x").string()}, 2);
  EXPECT_EQ(none.exit_status, 1);
  EXPECT_NE(none.err.find("session 's8' has no products (yet): aditd makes them after STOP"), std::string::npos) << none.err;

  // A request the client would not send: the daemon refuses it too.
  Sniffer sniffer(h.url);
  lcm::LCM lcm(h.url);
  file_request_t r{};
  r.schema = 1;
  r.request_id = 42;
  r.payload_id = h.payload;
  r.session_id = "s7";
  r.path = "products/../map.las";
  r.n_chunks = 64;
  lcm.publish(protocol::channel_name(h.payload, Channel::file_request), &r);
  std::string error;
  for (int i = 0; i < 200 && error.empty(); ++i) {
    std::this_thread::sleep_for(10ms);
    error = sniffer.file_error();
  }
  EXPECT_NE(error.find("is not a product file"), std::string::npos) << error;
  EXPECT_LT(sniffer.largest.load(), protocol::kMaxMessageBytes);
  EXPECT_GT(h.endpoint->counters().file_chunks_published.load(), 73U);
  std::filesystem::remove_all(root);
}

TEST(LcmEndpoint, ClientSaysSoWhenNoPayloadAnswers) {
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", 50000 + ::getpid() % 10000);
  const auto adit = (test::binary_dir() / "bin" / "adit").string();
  const auto start = std::chrono::steady_clock::now();
  auto r = test::run_program({adit, "start", "--payload", "nobody", "--lcm-url", url, "--timeout", "0.5"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("no payload 'nobody' answered within 0.5 s"), std::string::npos) << r.err;
  r = test::run_program({adit, "download", "--payload", "nobody", "--lcm-url", url, "--timeout", "0.5", "--format",
                         "las", "--out", "/nonexistent/x.las"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("no payload 'nobody' answered"), std::string::npos) << r.err;
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  r = test::run_program({adit, "status", "--payload", "bad/id", "--lcm-url", url});
  EXPECT_EQ(r.exit_status, 2) << r.err;
}

// --- authenticated commands (docs/PROTOCOL.md) ------------------------------

namespace auth {

struct KeyDir {
  std::filesystem::path dir = test::binary_dir() / fmt::format("auth-keys-{}", ::getpid());
  KeyDir() {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~KeyDir() { std::filesystem::remove_all(dir); }
  std::filesystem::path write(const std::string& name, const protocol::CommandKey& key, bool replace = false) const {
    protocol::write_key_file(dir / name, key, replace);
    return dir / name;
  }
};

// Publishes raw commands and waits for their acks.
struct Sender {
  Sniffer sniffer;
  lcm::LCM lcm;
  std::string channel;
  explicit Sender(const Harness& h)
      : sniffer(h.url), lcm(h.url), channel(protocol::channel_name(h.payload, Channel::command)) {
    std::this_thread::sleep_for(50ms);
  }
  command_ack_t send(const command_t& c) {
    lcm.publish(channel, &c);
    for (int i = 0; i < 100 && sniffer.acks_for(c.request_id).empty(); ++i) std::this_thread::sleep_for(10ms);
    const auto acks = sniffer.acks_for(c.request_id);
    return acks.empty() ? command_ack_t{} : acks.back();
  }
};

command_t signed_command(const Harness& h, std::int64_t id, const std::string& verb, const protocol::CommandKey& key,
                         std::int64_t utime = realtime_us()) {
  command_t c = command(h, id, verb);
  c.utime = utime;
  protocol::sign_command(c, key);
  return c;
}

TEST(LcmEndpointAuth, UnsignedAndWronglySignedAreRejectedSignedAreExecuted) {
  const KeyDir keys;
  const protocol::CommandKey key = protocol::CommandKey::generate();
  const auto key_file = keys.write("payload.key", key);
  const auto wrong_file = keys.write("wrong.key", protocol::CommandKey::generate());
  Harness h(0.0, key_file);
  EXPECT_TRUE(h.endpoint->counters().commands_authenticated.load());

  auto r = h.adit({"start"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("START rejected: unsigned: this payload accepts only signed commands"), std::string::npos)
      << r.err;
  r = h.adit({"start", "--key", wrong_file.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("START rejected: bad tag: signed with key id"), std::string::npos) << r.err;
  EXPECT_EQ(h.endpoint->state(), SessionState::idle);
  EXPECT_EQ(h.starts, 0);

  r = h.adit({"start", "--key", key_file.string()});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("state MAPPING, session s1"), std::string::npos) << r.out;
  r = h.adit({"sessions", "--key", key_file.string()});
  EXPECT_EQ(r.out, "s0\ns1\n");
  r = h.adit({"ping", "--key", key_file.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  r = h.adit({"stop"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_EQ(h.endpoint->state(), SessionState::mapping);
  r = h.adit({"stop", "--key", key_file.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(h.endpoint->state(), SessionState::stopping);
  const EndpointCounters& n = h.endpoint->counters();
  EXPECT_EQ(n.commands_unsigned.load(), 2u);
  EXPECT_EQ(n.commands_bad_tag.load(), 1u);
  EXPECT_EQ(n.commands_executed.load(), 4u);
}

TEST(LcmEndpointAuth, TamperedStaleOtherPayloadAndReplayedChangeNoState) {
  const KeyDir keys;
  const protocol::CommandKey key = protocol::CommandKey::generate();
  Harness h(0.0, keys.write("payload.key", key), 2);
  Sender s(h);

  command_t tampered = signed_command(h, 21, "PING", key);
  tampered.verb = "START";
  auto ack = s.send(tampered);
  EXPECT_FALSE(ack.accepted);
  EXPECT_EQ(ack.reason, "bad tag: the tag does not match the command's content");

  ack = s.send(signed_command(h, 22, "START", key, realtime_us() - 60'000'000));
  EXPECT_FALSE(ack.accepted);
  EXPECT_EQ(ack.reason.rfind("stale: signed at", 0), 0u) << ack.reason;

  command_t elsewhere = command(h, 23, "START");
  elsewhere.payload_id = "another-payload";
  elsewhere.utime = realtime_us();
  protocol::sign_command(elsewhere, key);
  ack = s.send(elsewhere);
  EXPECT_FALSE(ack.accepted);
  EXPECT_EQ(ack.reason.rfind("other payload: addressed to payload 'another-payload'", 0), 0u) << ack.reason;
  EXPECT_EQ(h.starts, 0);
  EXPECT_EQ(h.endpoint->state(), SessionState::idle);

  // A signed START, captured and sent again: answered with the stored ack,
  // not executed; once its answer is forgotten (window of 2 ids), refused.
  const command_t start = signed_command(h, 24, "START", key);
  ack = s.send(start);
  ASSERT_TRUE(ack.accepted) << ack.reason;
  ASSERT_EQ(s.send(signed_command(h, 25, "STOP", key)).accepted, true);
  h.endpoint->session_stopped();
  ASSERT_TRUE(h.wait_for(SessionState::idle));
  s.lcm.publish(s.channel, &start);
  for (int i = 0; i < 100 && s.sniffer.acks_for(24).size() < 2; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(s.sniffer.acks_for(24).size(), 2u);
  EXPECT_TRUE(s.sniffer.acks_for(24).back().accepted) << "the stored ack, sent again";
  EXPECT_EQ(h.endpoint->counters().commands_replayed.load(), 1u);
  EXPECT_EQ(h.endpoint->state(), SessionState::idle) << "a replayed START must not start a session";
  ASSERT_TRUE(s.send(signed_command(h, 26, "PING", key)).accepted);
  ASSERT_TRUE(s.send(signed_command(h, 27, "PING", key)).accepted);
  s.lcm.publish(s.channel, &start);
  for (int i = 0; i < 100 && s.sniffer.acks_for(24).size() < 3; ++i) std::this_thread::sleep_for(10ms);
  const auto acks = s.sniffer.acks_for(24);
  ASSERT_EQ(acks.size(), 3u);
  EXPECT_FALSE(acks.back().accepted);
  EXPECT_EQ(acks.back().reason, "replayed: this signed request id was executed before");
  EXPECT_EQ(h.starts, 1);
  EXPECT_EQ(h.endpoint->state(), SessionState::idle);

  const EndpointCounters& n = h.endpoint->counters();
  EXPECT_EQ(n.commands_bad_tag.load(), 1u);
  EXPECT_EQ(n.commands_stale.load(), 1u);
  EXPECT_EQ(n.commands_other_payload.load(), 1u);
  EXPECT_EQ(n.commands_replay_rejected.load(), 1u);
}

TEST(LcmEndpointAuth, SignedAcksArriveWithin100ms) {
  const KeyDir keys;
  const protocol::CommandKey key = protocol::CommandKey::generate();
  Harness h(0.0, keys.write("payload.key", key));
  Sender s(h);
  std::vector<double> ms;
  for (std::int64_t id = 300; id < 320; ++id) {
    const command_t c = signed_command(h, id, "PING", key);
    const auto sent = std::chrono::steady_clock::now();
    s.lcm.publish(s.channel, &c);
    while (s.sniffer.acks_for(id).empty() && std::chrono::steady_clock::now() - sent < 1s) std::this_thread::sleep_for(100us);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - sent).count());
    ASSERT_FALSE(s.sniffer.acks_for(id).empty());
    EXPECT_TRUE(s.sniffer.acks_for(id).back().accepted) << s.sniffer.acks_for(id).back().reason;
    EXPECT_LT(ms.back(), 100.0);
  }
  std::sort(ms.begin(), ms.end());
  double sum = 0;
  for (double v : ms) sum += v;
  std::printf("signed PING ack latency over %zu commands: mean %.2f ms, median %.2f ms, worst %.2f ms\n", ms.size(),
              sum / static_cast<double>(ms.size()), ms[ms.size() / 2], ms.back());
}

TEST(LcmEndpointAuth, KeyRotationWithoutRestartAndABadNewFileKeepsTheOldKey) {
  const KeyDir keys;
  const protocol::CommandKey first = protocol::CommandKey::generate();
  const protocol::CommandKey second = protocol::CommandKey::generate();
  const auto key_file = keys.write("payload.key", first);
  const auto first_file = keys.write("first.key", first);
  const auto second_file = keys.write("second.key", second);
  Harness h(0.0, key_file);
  EXPECT_EQ(h.adit({"ping", "--key", first_file.string()}).exit_status, 0);
  EXPECT_EQ(h.adit({"ping", "--key", second_file.string()}).exit_status, 1);

  keys.write("payload.key", second, true);  // written aside, renamed over: what an operator's tool does
  for (int i = 0; i < 50 && h.endpoint->counters().key_reloads.load() == 0; ++i) std::this_thread::sleep_for(20ms);
  EXPECT_EQ(h.endpoint->counters().key_reloads.load(), 1u);
  auto r = h.adit({"ping", "--key", first_file.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("bad tag"), std::string::npos) << r.err;
  EXPECT_EQ(h.adit({"ping", "--key", second_file.string()}).exit_status, 0);

  // A key file others may read is refused; the key in force stays.
  ASSERT_EQ(::chmod(key_file.c_str(), 0644), 0);
  for (int i = 0; i < 50 && h.endpoint->counters().key_reload_errors.load() == 0; ++i) std::this_thread::sleep_for(20ms);
  EXPECT_EQ(h.endpoint->counters().key_reload_errors.load(), 1u);
  EXPECT_EQ(h.adit({"ping", "--key", second_file.string()}).exit_status, 0);
  EXPECT_EQ(h.adit({"ping"}).exit_status, 1) << "still authenticated";
}

TEST(LcmEndpointAuth, BadKeyFilesAreRefusedAtStartAndByTheClient) {
  const KeyDir keys;
  const auto open_file = keys.write("open.key", protocol::CommandKey::generate());
  ASSERT_EQ(::chmod(open_file.c_str(), 0640), 0);
  try {
    Harness h(0.0, open_file);
    ADD_FAILURE() << "a group-readable key file was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), open_file.string());
    EXPECT_NE(e.reason().find("mode 0640"), std::string::npos) << e.reason();
  }
  EXPECT_THROW(Harness(0.0, keys.dir / "missing.key"), InputError);
  const auto garbage = keys.dir / "garbage.key";
  { std::ofstream(garbage) << "adit-command-key-v1 not-hex\n"; }
  ::chmod(garbage.c_str(), 0600);
  EXPECT_THROW(Harness(0.0, garbage), InputError);

  Harness h;  // no key: commands are not authenticated, as before keys existed
  EXPECT_FALSE(h.endpoint->counters().commands_authenticated.load());
  auto r = h.adit({"ping", "--key", open_file.string()});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find(open_file.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("chmod 600"), std::string::npos) << r.err;
  EXPECT_EQ(h.adit({"ping"}).exit_status, 0);
}

TEST(LcmEndpointAuth, KeygenWritesAKeyOnlyItsOwnerMayRead) {
  const KeyDir keys;
  const auto path = keys.dir / "new.key";
  auto r = test::run_program({(test::binary_dir() / "bin" / "adit").string(), "keygen", "--out", path.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("(mode 0600)"), std::string::npos) << r.out;
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  const auto key = protocol::read_key_file(path);
  EXPECT_NE(r.out.find(protocol::key_id_hex(key.at(0).id())), std::string::npos);
  r = test::run_program({(test::binary_dir() / "bin" / "adit").string(), "keygen", "--out", path.string()});
  EXPECT_EQ(r.exit_status, 2) << "an existing key is not overwritten";
  EXPECT_EQ(protocol::read_key_file(path).at(0).id(), key.at(0).id());
}

}  // namespace auth

}  // namespace
}  // namespace adit::daemon
