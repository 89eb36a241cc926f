#include "adit/sim/livox_lidar.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"

namespace adit::sim {
namespace {
constexpr std::size_t kPoints = drivers::kLivoxMid360PointsPerPacket;
}  // namespace

Eigen::Vector3d livox_direction(const LivoxPattern& p, std::uint64_t index) {
  const auto lasers = static_cast<std::uint64_t>(p.lasers);
  const std::uint64_t laser = index % lasers;
  const double t = static_cast<double>(index) / p.points_per_s;
  const double turn = 2.0 * std::numbers::pi * (p.turn_hz * t + static_cast<double>(laser) / static_cast<double>(lasers));
  const double phase = 2.0 * std::numbers::pi * (p.sweep_hz * t + 0.618 * static_cast<double>(laser));
  const double el_deg =
      p.min_elevation_deg + (p.max_elevation_deg - p.min_elevation_deg) * 0.5 * (1.0 - std::cos(phase));
  const double el = el_deg * std::numbers::pi / 180.0;
  return {std::cos(el) * std::cos(turn), std::cos(el) * std::sin(turn), std::sin(el)};
}

Eigen::Isometry3d livox_mid360_imu_in_sensor() {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  const std::array<double, 3> p = drivers::livox_imu_position_m(drivers::LivoxModel::mid360);
  e.translation() = Eigen::Vector3d(p[0], p[1], p[2]);  // the one figure aditd's LivoxImu mounts it by
  return e;
}

LivoxSimStats simulate_livox_lidar(const LivoxPattern& pattern, const BodyTrack& body, const RayCaster& caster,
                                   const TriangleMesh& mesh, std::span<const Target> targets, const People& people,
                                   const LivoxSimOptions& o, drivers::PcapWriter& pcap,
                                   const std::function<void(std::int64_t)>& before_packet) {
  const auto point_ns = static_cast<std::int64_t>(std::llround(1e9 / pattern.points_per_s));  // 5 000 ns
  const std::int64_t packet_ns = point_ns * static_cast<std::int64_t>(kPoints);
  const auto packets = static_cast<std::uint64_t>(body.duration() * 1e9 / static_cast<double>(packet_ns));
  const auto far = static_cast<float>(o.effects.max_range_m + 1.0);
  const SensorNoise noise(o.seed);
  std::array<Eigen::Vector3f, kPoints> origins, directions;
  std::array<Eigen::Vector3d, kPoints> local;
  std::array<Hit, kPoints> hits;
  std::array<drivers::LivoxRawPoint, kPoints> raw;
  std::vector<std::uint8_t> bytes(drivers::livox_sdk2_point_packet_bytes(kPoints));
  drivers::UdpEndpoints endpoints;
  endpoints.src_port = 56300;
  endpoints.dst_port = drivers::kLivoxMid360PointPort;
  LivoxSimStats stats;
  for (std::uint64_t k = 0; k < packets; ++k) {
    const std::int64_t first_ns = static_cast<std::int64_t>(k) * packet_ns;
    const double t0 = static_cast<double>(first_ns) * 1e-9;
    const double t1 = static_cast<double>(first_ns + packet_ns - point_ns) * 1e-9;
    // The pose at the packet's first and last point; each point's is interpolated (480 µs apart).
    const Eigen::Isometry3d pose0 = body.pose(t0) * o.extrinsics;
    const Eigen::Isometry3d pose1 = body.pose(t1) * o.extrinsics;
    for (std::size_t i = 0; i < kPoints; ++i) {
      const double f = static_cast<double>(i) / static_cast<double>(kPoints - 1);
      const Eigen::Matrix3d rotation = pose0.linear() + f * (pose1.linear() - pose0.linear());
      local[i] = livox_direction(pattern, k * kPoints + i);
      origins[i] = (pose0.translation() + f * (pose1.translation() - pose0.translation())).cast<float>();
      directions[i] = (rotation * local[i]).normalized().cast<float>();
    }
    caster.intersect(origins, directions, 0.0F, far, hits);
    for (std::size_t i = 0; i < kPoints; ++i) {
      Hit& hit = hits[i];
      const double t = t0 + static_cast<double>(i) * static_cast<double>(point_ns) * 1e-9;
      if (!people.empty()) {
        const Hit person = people.intersect(origins[i], directions[i], 0.0F, hit.valid() ? hit.distance : far, t);
        if (person.valid()) hit = person;
      }
      const Return r = measure(o.effects, noise, k * kPoints + i, hit, origins[i], directions[i], mesh, targets);
      const bool kept = r.valid && r.range_m <= pattern.max_range_m;
      const Eigen::Vector3d xyz_mm = kept ? Eigen::Vector3d(local[i] * r.range_m * 1000.0) : Eigen::Vector3d::Zero();
      raw[i] = {static_cast<std::int32_t>(std::lround(xyz_mm.x())), static_cast<std::int32_t>(std::lround(xyz_mm.y())),
                static_cast<std::int32_t>(std::lround(xyz_mm.z())), kept ? r.reflectivity : std::uint8_t{0}, 0};
      stats.returns += kept ? 1 : 0;
    }
    drivers::LivoxSdk2PointPacket packet;
    packet.time_ns = o.start_time_ns + first_ns;
    packet.time_interval = static_cast<std::uint16_t>(packet_ns / 100);  // 0.1 µs
    packet.udp_cnt = static_cast<std::uint16_t>(k);
    packet.frame_cnt = static_cast<std::uint8_t>(k * static_cast<std::uint64_t>(packet_ns) / 100'000'000);
    packet.points = raw;
    drivers::encode_livox_sdk2_points(packet, bytes);
    const std::int64_t capture_ns = packet.time_ns + packet_ns + std::llround(o.capture_latency_s * 1e9);
    if (before_packet) before_packet(capture_ns);
    pcap.write_udp(capture_ns, endpoints, bytes);
    ++stats.packets;
  }
  stats.rays = stats.packets * kPoints;
  return stats;
}

}  // namespace adit::sim
