#include "adit/daemon/run.hpp"

#include <signal.h>

#include <chrono>
#include <ctime>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/daemon/supervisor.hpp"

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

std::string session_name() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  return fmt::format("{:04}{:02}{:02}T{:02}{:02}{:02}Z", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday, utc.tm_hour,
                     utc.tm_min, utc.tm_sec);
}

std::string status_line(const PipelineStats& s) {
  return fmt::format("scans {} poses {} invalid {} degenerate {} dropped packets {} scans {}", s.scans.load(),
                     s.poses.load(), s.invalid_poses.load(), s.degenerate_poses.load(), s.dropped_packets.load(),
                     s.dropped_scans.load());
}

}  // namespace

int run(const config::Config& config, const std::filesystem::path& config_file) {
  log::info("configuration {}: payload '{}', lidar {} from {}", config_file.string(), config.payload.id,
            config.lidar.model, source_name(config.lidar.source));
  const std::filesystem::path session = std::filesystem::path(config.payload.state_dir) / "sessions" / session_name();
  PipelineOptions options;
  options.trajectory_file = session / "trajectory.tum";

  // SIGINT/SIGTERM are taken synchronously by this thread (sigtimedwait); the
  // workers inherit the blocked mask, so no handler runs on a hot path.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  Pipeline pipeline(config, options);
  pipeline.start();
  for (const std::string& warning : pipeline.warnings()) log::warn("{}", warning);

  const auto watchdog_ns = systemd_watchdog_ns();
  const std::int64_t check_ns = watchdog_ns ? *watchdog_ns / 2 : 1'000'000'000;
  const std::int64_t stall_ns = std::max<std::int64_t>(2'000'000'000, watchdog_ns.value_or(0) / 2);
  notify_ready(fmt::format("mapping: lidar {} from {}", config.lidar.model, source_name(config.lidar.source)));
  log::info("session {}: mapping", session.string());

  bool reported_stall = false;
  while (!pipeline.drained()) {
    const timespec timeout{static_cast<time_t>(check_ns / 1'000'000'000), static_cast<long>(check_ns % 1'000'000'000)};
    const int signal = sigtimedwait(&signals, nullptr, &timeout);
    if (signal == SIGINT || signal == SIGTERM) {
      log::info("signal {}: stopping", signal);
      pipeline.request_stop();
      break;
    }
    const auto beats = pipeline.heartbeats();
    const SupervisorVerdict verdict = check_heartbeats(beats, monotonic_ns(), stall_ns);
    if (verdict.healthy) {
      notify_watchdog();
      notify_status(status_line(pipeline.stats()));
      reported_stall = false;
    } else if (!reported_stall) {
      // No WATCHDOG=1 from here on: systemd restarts us after WatchdogSec.
      log::error("stalled worker(s): {}; no longer feeding the watchdog", verdict.stalled);
      notify_status("stalled: " + verdict.stalled);
      reported_stall = true;
    }
  }
  notify_stopping();
  pipeline.join();

  const PipelineStats& s = pipeline.stats();
  const PipelineTimings& t = pipeline.timings();
  log::info("{}", status_line(s));
  log::info("odometry per scan: median {:.2f} ms, p99 {:.2f} ms; pose latency p99 {:.2f} ms; {:.1f} s of data in {:.1f} s",
            quantile(t.odometry_ms, 0.5), quantile(t.odometry_ms, 0.99), quantile(t.latency_ms, 0.99), t.sensor_span_s,
            t.duration_s);
  log::info("trajectory: {}", options.trajectory_file.string());
  return kExitOk;
}

}  // namespace adit::daemon
