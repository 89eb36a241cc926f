#include "adit/daemon/run.hpp"

#include <signal.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <cstdlib>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/daemon/allocator.hpp"
#include "adit/daemon/imu_pose_publisher.hpp"
#include "adit/daemon/lcm_endpoint.hpp"
#include "adit/daemon/payload_panel.hpp"
#include "adit/daemon/sessions.hpp"
#include "adit/daemon/supervisor.hpp"
#include "adit/slam/prior_map_file.hpp"

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

// lcm.key_file may name a systemd credential (LoadCredential= in the unit):
// "$CREDENTIALS_DIRECTORY/NAME", the directory known only at run time.
std::filesystem::path key_file_path(const std::string& configured) {
  for (const std::string_view prefix : {"$CREDENTIALS_DIRECTORY/", "${CREDENTIALS_DIRECTORY}/"}) {
    if (configured.rfind(prefix, 0) != 0) continue;
    const char* dir = std::getenv("CREDENTIALS_DIRECTORY");
    if (dir == nullptr || *dir == '\0')
      throw InputError("lcm.key_file", "key_file",
                       "names a systemd credential but CREDENTIALS_DIRECTORY is not set (LoadCredential= in the unit)");
    return std::filesystem::path(dir) / configured.substr(prefix.size());
  }
  return configured;
}

EndpointOptions endpoint_options(const config::Config& c) {
  EndpointOptions o;
  o.lcm_url = c.lcm.url;
  o.key_file = key_file_path(c.lcm.key_file);
  o.command_window_s = c.lcm.command_window_s;
  o.payload_id = c.payload.id;
  o.tiles.tile_size_m = c.map.tile_size_m;
  o.tile_period_s = c.map.publish_period_s;
  o.grid_period_s = c.grid.publish_period_s;
  o.grid_refresh_s = c.grid.refresh_s;
  return o;
}

std::string status_line(protocol::SessionState state, const StatusSample& s, const EndpointCounters& c) {
  std::string line = fmt::format("{}", protocol::state_name(state));
  for (const SensorHealth& h : s.sensors) line += fmt::format("; {} {:.0f} packets/s", h.name, h.packet_rate_hz);
  line += fmt::format("; poses {} published", c.poses_published.load());
  line += fmt::format("; commands {} executed, {} rejected", c.commands_executed.load(), c.commands_rejected.load());
  if (!c.commands_authenticated) line += ", not authenticated";
  if (!s.fault.empty()) line += "; " + s.fault;  // with lcm_faults()
  return line;
}

// What arrived over LCM that aditd refused: undecodable commands and tile
// requests (garbage, another protocol on the group), and commands refused by
// authentication, each counted by reason. "" while there is none.
std::string lcm_faults(const EndpointCounters& c) {
  std::string text;
  if (const std::uint64_t bad = c.commands_malformed + c.tile_requests_malformed; bad > 0)
    text = fmt::format("LCM: {} malformed commands, {} malformed tile requests (ignored)", c.commands_malformed.load(),
                       c.tile_requests_malformed.load());
  const std::uint64_t refused = c.commands_unsigned + c.commands_bad_tag + c.commands_stale +
                                c.commands_replay_rejected + c.commands_other_payload;
  if (refused > 0)
    text += fmt::format("{}commands refused: {} unsigned, {} bad tag, {} stale, {} replayed, {} other payload",
                        text.empty() ? "" : "; ", c.commands_unsigned.load(), c.commands_bad_tag.load(),
                        c.commands_stale.load(), c.commands_replay_rejected.load(), c.commands_other_payload.load());
  return text;
}

drivers::gpio::PayloadState panel_state(protocol::SessionState state, bool fault) {
  if (fault) return drivers::gpio::PayloadState::fault;
  switch (state) {
    case protocol::SessionState::idle: return drivers::gpio::PayloadState::idle;
    case protocol::SessionState::mapping: return drivers::gpio::PayloadState::mapping;
    case protocol::SessionState::stopping: return drivers::gpio::PayloadState::starting;  // steady: busy writing
  }
  return drivers::gpio::PayloadState::fault;
}

}  // namespace

int run(const config::Config& config, const std::filesystem::path& config_file, const RunOptions& options) {
  log::info("configuration {}: payload '{}', lidar {} from {}", config_file.string(), config.payload.id,
            config.lidar.model, source_name(config.lidar.source));
  if (!keep_large_blocks_mmapped()) log::warn("malloc: cannot fix the mmap threshold; a long session's RSS may creep");
  // The prior map (prior_map.dir) is read and checked at start, so a bad one is
  // named before a flight; the odometry goes on without it when it is unusable.
  // Each session localises against it and corrects its drift live (docs/PRIOR-MAP.md, "In aditd").
  if (!config.prior_map.dir.empty()) {
    try {
      const slam::PriorMap prior = slam::read_prior_map(config.prior_map.dir);
      if (const std::string problem = slam::check_prior_map(prior); !problem.empty())
        log::error("prior map {}: not usable ({}); mapping without it", config.prior_map.dir, problem);
      else
        log::info("prior map {}: {} points, plan {} x {} cells", config.prior_map.dir, prior.points.size(),
                  prior.plan.width, prior.plan.height);
    } catch (const InputError& e) {
      log::error("prior map: {}; mapping without it", e.what());
    }
  }

  // SIGINT/SIGTERM are taken synchronously by this thread (sigtimedwait); the
  // workers inherit the blocked mask, so no handler runs on a hot path.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // Sessions hand poses and tiles to the endpoint; the endpoint's commands
  // drive the sessions. The endpoint outlives no session: it is reset only
  // after stop_and_wait().
  // Set once the endpoint exists; its thread may take a START a moment before.
  std::atomic<LcmEndpoint*> endpoint_ptr{nullptr};
  Sessions::Outputs outputs;
  outputs.pose = [&endpoint_ptr](const PoseSample& p) {
    if (LcmEndpoint* e = endpoint_ptr.load(std::memory_order_relaxed)) e->publish_pose(p);
  };
  outputs.tile = [&endpoint_ptr](TileUpdate&& t) {
    LcmEndpoint* e = endpoint_ptr.load(std::memory_order_relaxed);
    return e != nullptr && e->publish_tile(std::move(t));
  };
  outputs.tile_backlog = [&endpoint_ptr]() -> std::uint64_t {
    const LcmEndpoint* e = endpoint_ptr.load(std::memory_order_relaxed);
    return e != nullptr ? e->tile_points_waiting() : 0;
  };
  outputs.grid = [&endpoint_ptr](GridPatchUpdate&& g) {
    if (LcmEndpoint* e = endpoint_ptr.load(std::memory_order_relaxed)) e->publish_grid(std::move(g));
  };
  // The tile and grid streams' bandwidth per session, for the crew's link budget.
  std::atomic<std::uint64_t> tile_bytes_at_start{0};
  std::atomic<std::uint64_t> grid_bytes_at_start{0};
  std::atomic<std::int64_t> session_start_ns{0};
  outputs.ended = [&](const std::string& id) {
    const double seconds = 1e-9 * static_cast<double>(monotonic_ns() - session_start_ns.load());
    LcmEndpoint* e = endpoint_ptr.load();
    const double bytes = static_cast<double>(e->counters().chunk_bytes_published.load() - tile_bytes_at_start.load());
    log::info("session {}: tile stream {:.1f} kB/s ({:.1f} MB in {:.0f} s)", id, seconds > 0 ? bytes / seconds / 1e3 : 0.0,
              bytes / 1e6, seconds);
    const double grid_bytes = static_cast<double>(e->counters().grid_bytes_published.load() - grid_bytes_at_start.load());
    log::info("session {}: grid stream {:.1f} kB/s ({:.2f} MB)", id, seconds > 0 ? grid_bytes / seconds / 1e3 : 0.0,
              grid_bytes / 1e6);
    e->session_stopped();
  };
  // The IMU-rate pose goes out on the IMU's thread by an LCM instance of its own (imu_pose_publisher.hpp).
  std::optional<ImuPosePublisher> imu_poses;
  if (config.imu.enabled && config.imu.pose_horizon_s > 0.0) {
    imu_poses.emplace(config.lcm.url, config.payload.id);
    outputs.imu_pose = [&imu_poses](const slam::InertialState& s, const slam::Matrix6d& c) { imu_poses->publish(s, c); };
    if (const std::optional<std::string> warning = imu_pose_latency_warning(config)) log::warn("{}", *warning);
  }
  Sessions sessions(config, std::move(outputs));

  SessionHooks hooks;
  hooks.start = [&] {
    std::string id = sessions.start();
    if (const LcmEndpoint* e = endpoint_ptr.load()) {
      tile_bytes_at_start = e->counters().chunk_bytes_published.load();
      grid_bytes_at_start = e->counters().grid_bytes_published.load();
    }
    session_start_ns = monotonic_ns();
    return id;
  };
  hooks.stop = [&sessions] { sessions.request_stop(); };
  hooks.sessions = [&sessions] { return sessions.list(); };
  hooks.export_map = [&sessions, &config](const std::string& id, const std::vector<std::string>&) {
    // Exports are written when a session stops; EXPORT says where they are.
    const std::filesystem::path dir = sessions.folder(id);
    if (id.empty() || !std::filesystem::is_directory(dir)) throw std::runtime_error("no session '" + id + "'");
    std::string files;
    for (const std::string& format : config.session.exports)
      if (std::filesystem::exists(dir / ("map." + format))) files += (dir / ("map." + format)).string() + "\n";
    if (files.empty()) throw std::runtime_error("session '" + id + "' has no map files yet");
    return files;
  };
  hooks.load_tiles = [&sessions](const std::string& id, TileStore& into) { return sessions.load_tiles(id, into); };
  hooks.stored_frame = [&sessions](const std::string& id) { return sessions.stored_frame(id); };
  hooks.session_folder = [&sessions](const std::string& id) { return sessions.folder(id); };
  hooks.hint = [&sessions](const protocol::LocaliseHint& hint) { return sessions.hint(hint); };
  auto endpoint = std::make_unique<LcmEndpoint>(endpoint_options(config), std::move(hooks));
  endpoint_ptr.store(endpoint.get());
  log::info("LCM: {} as payload '{}'", config.lcm.url, config.payload.id);

  // The button, LED and LiDAR power, when the payload has them.
  PayloadGpio gpio;
  std::optional<PayloadPanel> panel;
  if (config.gpio.enabled) {
    gpio = open_payload_gpio(config.gpio);
    panel.emplace(*gpio.button, *gpio.led, *gpio.power, std::chrono::milliseconds(config.gpio.debounce_ms),
                  std::chrono::nanoseconds(monotonic_ns()));
    log::info("GPIO: button, status LED and LiDAR power on {}", config.gpio.chip);
  }

  if (options.once || config.session.autostart) endpoint->start_session();

  const auto watchdog_ns = systemd_watchdog_ns();
  const std::int64_t tick_ns = 50'000'000;
  const std::int64_t pet_ns = watchdog_ns ? *watchdog_ns / 2 : 1'000'000'000;
  const std::int64_t stall_ns = std::max<std::int64_t>(2'000'000'000, watchdog_ns.value_or(0) / 2);
  const std::int64_t status_ns = 500'000'000;  // 2 Hz, as docs/PROTOCOL.md promises
  notify_ready(fmt::format("idle: lidar {} from {}", config.lidar.model, source_name(config.lidar.source)));

  bool reported_stall = false;
  bool seen_session = false;
  std::int64_t last_status_ns = 0;
  std::int64_t last_pet_ns = 0;
  while (true) {
    const timespec timeout{0, static_cast<long>(tick_ns)};
    const int signal = sigtimedwait(&signals, nullptr, &timeout);
    if (signal == SIGINT || signal == SIGTERM) {
      log::info("signal {}: stopping", signal);
      break;
    }
    if (sessions.poll()) {
      log::info("the recording has ended: stopping the session");
      endpoint->stop_session();
    }
    for (const std::string& warning : sessions.take_warnings()) log::warn("{}", warning);
    if (const std::exception_ptr failure = sessions.take_start_failure(); failure && options.once) {
      notify_stopping();
      std::rethrow_exception(failure);  // named InputError: exit 2, as for a bad configuration
    }
    const bool running = sessions.running() || endpoint->state() != protocol::SessionState::idle;
    seen_session = seen_session || running;
    if (options.once && seen_session && !running) break;

    const std::int64_t now = monotonic_ns();
    if (panel && panel->tick(std::chrono::nanoseconds(now), panel_state(endpoint->state(), reported_stall))) {
      log::info("button pressed");
      endpoint->button_pressed();
    }
    if (now - last_status_ns >= status_ns) {
      last_status_ns = now;
      StatusSample status = sessions.status_sample();
      if (const std::string lcm = lcm_faults(endpoint->counters()); !lcm.empty())
        status.fault += (status.fault.empty() ? "" : "; ") + lcm;
      const std::string line = status_line(endpoint->state(), status, endpoint->counters());
      endpoint->publish_status(std::move(status));
      if (!reported_stall) notify_status(line);
    }
    if (now - last_pet_ns >= pet_ns) {
      last_pet_ns = now;
      const SupervisorVerdict verdict = check_heartbeats(sessions.heartbeats(), now, stall_ns);
      if (verdict.healthy) {
        notify_watchdog();
        reported_stall = false;
      } else if (!reported_stall) {
        // No WATCHDOG=1 from here on: systemd restarts us after WatchdogSec.
        log::error("stalled worker(s): {}; no longer feeding the watchdog", verdict.stalled);
        notify_status("stalled: " + verdict.stalled);
        reported_stall = true;
      }
    }
  }
  notify_stopping();
  sessions.stop_and_wait();  // the running session's files are written before we go
  endpoint.reset();
  if (panel) panel->shutdown(std::chrono::nanoseconds(monotonic_ns()));
  return kExitOk;
}

}  // namespace adit::daemon
