#pragma once
// aditd's whole pipeline on a simulated session's recordings (the config
// edited, e.g. a faulty copy of one recording), and its trajectory scored
// against the simulator's truth with `adit eval traj`.

#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/config/load.hpp"
#include "adit/daemon/pipeline.hpp"
#include "daemon_process.hpp"
#include "run_program.hpp"

namespace adit::test {

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
