// adit console's live 2D grid end to end: the daemon's LCM endpoint sends
// grid patches (as aditd's mapping thread does) over real LCM on loopback,
// `adit console` runs as a child process, and the test reads what a browser
// reads: GET /api/grid (a PNG and where it lies), its blocks
// (GET /api/grid/blocks, /api/grid/block/X/Y), the snapshot and the event
// stream. The PNG is decoded here with libpng's own reader, independently of
// the console's encoder, and compared cell for cell with what was sent. The
// session's frame (frame_t), the pose graph's path (graph_path_t) and the
// loop closure's progress (loop_status_t) travel the same way to the page's
// snapshot and events.
#include <gtest/gtest.h>

#include <httplib.h>
#include <png.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <future>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/daemon/lcm_endpoint.hpp"
#include "adit/slam/correction_track.hpp"
#include "daemon_process.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"
#include "temp_file.hpp"

namespace adit {
namespace {

using namespace std::chrono_literals;
constexpr int kCells = 32;  // cells per patch side
constexpr float kResolution = 0.1F;

// A patch with a diagonal wall, free cells below it, one free cell that tells
// the patches (and the grid's rows and columns) apart, and unknown elsewhere
// (the protocol's values: -1, 0 and 100 only).
std::vector<std::int8_t> patch_cells(int x, int y) {
  std::vector<std::int8_t> cells(kCells * kCells, -1);
  for (int row = 0; row < kCells; ++row)
    for (int col = 0; col < kCells; ++col) {
      if (col == row) cells[static_cast<std::size_t>(row * kCells + col)] = 100;
      if (col < row && col > row - 6) cells[static_cast<std::size_t>(row * kCells + col)] = 0;
    }
  cells[static_cast<std::size_t>((x + 4) * kCells + (y + 20))] = 0;  // row x + 4, column y + 20 (unknown else): a mark
  return cells;
}

// A payload's LCM endpoint and `adit console` following it.
struct Harness {
  std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + (::getpid() + 17) % 30000);
  std::string payload = fmt::format("console-grid-{}", ::getpid());
  int port = 30000 + ::getpid() % 10000;
  test::TempFolder folder;
  std::unique_ptr<daemon::LcmEndpoint> endpoint;
  std::unique_ptr<test::Daemon> console;
  int sessions = 0;

  Harness() {
    daemon::EndpointOptions o;
    o.lcm_url = url;
    o.payload_id = payload;
    o.grid_period_s = 0.2;
    o.grid_refresh_s = 2.0;
    daemon::SessionHooks hooks;
    hooks.start = [this] { return fmt::format("s{}", ++sessions); };
    hooks.stop = [] {};
    endpoint = std::make_unique<daemon::LcmEndpoint>(o, hooks);
    std::filesystem::create_directories(folder.path() / "web");
    const auto adit = (test::binary_dir() / "bin" / "adit").string();
    console = std::make_unique<test::Daemon>(
        std::vector<std::string>{adit, "console", "--payload", payload, "--lcm-url", url, "--listen",
                                 fmt::format("127.0.0.1:{}", port), "--data-dir", (folder.path() / "data").string(),
                                 "--web-dir", (folder.path() / "web").string(), "--three-dir",
                                 (folder.path() / "web").string()},
        folder.path() / "console.log");
  }

  httplib::Client http() const {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(5, 0);
    return c;
  }

  bool console_listens() const {
    for (int i = 0; i < 100; ++i) {
      if (auto r = http().Get("/api/config"); r && r->status == 200) return true;
      std::this_thread::sleep_for(100ms);
    }
    return false;
  }

  test::ProgramResult adit(const std::string& verb) const {
    return test::run_program({(test::binary_dir() / "bin" / "adit").string(), verb, "--payload", payload,
                              "--lcm-url", url, "--timeout", "5"});
  }

  void publish(int x, int y, int version, std::vector<std::int8_t> cells) const {
    ASSERT_TRUE(endpoint->publish_grid(
        daemon::GridPatchUpdate{1, x, y, version, 6, kResolution, kCells, std::move(cells)}));
  }

  // GET /api/grid once it answers with `patches` patches at `version` or more.
  httplib::Result grid_when(std::size_t patches, std::int64_t version) const {
    for (int i = 0; i < 100; ++i) {
      auto r = http().Get("/api/grid");
      if (r && r->status == 200 && std::stoul(r->get_header_value("X-Grid-Patches")) == patches &&
          std::stoll(r->get_header_value("X-Grid-Version")) >= version)
        return r;
      std::this_thread::sleep_for(100ms);
    }
    return http().Get("/api/grid");
  }

  nlohmann::json state() const {
    const auto r = http().Get("/api/state");
    return r && r->status == 200 ? nlohmann::json::parse(r->body) : nlohmann::json();
  }
};

// libpng's reader on the console's PNG: the cells in grid order (row 0 the
// lowest y, as grid_patch_t), by the mapping docs/CONSOLE.md gives.
struct Decoded {
  int width = 0, height = 0;
  std::vector<std::int8_t> cells;
  std::string error;
  std::int8_t at(int col, int row) const { return cells[static_cast<std::size_t>(row * width + col)]; }
};

Decoded decode(const std::string& png) {
  Decoded out;
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_memory(&image, png.data(), png.size()) == 0) {
    out.error = image.message;
    return out;
  }
  image.format = PNG_FORMAT_GA;
  std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr) == 0) {
    out.error = image.message;
    return out;
  }
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.cells.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height));
  for (int row = 0; row < out.height; ++row)
    for (int col = 0; col < out.width; ++col) {
      // The image's top row is the grid's last (the highest y).
      const std::size_t p = 2 * (static_cast<std::size_t>(out.height - 1 - row) * out.width + col);
      out.cells[static_cast<std::size_t>(row * out.width + col)] =
          pixels[p + 1] == 0 ? std::int8_t{-1} : static_cast<std::int8_t>(std::lround((255 - pixels[p]) / 2.55));
    }
  return out;
}

// The patches (x -1..1, y 0..1) as the grid's cells, for the comparison.
void expect_cells(const Decoded& grid, int x, int y, const std::vector<std::int8_t>& cells) {
  const int col0 = (x + 1) * kCells, row0 = y * kCells;
  int wrong = 0;
  for (int row = 0; row < kCells; ++row)
    for (int col = 0; col < kCells; ++col) {
      const int served = grid.at(col0 + col, row0 + row);
      const int sent = cells[static_cast<std::size_t>(row * kCells + col)];
      if (served != sent && ++wrong <= 3)
        ADD_FAILURE() << fmt::format("patch ({}, {}) cell (col {}, row {}): {} served, {} sent", x, y, col, row, served,
                                     sent);
    }
  EXPECT_EQ(wrong, 0) << "patch (" << x << ", " << y << ")";
}

// Every block the console lists, decoded, holds the whole grid's cells where
// they overlap and unknown elsewhere; the blocks' versions as listed.
void expect_blocks_match(const Harness& h, const Decoded& whole, double origin_x, double origin_y,
                         const nlohmann::json& versions) {
  const auto r = h.http().Get("/api/grid/blocks");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200);
  const nlohmann::json index = nlohmann::json::parse(r->body);
  ASSERT_EQ(index["block_cells"], 1024) << "32 patches of 32 cells";
  EXPECT_NEAR(index["origin_x"].get<double>(), origin_x, 1e-6);
  EXPECT_NEAR(index["origin_y"].get<double>(), origin_y, 1e-6);
  EXPECT_EQ(index["width"], whole.width);
  EXPECT_EQ(index["height"], whole.height);
  ASSERT_EQ(index["blocks"], versions) << index.dump();
  for (const nlohmann::json& b : index["blocks"]) {
    const int bx = b[0], by = b[1];
    const auto block = h.http().Get(fmt::format("/api/grid/block/{}/{}", bx, by));
    ASSERT_TRUE(block);
    ASSERT_EQ(block->status, 200);
    EXPECT_EQ(block->get_header_value("X-Grid-Version"), std::to_string(b[2].get<int>()));
    const double bx0 = std::stod(block->get_header_value("X-Grid-Origin-X"));
    const double by0 = std::stod(block->get_header_value("X-Grid-Origin-Y"));
    // Cut to its patches: at most 1024 cells a side, within its block.
    const Decoded cells = decode(block->body);
    ASSERT_EQ(cells.error, "");
    EXPECT_GE(bx0, bx * 1024 * kResolution - 1e-3);
    EXPECT_GE(by0, by * 1024 * kResolution - 1e-3);
    EXPECT_LE(bx0 + cells.width * kResolution, (bx + 1) * 1024 * kResolution + 1e-3);
    EXPECT_LE(by0 + cells.height * kResolution, (by + 1) * 1024 * kResolution + 1e-3);
    EXPECT_EQ(cells.width % kCells, 0);
    EXPECT_EQ(cells.height % kCells, 0);
    const int col0 = static_cast<int>(std::lround((bx0 - origin_x) / kResolution));
    const int row0 = static_cast<int>(std::lround((by0 - origin_y) / kResolution));
    int wrong = 0;
    for (int row = 0; row < cells.height; ++row)
      for (int col = 0; col < cells.width; ++col) {
        const int c = col0 + col, rr = row0 + row;
        const bool inside = c >= 0 && rr >= 0 && c < whole.width && rr < whole.height;
        if (cells.at(col, row) != (inside ? whole.at(c, rr) : -1)) ++wrong;
      }
    EXPECT_EQ(wrong, 0) << "block (" << bx << ", " << by << ")";
  }
}

// A browser's event stream until an event named `name` whose data holds `text` (or 8 s).
std::string wait_for_event(const Harness& h, const std::string& name, const std::string& text) {
  std::string seen;
  const auto start = std::chrono::steady_clock::now();
  h.http().Get("/api/events", [&](const char* data, std::size_t length) {
    seen.append(data, length);
    for (std::size_t at = seen.find("event: " + name + "\n"); at != std::string::npos;
         at = seen.find("event: " + name + "\n", at + 1)) {
      const std::size_t end = seen.find("\n\n", at);
      if (end != std::string::npos && seen.substr(at, end - at).find(text) != std::string::npos) return false;
    }
    return std::chrono::steady_clock::now() - start < 8s;
  });
  return seen;
}

TEST(ConsoleGrid, ThePayloadsGridIsServedAtApiGridCellForCellAndEachChangeIsAnnounced) {
  Harness h;
  ASSERT_TRUE(h.console_listens()) << "adit console did not listen on " << h.port;
  ASSERT_EQ(h.adit("start").exit_status, 0);
  {
    const auto none = h.http().Get("/api/grid");
    ASSERT_TRUE(none);
    EXPECT_EQ(none->status, 204) << "no patch yet: no grid";
  }
  for (int x = -1; x <= 1; ++x)
    for (int y = 0; y <= 1; ++y) h.publish(x, y, 1, patch_cells(x, y));

  const auto r = h.grid_when(6, 6);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(r->get_header_value("X-Grid-Session"), "s1");
  EXPECT_EQ(r->get_header_value("X-Grid-Patches"), "6");
  EXPECT_EQ(r->get_header_value("X-Grid-Version"), "6") << "the sum of the patches' versions";
  EXPECT_NEAR(std::stod(r->get_header_value("X-Grid-Resolution")), 0.1, 1e-9);
  EXPECT_NEAR(std::stod(r->get_header_value("X-Grid-Origin-X")), -3.2, 1e-6);  // patch x -1: -1 · 32 · 0.1 m
  EXPECT_NEAR(std::stod(r->get_header_value("X-Grid-Origin-Y")), 0.0, 1e-9);
  EXPECT_EQ(r->get_header_value("X-Grid-Width"), "96");
  EXPECT_EQ(r->get_header_value("X-Grid-Height"), "64");
  const Decoded grid = decode(r->body);
  ASSERT_EQ(grid.error, "");
  ASSERT_EQ(grid.width, 3 * kCells);
  ASSERT_EQ(grid.height, 2 * kCells);
  for (int x = -1; x <= 1; ++x)
    for (int y = 0; y <= 1; ++y) expect_cells(grid, x, y, patch_cells(x, y));
  EXPECT_LT(r->body.size(), 2000U) << "compressed: " << 96 * 64 << " cells";
  // In blocks, as the page fetches it: patch x -1 in block -1, x 0 and 1 in block 0.
  expect_blocks_match(h, grid, -3.2, 0.0, nlohmann::json::parse("[[-1, 0, 2], [0, 0, 4]]"));
  {
    const auto none = h.http().Get("/api/grid/block/5/5");
    ASSERT_TRUE(none);
    EXPECT_EQ(none->status, 204) << "no such block";
    const auto bad = h.http().Get("/api/grid/block/99999999999/0");
    ASSERT_TRUE(bad);
    EXPECT_EQ(bad->status, 400);
  }

  // The snapshot names the grid's version; a patch that changes is announced
  // on the event stream and served at the new version.
  EXPECT_EQ(h.state()["grid"], (nlohmann::json{{"v", 6}, {"patches", 6}}));
  std::vector<std::int8_t> changed = patch_cells(0, 1);
  for (int col = 0; col < kCells; ++col) changed[static_cast<std::size_t>(10 * kCells + col)] = 100;  // a wall across
  std::thread later([&] {
    std::this_thread::sleep_for(300ms);  // once the stream below is open
    h.publish(0, 1, 3, changed);
  });
  const std::string events = wait_for_event(h, "grid", R"("v":8)");
  later.join();
  EXPECT_NE(events.find(R"("session":"s1","v":8)"), std::string::npos) << events;
  const auto r2 = h.grid_when(6, 8);
  ASSERT_TRUE(r2);
  EXPECT_EQ(r2->get_header_value("X-Grid-Version"), "8");
  const Decoded grid2 = decode(r2->body);
  ASSERT_EQ(grid2.width, 3 * kCells);
  expect_cells(grid2, 0, 1, changed);
  expect_cells(grid2, 1, 1, patch_cells(1, 1));
  // Only block 0's version moved.
  expect_blocks_match(h, grid2, -3.2, 0.0, nlohmann::json::parse("[[-1, 0, 2], [0, 0, 6]]"));
  EXPECT_EQ(h.console->stop(), 0);
}

TEST(ConsoleGrid, ANewSessionStartsAnEmptyGrid) {
  Harness h;
  ASSERT_TRUE(h.console_listens()) << "adit console did not listen on " << h.port;
  ASSERT_EQ(h.adit("start").exit_status, 0);
  h.publish(0, 0, 1, patch_cells(0, 0));
  const auto first = h.grid_when(1, 1);
  ASSERT_TRUE(first);
  ASSERT_EQ(first->status, 200);
  EXPECT_EQ(first->get_header_value("X-Grid-Session"), "s1");

  ASSERT_EQ(h.adit("stop").exit_status, 0);
  h.endpoint->session_stopped();
  ASSERT_EQ(h.adit("start").exit_status, 0);
  h.endpoint->publish_status(daemon::StatusSample{});  // the payload's status names session s2
  for (int i = 0; i < 50 && h.state()["session"] != "s2"; ++i) std::this_thread::sleep_for(100ms);
  ASSERT_EQ(h.state()["session"], "s2");
  EXPECT_TRUE(h.state()["grid"].is_null()) << "s1's grid is not shown for s2";
  const auto none = h.http().Get("/api/grid");
  ASSERT_TRUE(none);
  EXPECT_EQ(none->status, 204);
  const auto no_blocks = h.http().Get("/api/grid/blocks");
  ASSERT_TRUE(no_blocks);
  EXPECT_EQ(no_blocks->status, 204);
  const auto old_block = h.http().Get("/api/grid/block/0/0");
  ASSERT_TRUE(old_block);
  EXPECT_EQ(old_block->status, 204) << "s1's block is not served for s2";

  h.publish(2, -1, 4, patch_cells(2, -1));
  const auto r = h.grid_when(1, 4);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("X-Grid-Session"), "s2");
  EXPECT_EQ(r->get_header_value("X-Grid-Version"), "4");
  EXPECT_NEAR(std::stod(r->get_header_value("X-Grid-Origin-X")), 6.4, 1e-6);
  EXPECT_NEAR(std::stod(r->get_header_value("X-Grid-Origin-Y")), -3.2, 1e-6);
  EXPECT_EQ(decode(r->body).width, kCells);
}

// The session's frame (frame_t, sent with each status) reaches the page's
// snapshot: identity until the payload anchors to its prior map, then the anchor;
// a new session starts in its own odometry frame again.
TEST(ConsoleFrame, TheSessionsFrameReachesThePageAndANewSessionForgetsIt) {
  Harness h;
  ASSERT_TRUE(h.console_listens()) << "adit console did not listen on " << h.port;
  ASSERT_EQ(h.adit("start").exit_status, 0);
  h.endpoint->publish_status(daemon::StatusSample{});
  for (int i = 0; i < 50 && h.state()["frame"].is_null(); ++i) std::this_thread::sleep_for(100ms);
  ASSERT_EQ(h.state()["frame"]["source"], "odometry") << h.state().dump();
  daemon::StatusSample anchored;
  anchored.frame = daemon::MapFrame{1, {100.0, 50.0, -2.0}, {0.0, 0.0, 0.0, 1.0}};  // a half turn about z
  h.endpoint->publish_status(std::move(anchored));
  for (int i = 0; i < 50 && h.state()["frame"]["source"] != "prior_map"; ++i) std::this_thread::sleep_for(100ms);
  const nlohmann::json frame = h.state()["frame"];
  ASSERT_EQ(frame["source"], "prior_map") << frame.dump();
  EXPECT_EQ(frame["session"], "s1");
  EXPECT_EQ(frame["p"], nlohmann::json::array({100.0, 50.0, -2.0}));
  EXPECT_EQ(frame["q"], nlohmann::json::array({0.0, 0.0, 0.0, 1.0}));

  ASSERT_EQ(h.adit("stop").exit_status, 0);
  h.endpoint->session_stopped();
  ASSERT_EQ(h.adit("start").exit_status, 0);
  h.endpoint->publish_status(daemon::StatusSample{});  // s2, not anchored
  for (int i = 0; i < 50 && h.state()["frame"]["session"] != "s2"; ++i) std::this_thread::sleep_for(100ms);
  EXPECT_EQ(h.state()["frame"]["session"], "s2");
  EXPECT_EQ(h.state()["frame"]["source"], "odometry");
}

// A loop closed: the graph's path (its keyframes where the graph put them)
// reaches the page, and the poses' path kept for it starts at the graph's
// newest keyframe; the same graph again (its resend) is not news, a new one is.
TEST(ConsoleGraphPath, TheGraphsPathReplacesThePosesPathUpToItsNewestKeyframe) {
  Harness h;
  ASSERT_TRUE(h.console_listens()) << "adit console did not listen on " << h.port;
  ASSERT_EQ(h.adit("start").exit_status, 0);
  h.endpoint->publish_status(daemon::StatusSample{});
  for (int k = 0; k <= 20; ++k) {  // 1 s to 3 s, 0.2 m apart along x
    daemon::PoseSample p;
    p.utime = 1'000'000 + k * 100'000;
    p.position = {0.2 * k, 0.0, 0.0};
    p.flags = 1;  // pose_t.FLAG_VALID
    ASSERT_TRUE(h.endpoint->publish_pose(p));
  }
  for (int i = 0; i < 50 && h.state()["path"].size() < 21; ++i) std::this_thread::sleep_for(100ms);
  ASSERT_EQ(h.state()["path"].size(), 21U) << h.state()["path"].dump();
  EXPECT_TRUE(h.state()["graph_path"].is_null());

  // The keyframes at 1.0 .. 2.0 s, bent by the graph toward +y by `bend` per metre.
  const auto graph = [](double bend) {
    std::vector<std::int64_t> stamps;
    std::vector<Eigen::Isometry3d> placed, odometry;
    for (int k = 0; k <= 10; ++k) {
      stamps.push_back(1'000'000'000 + k * 100'000'000);
      Eigen::Isometry3d o = Eigen::Isometry3d::Identity(), g = Eigen::Isometry3d::Identity();
      o.translation() = Eigen::Vector3d(0.2 * k, 0, 0);
      g.translation() = Eigen::Vector3d(0.2 * k, bend * 0.2 * k, 0);
      odometry.push_back(o);
      placed.push_back(g);
    }
    return std::make_shared<const slam::CorrectionTrack>(stamps, placed, odometry);
  };
  const auto first = graph(0.1);
  daemon::StatusSample closed;
  closed.graph = first;
  h.endpoint->publish_status(std::move(closed));
  for (int i = 0; i < 50 && h.state()["graph_path"].is_null(); ++i) std::this_thread::sleep_for(100ms);
  const nlohmann::json g = h.state()["graph_path"];
  ASSERT_FALSE(g.is_null());
  EXPECT_EQ(g["session"], "s1");
  EXPECT_EQ(g["rev"], 1);
  EXPECT_EQ(g["utime"], 2'000'000);
  EXPECT_EQ(g["n_keyframes"], 11);
  ASSERT_EQ(g["points"].size(), 11U);
  EXPECT_NEAR(g["points"][10][0].get<double>(), 2.0, 1e-3);
  EXPECT_NEAR(g["points"][10][1].get<double>(), 0.2, 1e-3);  // where the graph put it, not the odometry (0)
  const nlohmann::json path = h.state()["path"];
  ASSERT_EQ(path.size(), 11U) << path.dump();  // 2.0 .. 3.0 s: from the graph's newest keyframe on
  for (const auto& p : path) EXPECT_GE(p[3].get<std::int64_t>(), 2'000'000) << p.dump();

  daemon::StatusSample again;  // the same graph (the 2 Hz status): not a new revision
  again.graph = first;
  h.endpoint->publish_status(std::move(again));
  auto announced = std::async(std::launch::async, [&] { return wait_for_event(h, "graph_path", "\"rev\":2"); });
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(h.state()["graph_path"]["rev"], 1);
  daemon::StatusSample moved;
  moved.graph = graph(0.2);
  h.endpoint->publish_status(std::move(moved));
  const std::string seen = announced.get();
  EXPECT_NE(seen.find("\"rev\":2"), std::string::npos) << seen.substr(0, 2000);
  EXPECT_NEAR(h.state()["graph_path"]["points"][10][1].get<double>(), 0.4, 1e-3);
}

// The session's loop closure (loop_status_t, sent just before each status)
// reaches the page inside the status, as "loops"; a status without it has none.
TEST(ConsoleLoops, TheStatusCarriesTheSessionsLoopClosure) {
  Harness h;
  ASSERT_TRUE(h.console_listens()) << "adit console did not listen on " << h.port;
  ASSERT_EQ(h.adit("start").exit_status, 0);
  h.endpoint->publish_status(daemon::StatusSample{});
  for (int i = 0; i < 50 && h.state()["status"].is_null(); ++i) std::this_thread::sleep_for(100ms);
  ASSERT_FALSE(h.state()["status"].is_null());
  EXPECT_FALSE(h.state()["status"].contains("loops")) << h.state()["status"].dump();

  daemon::StatusSample with_loops;
  daemon::LoopStatus loops;
  loops.keyframes = 31;
  loops.candidates = 4;
  loops.accepted = 2;
  loops.rejected = 1;
  loops.last_loop_utime = 1'700'000'000'000'000;
  loops.correction_m = 0.5F;
  loops.correction_deg = 1.5F;
  loops.moves_map = true;
  with_loops.loops = loops;
  h.endpoint->publish_status(std::move(with_loops));
  for (int i = 0; i < 50 && !h.state()["status"].contains("loops"); ++i) std::this_thread::sleep_for(100ms);
  const nlohmann::json l = h.state()["status"]["loops"];
  ASSERT_FALSE(l.is_null()) << h.state()["status"].dump();
  EXPECT_EQ(l["session"], "s1");
  EXPECT_EQ(l["keyframes"], 31);
  EXPECT_EQ(l["candidates"], 4);
  EXPECT_EQ(l["accepted"], 2);
  EXPECT_EQ(l["rejected"], 1);
  EXPECT_EQ(l["last_loop_us"], 1'700'000'000'000'000);
  EXPECT_DOUBLE_EQ(l["correction_m"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(l["correction_deg"].get<double>(), 1.5);
  EXPECT_EQ(l["moves_map"], true);
}

}  // namespace
}  // namespace adit
