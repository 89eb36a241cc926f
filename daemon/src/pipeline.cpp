#include "adit/daemon/pipeline.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <numbers>
#include <optional>

#include <malloc.h>
#include <pthread.h>
#include <time.h>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/thread_settings.hpp"
#include "adit/daemon/wheel_feed.hpp"
#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/lidar/scan_directory.hpp"
#include "adit/drivers/pcap_replay.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/drivers/udp.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/slam/gravity.hpp"
#include "adit/slam/lie.hpp"
#include "adit/slam/map_refiner.hpp"

namespace adit::daemon {
namespace {

constexpr std::size_t kMaxDatagram = 65'536;
constexpr std::size_t kPacketSlots = 512;   // ~0.4 s of the busiest sensor (Ouster, 1280 packets/s)
constexpr std::size_t kScanSlots = 4;
constexpr std::size_t kPoseSlots = 8;
constexpr std::size_t kMapSlots = 4;
constexpr std::size_t kKeyframeScansInRam = 100;  // the newest keyframes keep their scans in RAM (~5 MB)
constexpr std::size_t kTimingCapacity = 1 << 20;  // scans kept for statistics (29 h at 10 Hz)

struct Packet {
  std::int64_t host_time_ns = 0;     // capture or kernel time (the sensor clock's reference)
  std::uint32_t src_ip = 0;          // for the raw recording
  std::uint16_t src_port = 0;
  std::int64_t received_mono_ns = 0; // when the receiver handed it on (latency)
  std::uint32_t size = 0;
  std::array<std::uint8_t, kMaxDatagram> data{};
};

struct ScanSlot {
  drivers::LidarScan scan;
  std::int64_t last_packet_mono_ns = 0;
};

struct PoseSlot {
  slam::OdometryResult result;
  std::int64_t last_packet_mono_ns = 0;
  std::int64_t pose_mono_ns = 0;
};

// A registered scan for the mapping thread: body-frame points as measured
// (not deskewed: mapping deskews with the corrected motion), with the pose.
struct MapSlot {
  std::int64_t stamp_ns = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  bool valid = false;
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times_s;
  std::vector<float> intensities;
};


void wait_a_little() { std::this_thread::sleep_for(std::chrono::microseconds(200)); }

std::int64_t realtime_ns() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec;
}

double thread_cpu_s(std::thread& thread) {
  clockid_t clock{};
  timespec t{};
  if (!thread.joinable() || pthread_getcpuclockid(thread.native_handle(), &clock) != 0 ||
      clock_gettime(clock, &t) != 0)
    return 0.0;
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

slam::TiledMapConfig map_config_of(const config::MapSection& m) {
  return {static_cast<float>(m.tile_size_m), static_cast<float>(m.voxel_m), static_cast<std::uint8_t>(m.min_hits)};
}

// No point of a scan lies farther than max_range_m from the body (map_scan
// filters them), deskewing moves points by at most a sweep's motion, and the
// sensor's offset from the body is small: the margin covers both.
slam::TileEvictionConfig eviction_config_of(const config::MapSection& m) {
  return {static_cast<float>(m.max_range_m + m.evict_margin_m), m.evict_after_keyframes,
          static_cast<std::size_t>(m.compact_tile_voxels)};
}

// One TUM line: stamp (s) x y z qx qy qz qw.
void write_tum_line(std::FILE* file, std::int64_t stamp_ns, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d& t = pose.translation();
  fmt::print(file, "{:.9f} {:.6f} {:.6f} {:.6f} {:.9f} {:.9f} {:.9f} {:.9f}\n", 1e-9 * static_cast<double>(stamp_ns),
             t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
}

}  // namespace

struct Pipeline::Impl {
  Impl(const config::Config& c, const PipelineOptions& o)
      : config(c),
        options(o),
        overflow(c.lidar.source == config::LidarSource::udp ? Overflow::drop_oldest : Overflow::wait),
        packets(kPacketSlots, overflow, [] { return Packet{}; }),
        extrinsic(isometry_of(c.lidar.extrinsics).cast<float>()),
        map(map_config_of(c.map)),
        eviction(eviction_config_of(c.map)),
        keyframe_selector({c.map.keyframe_distance_m, c.map.keyframe_angle_deg}) {
    options.odometry.min_range_m = static_cast<float>(c.lidar.min_range_m);
    options.odometry.max_range_m = static_cast<float>(c.lidar.max_range_m);
    const double speed = options.replay_speed >= 0.0 ? options.replay_speed : c.lidar.replay_speed;

    if (c.lidar.source == config::LidarSource::scan_dir) {
      scan_directory.emplace(c.lidar.scan_dir);
    } else {
      if (c.lidar.source == config::LidarSource::pcap) pcap.emplace(c.lidar.pcap, speed);
      const drivers::LidarFamily* family = drivers::lidar_family_of_model(c.lidar.model);
      if (family == nullptr) throw InputError("", "lidar.model", "no decoder for " + c.lidar.model);
      try {
        decoder = family->make_decoder(c.lidar.model, c.lidar.calibration);
      } catch (const InputError& e) {
        // The family speaks of its own inputs; name the configuration key.
        throw InputError(e.where().empty() ? c.lidar.calibration : e.where(), "lidar.calibration", e.reason());
      }
      data_port = c.lidar.port != 0 ? static_cast<std::uint16_t>(c.lidar.port) : decoder->default_port();
      if (c.lidar.source == config::LidarSource::udp) {
        drivers::UdpReceiverConfig udp_config;
        udp_config.bind_address = c.lidar.address;
        udp_config.port = data_port;
        udp_config.interface = c.lidar.interface;
        udp_config.multicast_group = c.lidar.multicast_group;
        udp_config.receive_buffer_bytes = c.lidar.receive_buffer_bytes;
        udp.emplace(udp_config);
      }
      // The packet period is learnt from the first packet by the family; 0 = by sequence only.
      assembler.emplace(drivers::assembler_config_for(*decoder, 0, static_cast<float>(c.lidar.scan_cut_azimuth_deg)));
      stream.emplace(*decoder, *assembler, [this](drivers::LidarScan& scan) { hand_on(scan); });
    }
    const std::size_t max_points =
        assembler ? assembler->config().max_points_per_scan : options.odometry.max_scan_points;
    options.odometry.max_scan_points = std::max(options.odometry.max_scan_points, max_points);
    scans.emplace(kScanSlots, overflow, [max_points] {
      ScanSlot slot;
      slot.scan.points.reserve(max_points);
      return slot;
    });
    odometry.emplace(options.odometry);
    if (c.can.enabled && c.wheel_odometry.enabled) wheels.emplace(c);
    if (options.mapping) {
      map_slots.emplace(kMapSlots, overflow, [max_points] {
        MapSlot slot;
        slot.points.reserve(max_points);
        slot.times_s.reserve(max_points);
        slot.intensities.reserve(max_points);
        return slot;
      });
      map_points.reserve(max_points);
      map_times.reserve(max_points);
      map_intensities.reserve(max_points);
      map_deskewed.reserve(max_points);
      pending.points.reserve(max_points);
      pending.times_s.reserve(max_points);
      pending.intensities.reserve(max_points);
      keyframe_points.reserve(max_points);
      if (c.map.refine) {
        slam::MapRefinerConfig refine;
        refine.max_scan_points = max_points;
        refiner.emplace(refine);
      }
      keyframe_downsampler.emplace(max_points);
    }
    body_points.reserve(options.odometry.max_scan_points);
    body_times.reserve(options.odometry.max_scan_points);
    timings.odometry_ms.reserve(kTimingCapacity);
    timings.latency_ms.reserve(kTimingCapacity);
    open_files(options.trajectory_file, options.map_trajectory_file, options.record_file);
  }

  void open_files(const std::filesystem::path& trajectory_file, const std::filesystem::path& map_trajectory_file,
                  const std::filesystem::path& record_file) {
    if (!record_file.empty()) {
      if (!udp && !pcap)
        throw InputError(record_file.string(), "session.record_lidar", "only packet sources can be recorded");
      if (record_file.has_parent_path()) std::filesystem::create_directories(record_file.parent_path());
      recorder.emplace(record_file);
    }
    if (!trajectory_file.empty()) {
      if (trajectory_file.has_parent_path()) std::filesystem::create_directories(trajectory_file.parent_path());
      trajectory.reset(std::fopen(trajectory_file.c_str(), "w"));
      if (!trajectory) throw InputError(trajectory_file.string(), "", "cannot write the trajectory");
    }
    if (!map_trajectory_file.empty()) {
      if (map_trajectory_file.has_parent_path()) std::filesystem::create_directories(map_trajectory_file.parent_path());
      map_trajectory.reset(std::fopen(map_trajectory_file.c_str(), "w"));
      if (!map_trajectory) throw InputError(map_trajectory_file.string(), "", "cannot write the map's trajectory");
    }
  }

  // Assembly thread: a finished scan goes to odometry (swapped, not copied).
  void hand_on(drivers::LidarScan& scan) {
    stats.scans.fetch_add(1, std::memory_order_relaxed);
    if (stream) {
      if (const auto clock = stream->clock().estimate())
        stats.clock_offset_ns.store(clock->offset_ns, std::memory_order_relaxed);
    }
    if (!scan.stats.complete) stats.incomplete_scans.fetch_add(1, std::memory_order_relaxed);
    ScanSlot* slot = nullptr;
    while ((slot = scans->acquire()) == nullptr && !stop.load(std::memory_order_relaxed)) {
      assembly_beat.beat();
      wait_a_little();
    }
    if (slot == nullptr) return;
    std::swap(slot->scan, scan);
    slot->last_packet_mono_ns = current_packet_mono_ns;
    scans->publish(slot);
  }

  void receiver_loop() {
    settle_thread("adit-receiver", config.threads.receiver);
    if (scan_directory) return scan_directory_loop();
    const auto push = [this](std::span<const std::uint8_t> payload, std::int64_t time_ns, std::uint32_t src_ip,
                             std::uint16_t src_port) {
      Packet* packet = nullptr;
      while ((packet = packets.acquire()) == nullptr) {  // replay: wait for assembly
        if (stop.load(std::memory_order_relaxed)) return;
        receiver_beat.beat();
        wait_a_little();
      }
      packet->host_time_ns = time_ns;
      packet->src_ip = src_ip;
      packet->src_port = src_port;
      packet->size = static_cast<std::uint32_t>(std::min(payload.size(), kMaxDatagram));
      std::memcpy(packet->data.data(), payload.data(), packet->size);
      packet->received_mono_ns = monotonic_ns();
      stats.last_packet_realtime_ns.store(realtime_ns(), std::memory_order_relaxed);
      if (recorder) {
        // Buffered file output on the receiver: a copy and no allocation per packet.
        const drivers::UdpEndpoints endpoints{src_ip, 0xFFFFFFFF, src_port, data_port};
        if (recorder->write_udp(time_ns > 0 ? time_ns : realtime_ns(), endpoints, payload))
          stats.recorded_datagrams.fetch_add(1, std::memory_order_relaxed);
      }
      packets.publish(packet);
    };
    if (pcap) {
      drivers::UdpDatagram d;
      while (!stop.load(std::memory_order_relaxed) && !source_stop.load(std::memory_order_relaxed) && pcap->next(d)) {
        receiver_beat.beat();
        stats.datagrams.fetch_add(1, std::memory_order_relaxed);
        if (d.dst_port != data_port) {
          stats.foreign_datagrams.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        push(d.payload, d.capture_time_ns, d.src_ip, d.src_port);
      }
    } else {
      // A pipeline built ahead of its session (Sessions keeps one ready) finds
      // old packets in the socket's buffer: they belong to no session.
      for (auto batch = udp->receive(0); !batch.empty(); batch = udp->receive(0))
        stats.stale_datagrams.fetch_add(batch.size(), std::memory_order_relaxed);
      while (!stop.load(std::memory_order_relaxed) && !source_stop.load(std::memory_order_relaxed)) {
        receiver_beat.beat();
        for (const drivers::ReceivedDatagram& d : udp->receive(100)) {
          stats.datagrams.fetch_add(1, std::memory_order_relaxed);
          push(d.payload, d.kernel_time_ns, d.src_ip, d.src_port);
        }
      }
    }
    if (recorder) {
      try {
        recorder->flush();
      } catch (const InputError& e) {
        log::error("{}: {}", e.where(), e.reason());
      }
    }
    source_done.store(true, std::memory_order_release);
    receiver_beat.finished.store(true);
  }

  void scan_directory_loop() {
    drivers::LidarScan scan;
    scan.points.reserve(options.odometry.max_scan_points);
    while (!stop.load(std::memory_order_relaxed) && !source_stop.load(std::memory_order_relaxed) &&
           scan_directory->next(scan)) {
      receiver_beat.beat();
      current_packet_mono_ns = monotonic_ns();
      hand_on(scan);
    }
    source_done.store(true, std::memory_order_release);
    assembly_done.store(true, std::memory_order_release);
    receiver_beat.finished.store(true);
    assembly_beat.finished.store(true);
  }

  void assembly_loop() {
    settle_thread("adit-assembly", config.threads.receiver);
    if (scan_directory) return;
    while (!stop.load(std::memory_order_relaxed)) {
      assembly_beat.beat();
      Packet* packet = packets.take();
      if (packet == nullptr) {
        if (source_done.load(std::memory_order_acquire) && packets.depth() == 0) break;
        wait_a_little();
        continue;
      }
      current_packet_mono_ns = packet->received_mono_ns;
      stream->push(std::span<const std::uint8_t>(packet->data.data(), packet->size), packet->host_time_ns);
      packets.release(packet);
    }
    if (!stop.load()) stream->finish();
    stats.bad_packets.store(stream->bad_packets());
    stats.dropped_packets.store(packets.dropped());
    assembly_done.store(true, std::memory_order_release);
    assembly_beat.finished.store(true);
  }

  void odometry_loop() {
    settle_thread("adit-odometry", config.threads.odometry);
    while (!stop.load(std::memory_order_relaxed)) {
      odometry_beat.beat();
      ScanSlot* slot = scans->take();
      if (slot == nullptr) {
        if (assembly_done.load(std::memory_order_acquire) && scans->depth() == 0) break;
        wait_a_little();
        continue;
      }
      // Sensor frame → body frame, and firing offsets in seconds.
      body_points.clear();
      body_times.clear();
      for (const drivers::LidarPoint& p : slot->scan.points) {
        body_points.push_back(extrinsic * Eigen::Vector3f(p.x, p.y, p.z));
        body_times.push_back(1e-9F * static_cast<float>(p.time_offset_ns));
      }
      float sweep_s = 0.0F;
      for (const float t : body_times) sweep_s = std::max(sweep_s, t);
      const std::optional<slam::MotionPrior> prior = wheel_prior_for(slot->scan.start_time_ns, sweep_s);
      const std::optional<slam::UpMeasurement> up = up_for(slot->scan.start_time_ns, sweep_s);
      const std::int64_t t0 = monotonic_ns();
      const slam::OdometryResult result =
          odometry->process({slot->scan.start_time_ns, body_points, body_times, up}, prior);
      const std::int64_t t1 = monotonic_ns();
      if (timings.odometry_ms.size() < kTimingCapacity) timings.odometry_ms.push_back(1e-6 * static_cast<double>(t1 - t0));
      if (first_stamp_ns == 0) first_stamp_ns = slot->scan.start_time_ns;
      last_stamp_ns = slot->scan.start_time_ns;

      PoseSlot* out = nullptr;
      while ((out = poses->acquire()) == nullptr && !stop.load(std::memory_order_relaxed)) {
        odometry_beat.beat();
        wait_a_little();
      }
      if (out != nullptr) {
        out->result = result;
        out->last_packet_mono_ns = slot->last_packet_mono_ns;
        out->pose_mono_ns = monotonic_ns();
        poses->publish(out);
      }
      if (map_slots && result.valid) hand_to_mapping(slot->scan, result);
      scans->release(slot);
    }
    stats.dropped_scans.store(scans->dropped());
    odometry_done.store(true, std::memory_order_release);
    odometry_beat.finished.store(true);
  }

  // Odometry thread: the wheels' motion since the previous scan, or nullopt
  // (then odometry predicts with constant velocity). A replayed CAN log is
  // waited for, so a replay as fast as possible still gets its priors.
  // The samples are taken up to the sweep's end and a little past it, for
  // the accelerometer's mean over the sweep and the wheels' speed there.
  std::optional<slam::MotionPrior> wheel_prior_for(std::int64_t stamp_ns, float sweep_s) {
    if (!wheels) return std::nullopt;
    const double t = 1e-9 * static_cast<double>(stamp_ns);
    const double until = t + sweep_s + kSpeedHalfWindow_s;
    ImuHistory* imu = config.imu.enabled ? &imu_history : nullptr;
    wheels->drain_into(wheel_history, until, imu);
    while (wheels->replay() && wheel_history.latest() < until && !wheels->finished() &&
           !stop.load(std::memory_order_relaxed)) {
      odometry_beat.beat();
      wait_a_little();
      wheels->drain_into(wheel_history, until, imu);
    }
    wheels->drain_into(wheel_history, until, imu);  // what the feed handed over just before it finished
    const double previous = previous_odometry_stamp_s;
    previous_odometry_stamp_s = t;
    if (previous <= 0.0) return std::nullopt;
    std::optional<slam::MotionPrior> prior = wheel_history.prior(previous, t);
    (prior ? stats.wheel_priors : stats.scans_without_wheels).fetch_add(1, std::memory_order_relaxed);
    return prior;
  }

  // Odometry thread, after wheel_prior_for: gravity's up in the body frame
  // over the sweep, from the accelerometer's mean with the wheels' kinematic
  // acceleration removed (slam/gravity.hpp), or nullopt.
  std::optional<slam::UpMeasurement> up_for(std::int64_t stamp_ns, float sweep_s) {
    if (!wheels || !config.imu.enabled) return std::nullopt;
    const double t0 = 1e-9 * static_cast<double>(stamp_ns);
    const double t1 = t0 + std::max(sweep_s, 0.01F);
    const std::optional<Eigen::Vector3d> force = imu_history.mean(t0, t1);
    const std::optional<Eigen::Vector3d> acceleration = wheel_history.acceleration(t0, t1, kSpeedHalfWindow_s);
    std::optional<slam::UpMeasurement> up;
    if (force && acceleration) up = slam::measured_up(*force, *acceleration, gravity_sigma_rad);
    (up ? stats.gravity_priors : stats.scans_without_gravity).fetch_add(1, std::memory_order_relaxed);
    return up;
  }

  // Odometry thread: copies (no allocation: the slot's buffers are reserved).
  void hand_to_mapping(const drivers::LidarScan& scan, const slam::OdometryResult& result) {
    MapSlot* m = nullptr;
    while ((m = map_slots->acquire()) == nullptr && !stop.load(std::memory_order_relaxed)) {
      odometry_beat.beat();
      wait_a_little();
    }
    if (m == nullptr) return;
    m->stamp_ns = result.stamp_ns;
    m->pose = result.pose;
    m->valid = result.valid;
    m->points.assign(body_points.begin(), body_points.end());
    m->times_s.assign(body_times.begin(), body_times.end());
    m->intensities.clear();
    for (const drivers::LidarPoint& p : scan.points) m->intensities.push_back(p.intensity);
    map_slots->publish(m);
  }

  // Mapping thread. A scan spans the time from its pose to the next scan's
  // pose, so it is mapped one scan late: deskewed with the corrected motion
  // over its own sweep, pose_k⁻¹·pose_k+1 (odometry could only deskew with
  // the prediction), then added to the tiled map; keyframes; changed tiles go
  // to the sink at most once per period.
  void mapping_loop() {
    settle_thread("adit-mapping", config.threads.mapping);
    const auto period_ns = static_cast<std::int64_t>(config.map.publish_period_s * 1e9);
    std::int64_t last_flush_ns = monotonic_ns();
    while (!stop.load(std::memory_order_relaxed)) {
      mapping_beat.beat();
      const std::int64_t now = monotonic_ns();
      if (now - last_flush_ns >= period_ns) {
        flush_tiles();
        last_flush_ns = now;
      }
      MapSlot* slot = map_slots->take();
      if (slot == nullptr) {
        if (odometry_done.load(std::memory_order_acquire) && map_slots->depth() == 0) break;
        wait_a_little();
        continue;
      }
      if (have_pending) {
        const double dt = 1e-9 * static_cast<double>(slot->stamp_ns - pending.stamp_ns);
        // After a gap the next pose says nothing of this sweep: keep the last motion.
        if (dt > 0.0 && dt <= options.odometry.max_scan_gap_s)
          map_velocity = slam::log_se3(pending.pose.inverse() * slot->pose) / dt;
        map_scan(pending, map_velocity);
      }
      // The slot's buffers and the pending ones have the same capacity: swap, no copy.
      std::swap(pending, *slot);
      have_pending = true;
      map_slots->release(slot);
    }
    if (have_pending && !stop.load()) map_scan(pending, map_velocity);  // the last sweep: the last motion known
    have_pending = false;
    flush_tiles();
    if (map_trajectory) std::fflush(map_trajectory.get());
    stats.map_bytes.store(map.memory_bytes(), std::memory_order_relaxed);
    stats.dropped_map_scans.store(map_slots->dropped());
    mapping_beat.finished.store(true);
  }

  void map_scan(const MapSlot& slot, const slam::Vector6d& velocity) {
    map_points.clear();
    map_times.clear();
    map_intensities.clear();
    const float min2 = options.odometry.min_range_m * options.odometry.min_range_m;
    const float max_range = std::min(options.odometry.max_range_m, static_cast<float>(config.map.max_range_m));
    const float max2 = max_range * max_range;
    const bool timed = slot.times_s.size() == slot.points.size();
    for (std::size_t i = 0; i < slot.points.size(); ++i) {
      const float r2 = slot.points[i].squaredNorm();
      if (!std::isfinite(r2) || r2 < min2 || r2 > max2) continue;
      map_points.push_back(slot.points[i]);
      map_times.push_back(timed ? slot.times_s[i] : 0.0F);
      map_intensities.push_back(i < slot.intensities.size() ? slot.intensities[i] : 0.0F);
    }
    map_deskewed.resize(map_points.size());
    map_deskewer.deskew(map_points, map_times, velocity, map_deskewed);
    // The map's pose of the scan: the odometry's, refined against the map of
    // the scans before it (slam::MapRefiner says why).
    const Eigen::Isometry3d map_pose = refiner ? refiner->refine(slot.pose, map_deskewed) : slot.pose;
    if (map_trajectory) write_tum_line(map_trajectory.get(), slot.stamp_ns, map_pose);
    const bool keyframe = keyframe_selector.take(map_pose);
    if (keyframe) {
      keyframe_downsampler->downsample(map_deskewed, static_cast<float>(config.map.keyframe_voxel_m), keyframe_points);
      keyframe_list.push_back({slot.stamp_ns, map_pose, keyframe_points});
      keyframe_bytes += sizeof(slam::Keyframe) + keyframe_list.back().points.capacity() * sizeof(Eigen::Vector3f);
      stats.keyframes.store(keyframe_list.size(), std::memory_order_relaxed);
      stats.keyframe_bytes.store(keyframe_bytes, std::memory_order_relaxed);
    }
    const Eigen::Isometry3f pose = map_pose.cast<float>();
    for (Eigen::Vector3f& p : map_deskewed) p = pose * p;
    if (spill) restore_tiles(map.evicted_hit_by(map_deskewed));
    map.add(map_deskewed, map_intensities, 1e-9 * static_cast<double>(slot.stamp_ns));
    if (spill && keyframe) {
      const std::vector<slam::TileCoord> cold = eviction.cold_tiles(map, map_pose.translation().cast<float>());
      const std::vector<slam::TileCoord> crowded = eviction.crowded_tiles(map);
      evict_tiles(cold);
      compact_tiles(crowded);
#ifdef __GLIBC__
      // The freed tiles lie amid the mapping thread's arena, which glibc gives
      // back to the kernel only from its top: return the free pages now.
      if (!cold.empty() || !crowded.empty()) malloc_trim(0);
#endif
    }
    if (!keyframes_dir.empty() && keyframe) spill_keyframes();
    stats.mapped_scans.fetch_add(1, std::memory_order_relaxed);
    stats.map_points.store(map.size(), std::memory_order_relaxed);
    stats.map_tiles.store(map.tile_count(), std::memory_order_relaxed);
    stats.resident_tiles.store(map.resident_tile_count(), std::memory_order_relaxed);
    stats.dropped_in_evicted.store(map.dropped_in_evicted(), std::memory_order_relaxed);
    if (keyframe) stats.map_bytes.store(map.memory_bytes(), std::memory_order_relaxed);  // a walk over the tiles
  }

  // Mapping thread: the scans of all but the newest kKeyframeScansInRam
  // keyframes go to the session folder; their poses stay. Loop closure looks
  // for old keyframes, and reads their scans back then. A 30-minute drive
  // keeps ~1800 keyframes of ~50 kB each; a radius rule would not bound them
  // on a route that keeps coming back to the same drifts.
  void spill_keyframes() {
    for (; keyframes_in_ram_from + kKeyframeScansInRam < keyframe_list.size(); ++keyframes_in_ram_from) {
      slam::Keyframe& k = keyframe_list[keyframes_in_ram_from];
      std::vector<protocol::MapPoint> points;
      points.reserve(k.points.size());
      for (const Eigen::Vector3f& p : k.points) points.push_back({p.x(), p.y(), p.z(), 0.0F, 0.0});
      try {
        std::filesystem::create_directories(keyframes_dir);
        protocol::write_map(keyframes_dir / fmt::format("{}.ply", k.stamp_ns), protocol::MapFormat::ply, points);
      } catch (const std::exception& e) {  // kept in RAM then
        if (stats.tile_file_errors.fetch_add(1, std::memory_order_relaxed) == 0) log::error("mapping: {}", e.what());
        continue;
      }
      keyframe_bytes -= k.points.capacity() * sizeof(Eigen::Vector3f);
      std::vector<Eigen::Vector3f>().swap(k.points);
      stats.spilled_keyframes.fetch_add(1, std::memory_order_relaxed);
    }
    stats.keyframe_bytes.store(keyframe_bytes, std::memory_order_relaxed);
  }

  // The whole tiles these functions read back or write (compact, evict,
  // restore, flush) live in a buffer local to each call, freed on return: a
  // buffer kept as a member held the capacity of the largest tile of the
  // session (24 B a point), resident between uses, and grew with the map
  // (+28 MB in steps over the 30-minute simulated drive).
  //
  // Mapping thread: a tile holding too many voxels in RAM is written out,
  // evicted and restored at once: its points go to its file and only a bit
  // per voxel stays (unconfirmed voxels are lost, as on eviction).
  void compact_tiles(const std::vector<slam::TileCoord>& coords) {
    std::vector<slam::MapSample> tile_buffer;  // whole tiles, freed on return (see compact_tiles)
    for (const slam::TileCoord& coord : coords) {
      std::string problem = spill->whole_tile(map, coord, tile_buffer);
      if (problem.empty()) problem = spill->write(coord, tile_buffer);
      if (!problem.empty()) {
        if (stats.tile_file_errors.fetch_add(1, std::memory_order_relaxed) == 0) log::error("mapping: {}", problem);
        continue;
      }
      if (map.evict(coord).changed && options.sinks.tile) options.sinks.tile(coord, tile_buffer);
      map.restore(coord, tile_buffer);
      stats.compacted_tiles.fetch_add(1, std::memory_order_relaxed);
    }
    stats.lost_candidates.store(map.lost_candidates(), std::memory_order_relaxed);
  }

  // Mapping thread: the sensor has come back to tiles it had left; they are
  // read back, so the scan continues them instead of starting copies. A tile
  // that cannot be read stays evicted (its file intact) and add() skips the
  // points that fall into it (counted).
  void restore_tiles(const std::vector<slam::TileCoord>& coords) {
    std::vector<slam::MapSample> tile_buffer;  // whole tiles, freed on return (see compact_tiles)
    for (const slam::TileCoord& coord : coords) {
      if (const std::string problem = spill->read(coord, tile_buffer); !problem.empty()) {
        if (stats.tile_file_errors.fetch_add(1, std::memory_order_relaxed) == 0) log::error("mapping: {}", problem);
        continue;
      }
      map.restore(coord, tile_buffer);
      stats.restored_tiles.fetch_add(1, std::memory_order_relaxed);
    }
  }

  // Mapping thread: tiles the sensor has left are written to the session's
  // tiles/ folder and leave RAM. A tile whose last change was not published
  // yet goes to the sink first. A tile that cannot be written stays in RAM.
  // A restored tile's file holds its stored part: it is rewritten with the new
  // points appended, or left as it is when nothing is new.
  void evict_tiles(const std::vector<slam::TileCoord>& coords) {
    std::vector<slam::MapSample> tile_buffer;  // whole tiles, freed on return (see compact_tiles)
    for (const slam::TileCoord& coord : coords) {
      const bool restored = map.stored_points(coord) > 0;
      if (!restored || !map.tile(coord).empty()) {
        std::string problem = spill->whole_tile(map, coord, tile_buffer);
        if (problem.empty()) problem = spill->write(coord, tile_buffer);
        if (!problem.empty()) {
          if (stats.tile_file_errors.fetch_add(1, std::memory_order_relaxed) == 0) log::error("mapping: {}", problem);
          continue;
        }
      }
      if (map.evict(coord).changed && options.sinks.tile && spill->whole_tile(map, coord, tile_buffer).empty())
        options.sinks.tile(coord, tile_buffer);
      stats.evicted_tiles.fetch_add(1, std::memory_order_relaxed);
    }
    stats.lost_candidates.store(map.lost_candidates(), std::memory_order_relaxed);
  }

  // A restored tile's whole content is its stored part (read back) and what
  // is new: decoding it costs a few ms per changed tile and period.
  void flush_tiles() {
    const std::vector<slam::TileCoord> changed = map.take_changed();
    if (!options.sinks.tile) return;
    std::vector<slam::MapSample> tile_buffer;  // whole tiles, freed on return (see compact_tiles)
    for (const slam::TileCoord& coord : changed) {
      if (!spill || map.stored_points(coord) == 0) {
        options.sinks.tile(coord, map.tile(coord));
      } else if (const std::string problem = spill->whole_tile(map, coord, tile_buffer); problem.empty()) {
        options.sinks.tile(coord, tile_buffer);
      } else if (stats.tile_file_errors.fetch_add(1, std::memory_order_relaxed) == 0) {
        log::error("mapping: {}", problem);
      }
    }
  }

  void output_loop() {
    settle_thread("adit-output", config.threads.publisher);
    while (!stop.load(std::memory_order_relaxed)) {
      output_beat.beat();
      PoseSlot* slot = poses->take();
      if (slot == nullptr) {
        if (odometry_done.load(std::memory_order_acquire) && poses->depth() == 0) break;
        wait_a_little();
        continue;
      }
      const slam::OdometryResult& r = slot->result;
      stats.poses.fetch_add(1, std::memory_order_relaxed);
      if (!r.valid) stats.invalid_poses.fetch_add(1, std::memory_order_relaxed);
      if (r.status == slam::OdometryStatus::degenerate) stats.degenerate_poses.fetch_add(1, std::memory_order_relaxed);
      if (timings.latency_ms.size() < kTimingCapacity)
        timings.latency_ms.push_back(1e-6 * static_cast<double>(slot->pose_mono_ns - slot->last_packet_mono_ns));
      if (options.sinks.pose) options.sinks.pose(r);
      if (trajectory && r.valid) write_tum_line(trajectory.get(), r.stamp_ns, r.pose);
      poses->release(slot);
    }
    if (trajectory) std::fflush(trajectory.get());
    output_beat.finished.store(true);
  }

  void settle_thread(std::string_view name, const config::ThreadSettings& settings) {
    auto w = apply_thread_settings(name, settings);
    const std::lock_guard lock(warnings_mutex);  // once per thread at start, never on the hot path
    warnings.insert(warnings.end(), w.begin(), w.end());
  }

  config::Config config;
  PipelineOptions options;
  Overflow overflow;
  std::unique_ptr<drivers::LidarDecoder> decoder;
  std::uint16_t data_port = 0;
  std::optional<drivers::PacedPcapReader> pcap;
  std::optional<drivers::UdpReceiver> udp;
  std::optional<drivers::ScanDirectorySource> scan_directory;
  std::optional<drivers::ScanAssembler> assembler;
  std::optional<drivers::DecodeStream> stream;
  Handoff<Packet> packets;
  std::optional<Handoff<ScanSlot>> scans;
  std::optional<Handoff<PoseSlot>> poses{std::in_place, kPoseSlots, Overflow::wait, [] { return PoseSlot{}; }};
  std::optional<slam::Odometry> odometry;
  Eigen::Isometry3f extrinsic;
  std::optional<drivers::PcapWriter> recorder;
  std::optional<WheelFeed> wheels;
  WheelHistory wheel_history{8192};       // odometry thread only: 80 s at 100 Hz
  ImuHistory imu_history{4096};           // odometry thread only: 40 s at 100 Hz
  const double gravity_sigma_rad = config.imu.gravity_sigma_deg * std::numbers::pi / 180.0;
  static constexpr double kSpeedHalfWindow_s = 0.05;  // the wheels' speed: central differences over ±50 ms
  double previous_odometry_stamp_s = 0.0;  // odometry thread only
  std::optional<Handoff<MapSlot>> map_slots;
  // Mapping thread only:
  slam::TiledVoxelMap map;
  slam::TileEviction eviction;
  std::optional<TileSpill> spill;          // set by start() when the session has a tiles folder
  std::uint64_t keyframe_bytes = 0;
  std::filesystem::path keyframes_dir;  // set by start(); empty = keyframe scans stay in RAM
  std::size_t keyframes_in_ram_from = 0;  // keyframes before this one had their scans written out
  slam::KeyframeSelector keyframe_selector;
  std::vector<slam::Keyframe> keyframe_list;
  std::optional<slam::VoxelDownsampler> keyframe_downsampler;
  slam::Deskewer map_deskewer;
  std::optional<slam::MapRefiner> refiner;  // with map.refine
  std::vector<Eigen::Vector3f> map_points;
  std::vector<float> map_times;
  std::vector<float> map_intensities;
  std::vector<Eigen::Vector3f> map_deskewed;
  std::vector<Eigen::Vector3f> keyframe_points;
  MapSlot pending;        // the scan waiting for the next pose
  bool have_pending = false;
  slam::Vector6d map_velocity = slam::Vector6d::Zero();
  std::vector<Eigen::Vector3f> body_points;
  std::vector<float> body_times;
  std::int64_t current_packet_mono_ns = 0;  // assembly thread only
  std::int64_t first_stamp_ns = 0;          // odometry thread only
  std::int64_t last_stamp_ns = 0;
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, FileCloser> trajectory;
  std::unique_ptr<std::FILE, FileCloser> map_trajectory;  // mapping thread

  PipelineStats stats;
  PipelineTimings timings;
  Heartbeat receiver_beat{"receiver"};
  Heartbeat assembly_beat{"assembly"};
  Heartbeat odometry_beat{"odometry"};
  Heartbeat output_beat{"output"};
  Heartbeat mapping_beat{"mapping"};
  std::atomic<bool> stop{false};
  std::atomic<bool> source_stop{false};
  std::atomic<bool> source_done{false};
  std::atomic<bool> assembly_done{false};
  std::atomic<bool> odometry_done{false};
  std::mutex warnings_mutex;
  std::vector<std::string> warnings;
  std::vector<std::thread> threads;
  std::int64_t started_ns = 0;
};

Pipeline::Pipeline(const config::Config& config, const PipelineOptions& options)
    : impl_(std::make_unique<Impl>(config, options)) {}

Pipeline::~Pipeline() {
  request_stop();
  join();
}

void Pipeline::start(const SessionFiles& files) {
  Impl& i = *impl_;
  if (!i.threads.empty()) throw std::logic_error("Pipeline::start called twice");
  i.open_files(files.trajectory_file, files.map_trajectory_file, files.record_file);
  if (!files.tiles_dir.empty() && i.config.map.evict_after_keyframes > 0) {
    i.spill.emplace(files.tiles_dir, stored_tile_params(i.config.map.tile_size_m));
  }
  if (i.config.map.evict_after_keyframes > 0) i.keyframes_dir = files.keyframes_dir;
  if (i.wheels) i.wheels->start(files.can_record_file);
  if (i.config.threads.lock_memory) {
    auto w = lock_memory();
    i.warnings.insert(i.warnings.end(), w.begin(), w.end());
  }
  i.started_ns = monotonic_ns();
  if (i.map_slots) i.threads.emplace_back([&i] { i.mapping_loop(); });
  i.threads.emplace_back([&i] { i.output_loop(); });
  i.threads.emplace_back([&i] { i.odometry_loop(); });
  i.threads.emplace_back([&i] { i.assembly_loop(); });
  i.threads.emplace_back([&i] { i.receiver_loop(); });
}

void Pipeline::request_stop() { impl_->stop.store(true, std::memory_order_release); }
void Pipeline::end_source() { impl_->source_stop.store(true, std::memory_order_release); }

void Pipeline::join() {
  Impl& i = *impl_;
  for (std::thread& t : i.threads)
    if (t.joinable()) t.join();
  if (i.wheels) i.wheels->stop();
  if (!i.threads.empty()) {
    i.timings.duration_s = 1e-9 * static_cast<double>(monotonic_ns() - i.started_ns);
    i.timings.sensor_span_s = 1e-9 * static_cast<double>(i.last_stamp_ns - i.first_stamp_ns);
    i.threads.clear();
  }
}

bool Pipeline::drained() const {
  return impl_->output_beat.finished.load(std::memory_order_acquire) &&
         (!impl_->map_slots || impl_->mapping_beat.finished.load(std::memory_order_acquire));
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

const PipelineStats& Pipeline::stats() const { return impl_->stats; }
const PipelineTimings& Pipeline::timings() const { return impl_->timings; }
std::vector<const Heartbeat*> Pipeline::heartbeats() const {
  std::vector<const Heartbeat*> beats{&impl_->receiver_beat, &impl_->assembly_beat, &impl_->odometry_beat,
                                      &impl_->output_beat};
  if (impl_->map_slots) beats.push_back(&impl_->mapping_beat);
  if (impl_->wheels) beats.push_back(&impl_->wheels->heartbeat());
  return beats;
}

std::vector<StageLoad> Pipeline::loads() const {
  Impl& i = *impl_;
  std::vector<StageLoad> out;
  if (i.threads.empty()) return out;
  // Threads were started in this order: [mapping,] output, odometry, assembly, receiver.
  const std::size_t first = i.map_slots ? 1 : 0;
  const auto cpu = [&](std::size_t k) { return k < i.threads.size() ? thread_cpu_s(i.threads[k]) : 0.0; };
  out.push_back({"receiver", cpu(first + 3), 0, 0});
  out.push_back({"assembly", cpu(first + 2), i.packets.depth(), i.packets.capacity()});
  out.push_back({"odometry", cpu(first + 1), i.scans->depth(), i.scans->capacity()});
  out.push_back({"output", cpu(first), i.poses->depth(), i.poses->capacity()});
  if (i.map_slots) out.push_back({"mapping", cpu(0), i.map_slots->depth(), i.map_slots->capacity()});
  return out;
}

const slam::TiledVoxelMap& Pipeline::map() const { return impl_->map; }
const TileSpill* Pipeline::tile_spill() const { return impl_->spill ? &*impl_->spill : nullptr; }
const std::vector<slam::Keyframe>& Pipeline::keyframes() const { return impl_->keyframe_list; }
std::vector<std::string> Pipeline::warnings() const {
  const std::lock_guard lock(impl_->warnings_mutex);
  return impl_->warnings;
}

}  // namespace adit::daemon
