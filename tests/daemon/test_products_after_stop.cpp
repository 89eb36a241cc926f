// aditd's sessions with session.products on: STOP, then START at once. The
// second session starts while the first one's products are made on their
// own thread, the products appear (summary.json gains their figures), and
// the second session runs to its end and gets its own.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/config/load.hpp"
#include "adit/daemon/sessions.hpp"
#include "daemon_process.hpp"
#include "pipeline_run.hpp"
#include "sim_sessions.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

config::Config session_config(const std::filesystem::path& work, const std::string& extra) {
  return test::replay_config(test::mine_drive_12s(), work, extra);
}

// Polls until the replay ends, asks for the stop, polls until the files are written.
void run_to_end(Sessions& sessions) {
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (!sessions.poll() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(10ms);
  sessions.request_stop();
  while (sessions.running() && std::chrono::steady_clock::now() < deadline) {
    sessions.poll();
    std::this_thread::sleep_for(10ms);
  }
}

bool has_products(const std::filesystem::path& dir) {
  std::ifstream in(dir / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(in, nullptr, false);
  return !s.is_discarded() && s.contains("products") && std::filesystem::exists(dir / "products" / "top_view.png");
}

TEST(ProductsAfterStop, TheNextSessionStartsWhileTheyAreMade) {
  const std::filesystem::path work = test::binary_dir() / fmt::format("products-after-stop-{}", ::getpid());
  std::filesystem::remove_all(work);
  std::string first, second;
  {
    Sessions sessions(session_config(work, ""), {});
    first = sessions.start();
    run_to_end(sessions);
    ASSERT_TRUE(std::filesystem::exists(sessions.folder(first) / "summary.json"));
    // START at once: no "still being written" refusal while the products are made.
    const bool made_already = has_products(sessions.folder(first));
    ASSERT_NO_THROW(second = sessions.start());
    std::cout << "products of the first session " << (made_already ? "were" : "were not yet")
              << " made when the second started\n";
    // The first one's products appear while the second maps.
    const auto deadline = std::chrono::steady_clock::now() + 120s;
    while (!has_products(sessions.folder(first)) && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(50ms);
    EXPECT_TRUE(has_products(sessions.folder(first)));
    run_to_end(sessions);
    EXPECT_TRUE(std::filesystem::exists(sessions.folder(second) / "summary.json"));
  }  // the destructor waits for the second session's products if begun
  const std::filesystem::path dir1 = work / "state" / "sessions" / first;
  const nlohmann::json s1 = nlohmann::json::parse(std::ifstream(dir1 / "summary.json"));
  EXPECT_GT(s1["products"]["bytes"]["grid"].get<std::size_t>(), 0U);
  EXPECT_GT(s1["products"]["bytes"]["octree_bt"].get<std::size_t>(), 0U);
  for (const char* f : {"occupancy.bt", "grid.pgm", "grid.yaml", "top_view.png", "targets.csv", "products.json"})
    EXPECT_TRUE(std::filesystem::exists(dir1 / "products" / f)) << f;
  EXPECT_FALSE(std::filesystem::exists(dir1 / "products.partial"));
  const nlohmann::json s2 = nlohmann::json::parse(std::ifstream(work / "state" / "sessions" / second / "summary.json"));
  EXPECT_GT(s2["poses"]["total"].get<std::size_t>(), 100U);  // the second session mapped its 12 s
  std::filesystem::remove_all(work);
}

TEST(ProductsAfterStop, TheConfigTurnsThemOff) {
  const std::filesystem::path work = test::binary_dir() / fmt::format("products-off-{}", ::getpid());
  std::filesystem::remove_all(work);
  std::string id;
  {
    Sessions sessions(session_config(work, "session:\n  products: false\n"), {});
    id = sessions.start();
    run_to_end(sessions);
  }
  const std::filesystem::path dir = work / "state" / "sessions" / id;
  EXPECT_TRUE(std::filesystem::exists(dir / "summary.json"));
  EXPECT_FALSE(std::filesystem::exists(dir / "products"));
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace adit::daemon
