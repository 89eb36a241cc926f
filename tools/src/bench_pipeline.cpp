// adit bench pipeline: aditd's pipeline receiving a capture sent to it over
// UDP loopback at the recorded rate (as `adit pcap-send` does), against the
// same pipeline reading the capture file at the same pace in the same run, so
// the network's share of the latency shows. Latency is from the receiver
// handing on the last packet of a scan to the pose being handed on.

#include "bench_pipeline.hpp"

#include <atomic>
#include <cerrno>
#include <ctime>
#include <exception>
#include <optional>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/daemon/imu_pose_publisher.hpp"
#include "adit/daemon/lidar_source.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/drivers/udp.hpp"
#include "capture_sender.hpp"
#include "pipeline_run.hpp"

namespace adit::tools {
namespace {

constexpr double kLatencyTargetMs = 10.0;    // p99, issue #6
constexpr const char* kBenchLcmUrl = "udpm://239.255.76.67:7667?ttl=0";  // this host only
constexpr std::int64_t kQuietNs = 500'000'000;   // everything sent arrived and nothing moved since: done
constexpr std::int64_t kGiveUpNs = 5'000'000'000; // nothing moved for this long: the rest was lost

struct BenchPipelineOptions {
  PipelineInputs inputs;
  double speed = 1.0;
  bool json = false;
};

// A free UDP port on loopback (asked of the kernel, then released for the pipeline).
std::uint16_t free_loopback_port() {
  drivers::UdpReceiverConfig probe;
  probe.bind_address = "127.0.0.1";
  return drivers::UdpReceiver(probe).port();
}

// The port the capture's data packets were sent to: configured, or the model's default.
std::uint16_t data_port_of(const config::Config& c) {
  if (c.lidar.port != 0) return static_cast<std::uint16_t>(c.lidar.port);
  const drivers::LidarFamily* family = drivers::lidar_family_of_model(c.lidar.model);
  if (family == nullptr) throw InputError("", "lidar.model", "no decoder for " + c.lidar.model);
  return family->make_decoder(c.lidar.model, c.lidar.calibration)->default_port();
}

// The capture time of the first datagram to `port` (0 when there is none).
std::int64_t first_capture_time_ns(const std::filesystem::path& pcap, int port) {
  drivers::PcapReader reader(pcap);
  drivers::UdpDatagram d;
  while (reader.next(d))
    if (d.dst_port == port) return d.capture_time_ns;
  return 0;
}

void sleep_until_realtime(std::int64_t ns) {
  const timespec until{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &until, nullptr) == EINTR) {
  }
}

// Over the network the pipeline stamps scans with the host clock, while a
// recorded CAN log keeps its recording's times: the wheels would never line
// up. Sending starts at a set instant, and the log is shifted by the
// configured CAN-minus-LiDAR offset so that its first record and the
// capture's meet there (at the recorded rate only; otherwise no wheels).
std::int64_t align_recorded_wheels(config::Config& c, double speed, int capture_port) {
  if (!c.can.enabled || !c.wheel_odometry.enabled || c.can.source != config::CanSource::candump) return 0;
  if (speed != 1.0) {
    fmt::print("wheels: off over loopback (a recorded CAN log follows the host clock only at --speed 1)\n");
    c.can.enabled = false;
    return 0;
  }
  constexpr std::int64_t kStartupNs = 1'500'000'000;  // pipeline construction and start, with room to spare
  const std::int64_t send_at = realtime_ns() + kStartupNs;
  c.wheel_odometry.time_offset_s += 1e-9 * static_cast<double>(first_capture_time_ns(c.lidar.pcap, capture_port) - send_at);
  return send_at;
}

struct LoopbackRun {
  PipelineFigures figures;
  SendTotals sent;
};

LoopbackRun run_over_loopback(const config::Config& file_config, double speed, const daemon::PipelineSinks& sinks) {
  config::Config c = file_config;
  const int capture_port = data_port_of(file_config);
  c.lidar.source = config::LidarSource::udp;
  c.lidar.address = "127.0.0.1";
  c.lidar.port = free_loopback_port();
  c.lidar.interface.clear();
  c.lidar.multicast_group.clear();
  // The LiDAR's own IMU packets (an Ouster's, a Mid-360's) to a port of their own, as the sensor sends them.
  std::vector<SendRoute> routes{{capture_port, static_cast<std::uint16_t>(c.lidar.port)}};
  if (const std::uint16_t imu_capture_port = daemon::lidar_imu_port(file_config);
      imu_capture_port != 0 && imu_capture_port != capture_port) {
    do c.lidar.imu_port = free_loopback_port();
    while (c.lidar.imu_port == c.lidar.port);
    routes.push_back({imu_capture_port, static_cast<std::uint16_t>(c.lidar.imu_port)});
  }
  const std::int64_t send_at_ns = align_recorded_wheels(c, speed, capture_port);
  daemon::PipelineOptions options;
  options.sinks = sinks;
  daemon::Pipeline pipeline(c, options);

  LoopbackRun run;
  std::atomic<bool> stop_sending{false};
  std::atomic<bool> sent_all{false};
  std::exception_ptr send_error;
  std::thread sender;
  std::uint64_t last_count = 0;
  std::int64_t last_change_ns = monotonic_ns();
  RunHooks hooks;
  hooks.started = [&] {
    sender = std::thread([&] {
      try {
        if (send_at_ns != 0) sleep_until_realtime(send_at_ns);
        run.sent = send_capture(c.lidar.pcap, "127.0.0.1", routes, speed, stop_sending);
      } catch (...) {
        send_error = std::current_exception();
      }
      sent_all.store(true, std::memory_order_release);
    });
  };
  // A live source never ends: stop once everything is sent and the pipeline has been quiet a while.
  hooks.stop_when = [&] {
    const daemon::PipelineStats& s = pipeline.stats();
    const std::uint64_t count = s.datagrams.load() + s.poses.load();
    const std::int64_t now = monotonic_ns();
    if (count != last_count) {
      last_count = count;
      last_change_ns = now;
    }
    if (!sent_all.load(std::memory_order_acquire)) return false;
    // A busy machine may not run the receiver for a while: wait for every
    // datagram sent (or give up after a long silence, counting the rest lost).
    const bool all_arrived = s.datagrams.load() >= run.sent.sent;
    return (all_arrived && now - last_change_ns > kQuietNs) || now - last_change_ns > kGiveUpNs;
  };
  run.figures = run_pipeline(pipeline, hooks);
  stop_sending.store(true);
  if (sender.joinable()) sender.join();
  if (send_error) std::rethrow_exception(send_error);
  return run;
}

int bench_pipeline(const BenchPipelineOptions& o) {
  const config::Config config = load_pipeline_config(o.inputs);
  if (config.lidar.source != config::LidarSource::pcap)
    throw InputError(o.inputs.config_file, "lidar.source", "the bench needs a capture: give --pcap or lidar.source: pcap");

  // The IMU-rate pose goes out over LCM as aditd sends it (to this host only,
  // ttl=0), so its latency includes the send.
  std::optional<daemon::ImuPosePublisher> imu_poses;
  daemon::PipelineSinks sinks;
  if (config.imu.enabled && config.imu.pose_horizon_s > 0.0) {
    imu_poses.emplace(kBenchLcmUrl, "adit-bench");
    sinks.imu_pose = [&](const slam::InertialState& s, const slam::Matrix6d& c) { imu_poses->publish(s, c); };
  }
  // The file's pipeline is gone before the loopback run, whose resident size
  // would otherwise hold both (the peak, VmHWM, is the process's and does).
  const PipelineFigures file = [&] {
    daemon::PipelineOptions file_options;
    file_options.replay_speed = o.speed;
    file_options.sinks = sinks;
    daemon::Pipeline file_pipeline(config, file_options);
    return run_pipeline(file_pipeline);
  }();
  const LoopbackRun udp = run_over_loopback(config, o.speed, sinks);
  const std::uint64_t lost = udp.sent.sent > udp.figures.datagrams ? udp.sent.sent - udp.figures.datagrams : 0;

  if (o.json) {
    nlohmann::json j;
    j["capture"] = config.lidar.pcap;
    j["speed"] = o.speed;
    j["file"] = figures_json(file, 0.1);
    j["udp"] = figures_json(udp.figures, 0.1);
    j["udp"]["sent"] = udp.sent.sent;
    j["udp"]["refused"] = udp.sent.refused;
    j["udp"]["lost"] = lost;
    j["latency_target_ms"] = kLatencyTargetMs;
    fmt::print("{}\n", j.dump(2));
    return kExitOk;
  }
  fmt::print("capture {} ({}) at {}x the recorded rate\n\n", config.lidar.pcap, config.lidar.model, o.speed);
  fmt::print("from the file (no network):\n{}\n", figures_text(file, 0.1));
  fmt::print("over UDP loopback: sent {} datagrams ({} refused), received {}, lost {} ({} overflowed the socket's buffer)\n{}\n",
             udp.sent.sent, udp.sent.refused, udp.figures.datagrams, lost, udp.figures.socket_drops,
             figures_text(udp.figures, 0.1));
  // The latency starts when the receiver hands the last packet of a scan on,
  // so the kernel's loopback hop itself is outside it; what the network source
  // changes is the receiver's batching and scheduling, seen beyond odometry.
  fmt::print("latency p99: {:.2f} ms over loopback, {:.2f} ms from the file; beyond odometry {:.2f} ms vs {:.2f} ms "
             "(network share {:+.2f} ms); target <= {:.0f} ms: {}\n",
             udp.figures.latency_p99_ms, file.latency_p99_ms, udp.figures.beyond_odometry_p99_ms,
             file.beyond_odometry_p99_ms, udp.figures.beyond_odometry_p99_ms - file.beyond_odometry_p99_ms,
             kLatencyTargetMs, udp.figures.latency_p99_ms <= kLatencyTargetMs ? "met" : "NOT met");
  if (const std::optional<std::string> warning = daemon::imu_pose_latency_warning(config)) fmt::print("note: {}\n", *warning);
  return kExitOk;
}

}  // namespace

void add_bench_pipeline_command(CLI::App& bench, int& status) {
  auto o = std::make_shared<BenchPipelineOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "pipeline", "aditd's pipeline fed a capture over UDP loopback: latency median/p99/max, drops, odometry time; "
                  "the same replay from the file as a baseline");
  cmd->add_option("--config", o->inputs.config_file, "Payload configuration (YAML) giving the lidar section")
      ->capture_default_str();
  cmd->add_option("--pcap", o->inputs.pcap, "Capture to send (sets lidar.source: pcap)");
  cmd->add_option("--model", o->inputs.model, "Override lidar.model");
  cmd->add_option("--calibration", o->inputs.calibration, "Override lidar.calibration");
  cmd->add_option("--speed", o->speed, "Times the recorded rate for both runs (default 1: real time)")
      ->check(CLI::Range(0.01, 100.0));
  cmd->add_flag("--json", o->json, "Print the figures as JSON (for scripts)");
  cmd->callback([o, &status] { status = bench_pipeline(*o); });
}

}  // namespace adit::tools
