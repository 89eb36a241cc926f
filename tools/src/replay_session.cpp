// Mapping a stored session again from its raw recordings (replay_session.hpp).
#include "replay_session.hpp"

#include <chrono>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/sessions.hpp"

namespace adit::tools {

int replay_session(const std::filesystem::path& session_dir, const std::filesystem::path& out_dir) {
  const std::filesystem::path config_file = session_dir / "config.yaml";
  const std::filesystem::path pcap = session_dir / "lidar.pcap";
  if (!std::filesystem::exists(config_file))
    throw InputError(config_file.string(), "--session", "no configuration: not a session folder of aditd");
  if (!std::filesystem::exists(pcap))
    throw InputError(pcap.string(), "--session",
                     "no raw recording: the session ran with session.record_lidar false (or from a scan directory)");
  config::Config c = config::load_config(config_file);
  c.lidar.source = config::LidarSource::pcap;
  c.lidar.pcap = pcap.string();
  c.lidar.replay_speed = 0.0;  // as fast as possible: a replay waits, nothing is dropped
  if (c.can.enabled) {
    const std::filesystem::path can_log = session_dir / "can.log";
    if (std::filesystem::exists(can_log)) {
      c.can.source = config::CanSource::candump;
      c.can.log = can_log.string();
    } else {
      fmt::print(stderr, "adit replay: {}: no CAN recording: mapped without wheels and CAN IMU\n", can_log.string());
      c.can.enabled = false;
      c.wheel_odometry.enabled = false;
      if (c.imu.source == config::ImuSource::can) c.imu.enabled = false;
    }
  }
  c.payload.state_dir = out_dir.string();
  c.session.record_lidar = false;  // the recordings exist already
  c.can.record = false;
  c.session.autostart = false;
  c.threads.lock_memory = false;

  daemon::Sessions sessions(c, {});
  const std::string id = sessions.start();
  fmt::print("mapping {} again as session {} in {}\n", session_dir.string(), id, sessions.folder(id).string());
  while (!sessions.poll()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  sessions.stop_and_wait();  // writes the map files and the summary
  for (const std::string& warning : sessions.take_warnings()) fmt::print(stderr, "adit replay: {}\n", warning);
  const std::filesystem::path summary_file = sessions.folder(id) / "summary.json";
  std::ifstream summary_in(summary_file);
  const nlohmann::json summary = nlohmann::json::parse(summary_in, nullptr, false);
  if (!summary.is_object()) throw InputError(summary_file.string(), "", "the session's files were not written");
  fmt::print("{} scans, {} poses, {} map points in {} tiles; files in {}\n", summary["scans"]["total"].get<std::uint64_t>(),
             summary["poses"]["total"].get<std::uint64_t>(), summary["map"]["points"].get<std::uint64_t>(),
             summary["map"]["tiles"].get<std::uint64_t>(), sessions.folder(id).string());
  return kExitOk;
}

}  // namespace adit::tools
