// adit replay: aditd's packet-to-pose pipeline on a capture or a directory of
// scans, as fast as possible or at a chosen pace; writes the trajectory and
// prints the pipeline's figures (counters, odometry time, latency, memory).

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/daemon/allocator.hpp"
#include "adit/daemon/pipeline.hpp"
#include "commands.hpp"
#include "pipeline_run.hpp"
#include "replay_session.hpp"
#include "temporary_folder.hpp"

namespace adit::tools {
namespace {

struct ReplayOptions {
  PipelineInputs inputs;
  std::string out;
  bool realtime = false;
  double speed = 0.0;  // × real time; 0 = as fast as possible
  bool json = false;
  double memory_from = 0.1;
  std::string session_dir;  // empty: a temporary folder, removed at the end
  std::string memory_csv;   // empty: none
  std::string session;      // a stored session to map again (replay_session.hpp)
  std::string out_dir;      // where its new session goes
};

const std::string& source_of(const config::Config& c) {
  return c.lidar.source == config::LidarSource::scan_dir ? c.lidar.scan_dir : c.lidar.pcap;
}

int replay(const ReplayOptions& o) {
  if (!o.session.empty())
    return replay_session(o.session, o.out_dir.empty() ? std::filesystem::path(o.session) / "replayed" : std::filesystem::path(o.out_dir));
  const config::Config config = load_pipeline_config(o.inputs);
  if (config.lidar.source == config::LidarSource::scan_dir && (o.realtime || o.speed > 0.0))
    throw InputError(config.lidar.scan_dir, o.realtime ? "--realtime" : "--speed",
                     "a scan directory is replayed as fast as possible (the pipeline does not pace it)");
  daemon::keep_large_blocks_mmapped();  // as aditd does, so the memory figures are aditd's
  daemon::PipelineOptions options;
  // Absolute: the pipeline creates the file's folder, and a bare name has none.
  if (!o.out.empty()) options.trajectory_file = std::filesystem::absolute(o.out);
  options.replay_speed = o.realtime ? 1.0 : o.speed;
  daemon::Pipeline pipeline(config, options);
  std::optional<TemporaryFolder> temporary;
  if (o.session_dir.empty()) temporary.emplace("adit-replay-tiles-");
  const std::filesystem::path dir = temporary ? temporary->path() : std::filesystem::absolute(o.session_dir);
  daemon::SessionFiles files;
  files.tiles_dir = dir / "tiles";
  files.keyframes_dir = dir / "keyframes";
  const PipelineFigures figures = run_pipeline(pipeline, {}, files);
  for (const std::string& warning : pipeline.warnings()) fmt::print(stderr, "adit replay: {}\n", warning);
  if (!o.memory_csv.empty()) {
    std::ofstream csv(o.memory_csv);
    csv << "poses,resident_mb,heap_in_use_mb,map_mb\n";
    for (const MemorySample& m : figures.memory)
      csv << fmt::format("{},{:.2f},{},{:.2f}\n", m.poses, m.resident_mb, m.heap_mb < 0 ? "" : fmt::format("{:.2f}", m.heap_mb),
                         m.map_mb);
    csv.close();
    if (!csv) throw InputError(o.memory_csv, "--memory-csv", "cannot write the memory samples");
  }
  if (o.json) {
    nlohmann::json j = figures_json(figures, o.memory_from);
    j["trajectory"] = o.out;
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print("replay of {} ({})\n{}", source_of(config), config.lidar.model, figures_text(figures, o.memory_from));
    if (!o.out.empty()) fmt::print("trajectory: {} ({} poses)\n", o.out, figures.poses - figures.invalid_poses);
    if (config.imu.enabled) {
      const daemon::ImuStats& imu = pipeline.stats().imu;
      const std::string_view source = daemon::imu_source_name(config.imu.source);
      fmt::print("imu {}: {} packets or frames, {} readings ({} with gyro) at {:.1f} Hz{}\n", source,
                 imu.packets.load(), imu.samples.load(), imu.gyro_samples.load(), imu.rate_hz.load(),
                 std::isfinite(imu.clock_spread_s.load())
                     ? fmt::format(", IMU packets' clock {:+.4f} s from the LiDAR's", imu.clock_spread_s.load())
                     : std::string());
      if (const std::string problems = daemon::describe_problems(imu, source); !problems.empty())
        fmt::print("{}\n", problems);
    }
  }
  if (figures.scans == 0) throw InputError(source_of(config), "lidar.model", "no scans decoded: is it a " + config.lidar.model + " capture?");
  return kExitOk;
}

}  // namespace

void register_replay_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<ReplayOptions>();
  CLI::App* cmd = app.add_subcommand(
      "replay", "Run aditd's pipeline on a capture or a scan directory: trajectory, counters, timing, latency, memory");
  cmd->add_option("--config", o->inputs.config_file, "Payload configuration (YAML) giving the lidar section")
      ->capture_default_str();
  auto* pcap = cmd->add_option("--pcap", o->inputs.pcap, "Capture to replay (sets lidar.source: pcap)");
  auto* scans = cmd->add_option("--scan-dir", o->inputs.scan_dir, "Directory of PCD or KITTI .bin scans (lidar.source: scan_dir)");
  pcap->excludes(scans);
  cmd->add_option("--can-log", o->inputs.can_log,
                  "Wheel encoders of this recording (candump -L; the config's can/wheel_odometry signals). Without "
                  "it, --pcap/--scan-dir replay without wheels");
  cmd->add_option("--model", o->inputs.model, "Override lidar.model (VLP-16, PandarXT32, OS1-64, ...)");
  cmd->add_option("--calibration", o->inputs.calibration, "Override lidar.calibration");
  cmd->add_option("--out", o->out, "Write the trajectory here (TUM: one line per valid pose)");
  auto* realtime = cmd->add_flag("--realtime", o->realtime, "Replay at the recorded rate (default: as fast as possible)");
  auto* speed = cmd->add_option("--speed", o->speed, "Replay at X times the recorded rate; 0 = as fast as possible")
                    ->check(CLI::Range(0.0, 1e6));
  realtime->excludes(speed);
  cmd->add_flag("--json", o->json, "Print the figures as JSON (for scripts)");
  auto* session = cmd->add_option("--session", o->session,
                  "Map a stored session again from its raw recordings (lidar.pcap, can.log) with its own config.yaml, "
                  "as aditd does: a new session folder with map, trajectory and summary (under --out-dir)")
      ->check(CLI::ExistingDirectory);
  session->excludes(pcap)->excludes(scans);
  cmd->add_option("--out-dir", o->out_dir,
                  "With --session: the state folder of the new session (<out-dir>/sessions/<id>/). Default: "
                  "<session>/replayed");
  cmd->add_option("--session-dir", o->session_dir,
                  "Where the mapping thread writes what the sensor has left, as a session does: tiles/<id>.adt and "
                  "keyframes/<stamp>.ply (map.evict_after_keyframes: 0 keeps all in RAM). Default: a temporary "
                  "folder removed at the end");
  cmd->add_option("--memory-from", o->memory_from,
                  "Resident growth is measured from this fraction of the poses (local map full) to the end")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--memory-csv", o->memory_csv,
                  "Write the memory samples here: poses, resident MB, malloc's bytes in use (every 50th sample), "
                  "the tiled map's MB");
  cmd->callback([o, &status] { status = replay(*o); });
}

}  // namespace adit::tools
