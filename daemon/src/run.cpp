#include "adit/daemon/run.hpp"

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"

namespace adit::daemon {
namespace {

std::string_view source_name(config::LidarSource source) {
  switch (source) {
    case config::LidarSource::udp: return "udp";
    case config::LidarSource::pcap: return "pcap";
    case config::LidarSource::scan_dir: return "scan_dir";
  }
  return "?";
}

}  // namespace

int run(const config::Config& config, const std::filesystem::path& config_file) {
  log::info("configuration {} loaded: payload '{}', lidar {} from {}", config_file.string(), config.payload.id,
            config.lidar.model, source_name(config.lidar.source));
  log::info("CAN {}, wheel odometry {}, GPIO {}", config.can.enabled ? "enabled" : "disabled",
            config.wheel_odometry.enabled ? "enabled" : "disabled", config.gpio.enabled ? "enabled" : "disabled");
  // The packet-to-pose pipeline (threads, queues, odometry, mapping, LCM) is
  // built by later work; until then the daemon says so plainly and stops.
  log::warn("the packet-to-pose pipeline is not built yet: nothing to run, exiting");
  return kExitOk;
}

}  // namespace adit::daemon
