#include "pipeline_run.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include <fmt/format.h>

#include "adit/common/quantile.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/imu_pose_feed.hpp"
#include "process_memory.hpp"

namespace adit::tools {

config::Config load_pipeline_config(const PipelineInputs& in) {
  config::Config c = config::load_config(in.config_file);
  if (!in.pcap.empty()) {
    c.lidar.source = config::LidarSource::pcap;
    c.lidar.pcap = in.pcap;
  }
  if (!in.scan_dir.empty()) {
    c.lidar.source = config::LidarSource::scan_dir;
    c.lidar.scan_dir = in.scan_dir;
  }
  // Another recording than the config's: its own CAN log, or no wheels (the
  // config's log belongs to its own recording).
  if (!in.can_log.empty()) {
    c.can.source = config::CanSource::candump;
    c.can.log = in.can_log;
  } else if (c.can.source == config::CanSource::candump && (!in.pcap.empty() || !in.scan_dir.empty())) {
    c.can.enabled = false;
    c.wheel_odometry.enabled = false;
  }
  if (!in.model.empty()) c.lidar.model = in.model;
  if (!in.calibration.empty()) c.lidar.calibration = in.calibration;
  c.threads.lock_memory = false;
  return c;
}

PipelineFigures run_pipeline(daemon::Pipeline& pipeline, const RunHooks& hooks, const daemon::SessionFiles& files) {
  PipelineFigures f;
  f.memory.reserve(1 << 20);  // 29 h of scans at 10 Hz; reserved, so sampling does not move memory
  const daemon::PipelineStats& s = pipeline.stats();
  pipeline.start(files);
  if (hooks.started) hooks.started();
  std::uint64_t sampled_poses = 0;
  while (!pipeline.drained()) {
    if (hooks.stop_when && hooks.stop_when()) {
      pipeline.request_stop();
      break;
    }
    const std::uint64_t poses = s.poses.load(std::memory_order_relaxed);
    if (poses != sampled_poses && f.memory.size() < f.memory.capacity()) {
      // The heap walk locks the arenas the pipeline allocates from: every
      // 50th sample only (about every 5 s of data).
      f.memory.push_back({poses, resident_mb(), f.memory.size() % 50 == 0 ? heap_in_use_mb() : -1.0,
                          1e-6 * static_cast<double>(s.map_bytes.load(std::memory_order_relaxed))});
      sampled_poses = poses;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  pipeline.join();
  f.memory.push_back({s.poses.load(), resident_mb(), heap_in_use_mb(), 1e-6 * static_cast<double>(s.map_bytes.load())});

  f.datagrams = s.datagrams.load();
  f.scans = s.scans.load();
  f.incomplete_scans = s.incomplete_scans.load();
  f.skipped_start_scans = s.skipped_start_scans.load();
  f.poses = s.poses.load();
  f.invalid_poses = s.invalid_poses.load();
  f.degenerate_poses = s.degenerate_poses.load();
  f.bad_packets = s.bad_packets.load();
  f.dropped_packets = s.dropped_packets.load();
  f.socket_drops = s.socket_drops.load();
  f.dropped_scans = s.dropped_scans.load();
  const daemon::PipelineTimings& t = pipeline.timings();
  f.odometry_median_ms = quantile(t.odometry_ms, 0.5);
  f.odometry_p99_ms = quantile(t.odometry_ms, 0.99);
  f.latency_median_ms = quantile(t.latency_ms, 0.5);
  f.latency_p99_ms = quantile(t.latency_ms, 0.99);
  f.latency_max_ms = quantile(t.latency_ms, 1.0);
  if (t.latency_ms.size() == t.odometry_ms.size()) {  // one of each per scan, in order
    std::vector<double> beyond(t.latency_ms.size());
    for (std::size_t i = 0; i < beyond.size(); ++i) beyond[i] = t.latency_ms[i] - t.odometry_ms[i];
    f.beyond_odometry_median_ms = quantile(beyond, 0.5);
    f.beyond_odometry_p99_ms = quantile(beyond, 0.99);
  }
  f.sensor_span_s = t.sensor_span_s;
  f.duration_s = t.duration_s;
  f.peak_resident_mb = peak_resident_mb();
  f.mapping = s.mapped_scans.load() > 0;
  f.map_points = s.map_points.load();
  f.map_tiles = s.map_tiles.load();
  f.resident_tiles = s.resident_tiles.load();
  f.evicted_tiles = s.evicted_tiles.load();
  f.restored_tiles = s.restored_tiles.load();
  f.compacted_tiles = s.compacted_tiles.load();
  f.lost_candidates = s.lost_candidates.load();
  f.tile_file_errors = s.tile_file_errors.load();
  f.keyframes = s.keyframes.load();
  f.spilled_keyframes = s.spilled_keyframes.load();
  f.map_mb = 1e-6 * static_cast<double>(s.map_bytes.load());
  f.keyframe_mb = 1e-6 * static_cast<double>(s.keyframe_bytes.load());
  if (const daemon::ImuPoseFeed* imu = pipeline.imu_poses()) {
    f.imu_pose = true;
    f.imu_poses = imu->poses();
    f.imu_pose_latency_median_ms = quantile(imu->latency_ms(), 0.5);
    f.imu_pose_latency_p99_ms = quantile(imu->latency_ms(), 0.99);
    f.imu_pose_latency_max_ms = quantile(imu->latency_ms(), 1.0);
  }
  return f;
}

std::optional<MemoryGrowth> memory_growth(const std::vector<MemorySample>& samples, double from_fraction) {
  if (samples.size() < 2) return std::nullopt;
  const auto from_pose = static_cast<std::uint64_t>(from_fraction * static_cast<double>(samples.back().poses));
  const auto first = std::find_if(samples.begin(), samples.end(), [&](const MemorySample& m) { return m.poses >= from_pose; });
  MemoryGrowth g;
  g.from_pose = first->poses;
  g.from_mb = first->resident_mb;
  g.end_mb = samples.back().resident_mb;
  const auto heap = std::find_if(first, samples.end(), [](const MemorySample& m) { return m.heap_mb >= 0.0; });
  if (heap != samples.end()) g.heap_from_mb = heap->heap_mb;
  g.heap_end_mb = samples.back().heap_mb;
  g.map_from_mb = first->map_mb;
  g.map_end_mb = samples.back().map_mb;
  g.max_mb = std::max_element(first, samples.end(), [](const MemorySample& a, const MemorySample& b) {
               return a.resident_mb < b.resident_mb;
             })->resident_mb;
  for (auto m = first; m != samples.end(); ++m) g.max_beyond_map_mb = std::max(g.max_beyond_map_mb, m->resident_mb - m->map_mb);
  return g;
}

nlohmann::json figures_json(const PipelineFigures& f, double from_fraction) {
  nlohmann::json j = {
      {"datagrams", f.datagrams},
      {"scans", f.scans},
      {"incomplete_scans", f.incomplete_scans},
      {"skipped_start_scans", f.skipped_start_scans},
      {"poses", f.poses},
      {"invalid_poses", f.invalid_poses},
      {"degenerate_poses", f.degenerate_poses},
      {"bad_packets", f.bad_packets},
      {"dropped_packets", f.dropped_packets},
      {"socket_drops", f.socket_drops},
      {"dropped_scans", f.dropped_scans},
      {"odometry_ms", {{"median", f.odometry_median_ms}, {"p99", f.odometry_p99_ms}}},
      {"latency_ms", {{"median", f.latency_median_ms}, {"p99", f.latency_p99_ms}, {"max", f.latency_max_ms}}},
      {"latency_beyond_odometry_ms", {{"median", f.beyond_odometry_median_ms}, {"p99", f.beyond_odometry_p99_ms}}},
      {"sensor_span_s", f.sensor_span_s},
      {"duration_s", f.duration_s},
      {"speed", f.speed()},
      {"peak_resident_mb", f.peak_resident_mb},
  };
  if (const auto g = memory_growth(f.memory, from_fraction))
    j["resident_growth"] = {{"from_pose", g->from_pose}, {"from_mb", g->from_mb}, {"end_mb", g->end_mb},
                            {"max_mb", g->max_mb},       {"percent", g->percent()}, {"samples", f.memory.size()},
                            {"heap_in_use_from_mb", g->heap_from_mb}, {"heap_in_use_end_mb", g->heap_end_mb},
                            {"map_from_mb", g->map_from_mb}, {"map_end_mb", g->map_end_mb},
                            {"max_beyond_map_mb", g->max_beyond_map_mb}};
  if (f.imu_pose)
    j["imu_poses"] = {{"count", f.imu_poses},
                      {"latency_ms",
                       {{"median", f.imu_pose_latency_median_ms},
                        {"p99", f.imu_pose_latency_p99_ms},
                        {"max", f.imu_pose_latency_max_ms}}}};
  if (f.mapping)
    j["map"] = {{"points", f.map_points},           {"tiles", f.map_tiles},
                {"resident_tiles", f.resident_tiles}, {"evicted_tiles", f.evicted_tiles},
                {"restored_tiles", f.restored_tiles}, {"compacted_tiles", f.compacted_tiles},
                {"lost_candidates", f.lost_candidates},
                {"tile_file_errors", f.tile_file_errors}, {"resident_mb", f.map_mb},
                {"keyframes", f.keyframes},           {"spilled_keyframes", f.spilled_keyframes},
                {"keyframe_mb", f.keyframe_mb}};
  return j;
}

std::string figures_text(const PipelineFigures& f, double from_fraction) {
  std::string text = fmt::format(
      "scans {} ({} incomplete, {} skipped: an incomplete first scan), poses {} ({} invalid, {} degenerate); dropped {} packets, {} scans; {} bad packets\n"
      "odometry per scan: median {:.2f} ms, p99 {:.2f} ms\n"
      "latency, last packet of a scan to its pose: median {:.2f} ms, p99 {:.2f} ms, max {:.2f} ms "
      "(beyond odometry: median {:.2f} ms, p99 {:.2f} ms)\n"
      "{:.1f} s of data in {:.1f} s = {:.1f}x real time\n"
      "memory: peak resident {:.1f} MB",
      f.scans, f.incomplete_scans, f.skipped_start_scans, f.poses, f.invalid_poses, f.degenerate_poses, f.dropped_packets, f.dropped_scans,
      f.bad_packets, f.odometry_median_ms, f.odometry_p99_ms, f.latency_median_ms, f.latency_p99_ms, f.latency_max_ms,
      f.beyond_odometry_median_ms, f.beyond_odometry_p99_ms, f.sensor_span_s, f.duration_s, f.speed(), f.peak_resident_mb);
  if (const auto g = memory_growth(f.memory, from_fraction))
    text += fmt::format("; resident {:.1f} MB at pose {} -> {:.1f} MB at the end ({:+.2f} %, max {:.1f} MB; "
                        "max {:.1f} MB beyond the map's tiles)",
                        g->from_mb, g->from_pose, g->end_mb, g->percent(), g->max_mb, g->max_beyond_map_mb);
  if (const auto g = memory_growth(f.memory, from_fraction); g && g->heap_from_mb >= 0.0 && g->heap_end_mb >= 0.0)
    text += fmt::format("; malloc in use {:.1f} -> {:.1f} MB, map tiles {:.1f} -> {:.1f} MB", g->heap_from_mb,
                        g->heap_end_mb, g->map_from_mb, g->map_end_mb);
  if (f.mapping)
    text += fmt::format(
        "\nmap: {} points in {} tiles, {} resident ({:.1f} MB); {} evictions, {} reloads, {} compactions, {} "
        "unconfirmed voxels lost, {} file errors; {} keyframes, {} scans in RAM ({:.1f} MB)",
        f.map_points, f.map_tiles, f.resident_tiles, f.map_mb, f.evicted_tiles, f.restored_tiles, f.compacted_tiles,
        f.lost_candidates,
        f.tile_file_errors, f.keyframes, f.keyframes - f.spilled_keyframes, f.keyframe_mb);
  if (f.imu_pose)
    text += fmt::format("\nIMU-rate poses: {}; latency from the IMU reading's arrival: median {:.3f} ms, p99 {:.3f} ms, "
                        "max {:.3f} ms",
                        f.imu_poses, f.imu_pose_latency_median_ms, f.imu_pose_latency_p99_ms, f.imu_pose_latency_max_ms);
  return text + "\n";
}

}  // namespace adit::tools
