// The products thread of aditd (products_worker.hpp): sessions made in the
// background in order, a stale products.partial replaced, a kill -9 at any
// moment leaves the session's own files whole, and stop() with sessions
// queued returns without making them.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/daemon/products_worker.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/slam/tum.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

// A session folder as aditd leaves it: a 3 m wide corridor along x with a
// bright target on a wall, the map's poses and a summary.json.
std::filesystem::path corridor_session(const std::string& name) {
  const auto dir = test::binary_dir() / ("products-worker-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  slam::Trajectory poses;
  for (int k = 0; k <= 20; ++k) {
    slam::Pose p = slam::Pose::Identity();
    p.translation() = Eigen::Vector3d(0.5 * k, 0.0, 0.0);
    poses.push_back(1000.0 + 0.5 * k, p);
  }
  slam::write_tum(dir / "map_trajectory.tum", poses);
  std::vector<protocol::MapPoint> points;
  for (double x = -1.99; x <= 12.0; x += 0.05) {
    for (double z = -0.5; z <= 2.0; z += 0.05)
      for (double y : {-1.5, 1.5}) {
        const bool target = y > 0 && std::abs(x - 5.0) < 0.15 && std::abs(z - 1.0) < 0.15;
        points.push_back({x, y, z, target ? 230.0F : 20.0F, 1005.0});
      }
    for (double y = -1.46; y < 1.5; y += 0.05) points.push_back({x, y, -0.5, 20.0F, 1005.0});
  }
  protocol::write_map(dir / "map.las", protocol::MapFormat::las, points);
  std::ofstream(dir / "summary.json") << R"({"id": "test", "map": {"points": 1}})";
  return dir;
}

std::string contents(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ProductsWorker, MakesQueuedSessionsInTheBackground) {
  const auto a = corridor_session("a");
  const auto b = corridor_session("b");
  std::filesystem::create_directories(b / "products.partial");  // a run cut short earlier
  std::ofstream(b / "products.partial" / "junk") << "x";
  ProductsWorker worker;
  worker.enqueue(a);
  worker.enqueue(b);
  worker.wait_idle();
  EXPECT_EQ(worker.made(), 2U);
  EXPECT_EQ(worker.failed(), 0U);
  for (const auto& dir : {a, b}) {
    EXPECT_FALSE(std::filesystem::exists(dir / "products.partial")) << dir;
    for (const char* f : {"occupancy.bt", "grid.pgm", "grid.yaml", "top_view.png", "targets.csv", "products.json"})
      EXPECT_TRUE(std::filesystem::exists(dir / "products" / f)) << dir << " " << f;
    const nlohmann::json summary = nlohmann::json::parse(contents(dir / "summary.json"));
    EXPECT_EQ(summary["id"], "test");
    EXPECT_EQ(summary["products"]["targets"]["found"], 1);
    EXPECT_GT(summary["products"]["bytes"]["grid"].get<std::size_t>(), 0U);
  }
  EXPECT_FALSE(std::filesystem::exists(b / "products" / "junk"));
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}

TEST(ProductsWorker, AFailedSessionIsCountedAndTheNextIsMade) {
  const auto bad = corridor_session("bad");
  std::filesystem::remove(bad / "map.las");
  const auto good = corridor_session("good");
  ProductsWorker worker;
  worker.enqueue(bad);
  worker.enqueue(good);
  worker.wait_idle();
  EXPECT_EQ(worker.failed(), 1U);
  EXPECT_EQ(worker.made(), 1U);
  EXPECT_FALSE(std::filesystem::exists(bad / "products.partial"));
  EXPECT_FALSE(std::filesystem::exists(bad / "products"));
  std::filesystem::remove_all(bad);
  std::filesystem::remove_all(good);
}

TEST(ProductsWorker, StopCancelsTheOneBegunAndDropsTheRest) {
  std::vector<std::filesystem::path> dirs;
  for (int i = 0; i < 6; ++i) dirs.push_back(corridor_session("stop" + std::to_string(i)));
  {
    ProductsWorker worker;
    for (const auto& d : dirs) worker.enqueue(d);
    std::this_thread::sleep_for(30ms);  // the first is begun
    worker.stop();  // it is cancelled (or done, on a fast machine); the others are dropped
    EXPECT_LE(worker.made() + worker.cancelled(), 1U);
    EXPECT_EQ(worker.failed(), 0U);
    worker.enqueue(dirs[0]);  // after stop: ignored, never waits
  }
  for (const auto& d : dirs) {
    EXPECT_FALSE(std::filesystem::exists(d / "products.partial")) << d;
    EXPECT_FALSE(nlohmann::json::parse(contents(d / "summary.json"), nullptr, false).is_discarded());
    std::filesystem::remove_all(d);
  }
}

// kill -9 of a process making products, at several moments: the session's
// map, trajectory and summary are as they were (or the summary has gained
// "products" whole), and the next run makes the products.
TEST(ProductsWorker, AKillDuringProductsLeavesTheSessionWhole) {
#if defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "fork() of a process that has run threads: not under ThreadSanitizer";
#endif
  for (const int after_ms : {0, 5, 20, 60, 150}) {
    const auto dir = corridor_session("kill");
    const std::string map_before = contents(dir / "map.las");
    const std::string path_before = contents(dir / "map_trajectory.tum");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ProductsWorker worker;
      worker.enqueue(dir);
      worker.wait_idle();
      ::_exit(0);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_EQ(contents(dir / "map.las"), map_before) << after_ms;
    EXPECT_EQ(contents(dir / "map_trajectory.tum"), path_before) << after_ms;
    const nlohmann::json summary = nlohmann::json::parse(contents(dir / "summary.json"), nullptr, false);
    ASSERT_FALSE(summary.is_discarded()) << after_ms;
    EXPECT_EQ(summary["id"], "test");
    ProductsWorker again;
    again.enqueue(dir);
    again.wait_idle();
    EXPECT_EQ(again.made(), 1U) << after_ms;
    EXPECT_TRUE(std::filesystem::exists(dir / "products" / "top_view.png")) << after_ms;
    EXPECT_FALSE(std::filesystem::exists(dir / "products.partial")) << after_ms;
    std::filesystem::remove_all(dir);
  }
}

}  // namespace
}  // namespace adit::daemon
