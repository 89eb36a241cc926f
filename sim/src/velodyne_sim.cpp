#include "adit/sim/velodyne_sim.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "adit/drivers/lidar/velodyne_encoder.hpp"

namespace adit::sim {
namespace {

using drivers::VelodyneDecoder;

struct Beam {  // one laser's geometry from the calibration
  double cos_v, sin_v, rot, vert_offset, horiz_offset;
};

constexpr std::size_t kChunk = 256;  // packets simulated between writes

}  // namespace

LidarSimStats simulate_velodyne(drivers::VelodyneModel model, const drivers::VelodyneCalibration& calibration,
                                const Trajectory& body, const RayCaster& caster, const TriangleMesh& mesh,
                                std::span<const Target> targets, const LidarSimOptions& o,
                                drivers::PcapWriter& pcap) {
  std::vector<Beam> beams;
  for (const auto& l : calibration.lasers) {
    beams.push_back({std::cos(l.vert_correction), std::sin(l.vert_correction), l.rot_correction,
                     l.vert_offset_correction, l.horiz_offset_correction});
  }
  const double resolution = calibration.distance_resolution_m > 0 ? calibration.distance_resolution_m
                                                                   : drivers::velodyne_distance_resolution_m(model);
  const std::size_t per_group = drivers::velodyne_blocks_per_group(model);
  const double group_s = drivers::velodyne_group_ns(model) * 1e-9;
  const std::int64_t period_ns = drivers::velodyne_packet_period_ns(model, drivers::VelodyneReturnMode::strongest);
  const auto packets = static_cast<std::uint64_t>(body.duration() * 1e9 / static_cast<double>(period_ns));
  const double turn_per_s = 2.0 * std::numbers::pi * o.rpm / 60.0;  // rad/s, clockwise seen from above

  // One packet, a pure function of its index.
  const auto simulate_packet = [&](std::uint64_t k, std::array<std::uint8_t, drivers::kVelodyneDataPacketSize>& out,
                                   std::uint64_t& returns) {
    drivers::VelodyneDataPacket packet;
    const std::int64_t packet_ns = static_cast<std::int64_t>(k) * period_ns;
    packet.us_past_hour = static_cast<std::uint32_t>(((o.start_time_ns + packet_ns) / 1000) % 3'600'000'000LL);
    for (std::size_t b = 0; b < VelodyneDecoder::kBlocks; ++b) {
      const double block_t = static_cast<double>(packet_ns) * 1e-9 + static_cast<double>(b / per_group) * group_s;
      auto& block = packet.blocks[b];
      const double block_azimuth = std::fmod(block_t * turn_per_s, 2.0 * std::numbers::pi);
      block.azimuth = static_cast<std::uint16_t>(std::lround(block_azimuth * 18000.0 / std::numbers::pi) % 36000);
      for (std::size_t c = 0; c < VelodyneDecoder::kChannels; ++c) {
        const auto firing = drivers::velodyne_firing(model, b % per_group, c);
        if (firing.laser >= beams.size()) continue;
        const double t = block_t + firing.time_ns * 1e-9;
        const Beam& beam = beams[firing.laser];
        // θ = azimuth − rotational correction; the azimuth turns clockwise, so y = −sin θ (decoder's convention).
        const double theta = t * turn_per_s - beam.rot;
        const double ct = std::cos(theta), st = std::sin(theta);
        const Eigen::Vector3d direction(beam.cos_v * ct, -beam.cos_v * st, beam.sin_v);
        const Eigen::Vector3d offset(-beam.vert_offset * beam.sin_v * ct + beam.horiz_offset * st,
                                     beam.vert_offset * beam.sin_v * st + beam.horiz_offset * ct,
                                     beam.vert_offset * beam.cos_v);
        const Eigen::Isometry3d sensor = body.pose(t) * o.extrinsics;
        const Eigen::Vector3f origin = (sensor * offset).cast<float>();
        const Eigen::Vector3f dir = (sensor.linear() * direction).cast<float>();
        const Hit hit = caster.intersect(origin, dir, 0.0F, static_cast<float>(o.effects.max_range_m + 1.0));
        const std::uint64_t ray = k * VelodyneDecoder::kMaxPoints + b * VelodyneDecoder::kChannels + c;
        const Return r = measure(o.effects, o.seed, ray, hit, origin, dir, mesh, targets);
        if (!r.valid) continue;
        const long raw = std::lround(r.range_m / resolution);
        if (raw <= 0 || raw > 0xFFFF) continue;
        block.distance[c] = static_cast<std::uint16_t>(raw);
        block.reflectivity[c] = r.reflectivity;
        ++returns;
      }
    }
    drivers::encode_velodyne_packet(model, packet, out);
  };

  LidarSimStats stats;
  const int threads = std::max(1, o.threads);
  std::vector<std::array<std::uint8_t, drivers::kVelodyneDataPacketSize>> buffer(kChunk);
  std::vector<std::uint64_t> returns(static_cast<std::size_t>(threads));
  const drivers::UdpEndpoints endpoints;
  for (std::uint64_t first = 0; first < packets; first += kChunk) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, packets - first));
    {
      // Interleaved packets per thread; each packet depends only on its index.
      std::vector<std::jthread> workers;
      for (int w = 0; w < threads; ++w) {
        workers.emplace_back([&, w] {
          for (std::size_t i = static_cast<std::size_t>(w); i < n; i += static_cast<std::size_t>(threads)) {
            simulate_packet(first + i, buffer[i], returns[static_cast<std::size_t>(w)]);
          }
        });
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::int64_t end_ns = static_cast<std::int64_t>(first + i + 1) * period_ns;
      pcap.write_udp(o.start_time_ns + end_ns + std::llround(o.capture_latency_s * 1e9), endpoints, buffer[i]);
    }
    stats.packets += n;
  }
  stats.rays = stats.packets * VelodyneDecoder::kMaxPoints;
  for (const std::uint64_t r : returns) stats.returns += r;
  return stats;
}

}  // namespace adit::sim
