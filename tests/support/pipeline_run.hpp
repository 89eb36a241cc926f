#pragma once
// aditd's whole pipeline on a simulated session's recordings (the config
// edited, e.g. a faulty copy of one recording), and its trajectory scored
// against the simulator's truth with `adit eval traj`.

#include <filesystem>
#include <fstream>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/common/clock.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/pipeline.hpp"
#include "daemon_process.hpp"
#include "run_program.hpp"

namespace adit::test {

// A pipeline for a live-input test: odometry without mapping, not started.
inline std::unique_ptr<daemon::Pipeline> live_pipeline(const std::string& yaml) {
  daemon::PipelineOptions options;
  options.mapping = false;
  return std::make_unique<daemon::Pipeline>(config::parse_config(yaml, "test.yaml", "/"), options);
}

// Starts a live pipeline and returns once its receiver reads: the receiver
// first drains what its sockets held before the session (as stale), so a
// test sends only when the receiver's heartbeat beats after the start.
inline bool start_and_wait_for_receiver(daemon::Pipeline& pipeline) {
  const std::int64_t started_ns = monotonic_ns();
  pipeline.start();
  const auto receiving = [&] {
    for (const daemon::Heartbeat* h : pipeline.heartbeats())
      if (h->name == "receiver") return h->last_ns.load() > started_ns;
    return false;
  };
  for (int i = 0; i < 1000 && !receiving(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  return receiving();
}

struct ScoredRun {
  std::unique_ptr<daemon::Pipeline> pipeline;  // joined: its stats are final
  double ape_rmse_m = 1e9;
  double ape_max_m = 1e9;
};

// aditd's configuration replaying a simulated session as fast as it goes
// (`--once`-like), its state under work/state; `extra` YAML appended.
inline config::Config replay_config(const std::filesystem::path& session, const std::filesystem::path& work,
                                    const std::string& extra = "") {
  std::filesystem::create_directories(work);
  const std::filesystem::path file = work / "aditd.yaml";
  std::ofstream(file) << aditd_yaml_for(session, work / "state", {"", "", true, "threads:\n  lock_memory: false\n" + extra});
  return config::load_config(file);
}

inline ScoredRun run_and_score(const std::filesystem::path& session, const std::filesystem::path& work,
                               const std::function<void(config::Config&)>& edit) {
  config::Config c = replay_config(session, work);
  edit(c);
  daemon::PipelineOptions options;
  options.trajectory_file = work / "trajectory.tum";
  ScoredRun run;
  run.pipeline = std::make_unique<daemon::Pipeline>(c, options);
  run.pipeline->start();
  run.pipeline->join();
  const CommandRun eval = run_adit(fmt::format("eval traj --ref {} --est {} --json", (session / "truth_body.tum").string(),
                                               (work / "trajectory.tum").string()));
  EXPECT_EQ(eval.status, 0) << eval.output;
  const nlohmann::json j = nlohmann::json::parse(eval.output.substr(eval.output.find('{')), nullptr, false);
  if (j.is_object()) {
    run.ape_rmse_m = j["ape"]["translation_m"]["rmse"].get<double>();
    run.ape_max_m = j["ape"]["translation_m"]["max"].get<double>();
  }
  return run;
}

}  // namespace adit::test
