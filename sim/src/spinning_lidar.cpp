#include "adit/sim/spinning_lidar.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <thread>

#include "adit/common/error.hpp"

namespace adit::sim {
namespace {

constexpr std::size_t kChunk = 256;  // packets simulated between writes

struct BeamTrig {  // Beam with its sines and cosines
  double cos_v, sin_v, offset, vo, ho, rx;
};

}  // namespace

SpinningSensor make_spinning_sensor(std::string_view model) {
  if (model == "VLP-16") return velodyne_vlp16_sensor();
  if (model == "RS-16") return robosense_rs16_sensor();
  if (model == "PandarXT32") return hesai_xt32_sensor();
  if (model == "OS1-64") return ouster_os1_64_sensor();
  throw InputError("adit sim", "--sensor",
                   "unsupported sensor '" + std::string(model) + "' (VLP-16, RS-16, PandarXT32, OS1-64)");
}

LidarSimStats simulate_spinning_lidar(const SpinningSensor& sensor, const Trajectory& body, const RayCaster& caster,
                                      const TriangleMesh& mesh, std::span<const Target> targets,
                                      const People& people, const LidarSimOptions& o,
                                      drivers::PcapWriter& pcap) {
  std::vector<BeamTrig> beams;
  for (const Beam& b : sensor.beams) {
    beams.push_back({std::cos(b.elevation_rad), std::sin(b.elevation_rad), b.azimuth_offset_rad, b.vert_offset_m,
                     b.horiz_offset_m, b.lens_offset_m});
  }
  const auto packets = static_cast<std::uint64_t>(body.duration() * 1e9 / static_cast<double>(sensor.packet_period_ns));
  const double turn_per_s = 2.0 * std::numbers::pi * o.rpm / 60.0;  // rad/s, clockwise seen from above
  const auto head = [&](double t) { return std::fmod(t * turn_per_s, 2.0 * std::numbers::pi); };
  const std::size_t channels = sensor.channels;
  const std::size_t firings = sensor.blocks * channels;
  const Eigen::Isometry3d mount = o.extrinsics * sensor.lidar_to_sensor;  // the beams' frame in the body

  // One packet, a pure function of its index.
  const auto simulate_packet = [&](std::uint64_t k, SpinningPacket& packet, std::uint64_t& returns) {
    const std::int64_t packet_ns = static_cast<std::int64_t>(k) * sensor.packet_period_ns;
    packet.index = k;
    packet.time_ns = o.start_time_ns + packet_ns;
    double block_head = 0.0;
    // The sensor pose at a block's first and last firing; each firing's pose is
    // interpolated between them. Within a block (≤ 111 µs) that is the
    // trajectory's own interpolation to ~1e-8 (rotation below 0.01 rad), at a
    // fraction of the cost of evaluating it per ray.
    Eigen::Isometry3d pose0 = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d pose1 = Eigen::Isometry3d::Identity();
    double t0 = 0.0, t_span = 1.0;
    for (std::size_t i = 0; i < firings; ++i) {
      const double t = static_cast<double>(packet_ns + sensor.firing_ns[i]) * 1e-9;
      if (i % channels == 0) {
        block_head = head(t);
        packet.azimuth[i / channels] =
            static_cast<std::uint16_t>(std::lround(block_head * 18000.0 / std::numbers::pi) % 36000);
        const auto first = sensor.firing_ns.begin() + static_cast<std::ptrdiff_t>(i);
        const std::int64_t last_ns = *std::max_element(first, first + static_cast<std::ptrdiff_t>(channels));
        t0 = t;
        const double t1 = static_cast<double>(packet_ns + last_ns) * 1e-9;
        t_span = std::max(t1 - t0, 1e-12);
        pose0 = body.pose(t0) * mount;
        pose1 = body.pose(t1) * mount;
      }
      const double a = sensor.block_azimuth ? block_head : head(t);
      packet.range_m[i] = 0.0;
      packet.reflectivity[i] = 0;
      const BeamTrig& b = beams[sensor.beam[i]];
      const double theta = a + b.offset;
      const double ct = std::cos(theta), st = std::sin(theta);
      const double ca = b.offset == 0.0 ? ct : std::cos(a), sa = b.offset == 0.0 ? st : std::sin(a);
      const Eigen::Vector3d direction(b.cos_v * ct, -b.cos_v * st, b.sin_v);
      const Eigen::Vector3d offset(-b.vo * b.sin_v * ct + b.ho * st + b.rx * ca,
                                   b.vo * b.sin_v * st + b.ho * ct - b.rx * sa, b.vo * b.cos_v);
      const double f = (t - t0) / t_span;
      const Eigen::Matrix3d rotation = pose0.linear() + f * (pose1.linear() - pose0.linear());
      const Eigen::Vector3d translation = pose0.translation() + f * (pose1.translation() - pose0.translation());
      const Eigen::Vector3f origin = (rotation * offset + translation).cast<float>();
      const Eigen::Vector3f dir = (rotation * direction).cast<float>();
      const auto far = static_cast<float>(o.effects.max_range_m + 1.0);
      Hit hit = caster.intersect(origin, dir, 0.0F, far);
      if (!people.empty()) {
        const Hit person = people.intersect(origin, dir, 0.0F, hit.valid() ? hit.distance : far, t);
        if (person.valid()) hit = person;
      }
      const Return r = measure(o.effects, o.seed, k * firings + i, hit, origin, dir, mesh, targets);
      if (!r.valid || r.range_m > sensor.max_range_m) continue;
      packet.range_m[i] = r.range_m;
      packet.reflectivity[i] = r.reflectivity;
      ++returns;
    }
  };

  LidarSimStats stats;
  const int threads = std::max(1, o.threads);
  std::vector<SpinningPacket> buffer(kChunk);
  std::vector<std::uint8_t> bytes(sensor.packet_size);
  std::vector<std::uint64_t> returns(static_cast<std::size_t>(threads));
  drivers::UdpEndpoints endpoints;
  endpoints.src_port = sensor.port;
  endpoints.dst_port = sensor.port;
  const std::int64_t last_firing =
      *std::max_element(sensor.firing_ns.begin(), sensor.firing_ns.begin() + static_cast<std::ptrdiff_t>(firings));
  for (std::uint64_t first = 0; first < packets; first += kChunk) {
    const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, packets - first));
    {
      // Interleaved packets per thread; each packet depends only on its index.
      std::vector<std::jthread> workers;
      for (int w = 0; w < threads; ++w) {
        workers.emplace_back([&, w] {
          for (auto i = static_cast<std::size_t>(w); i < n; i += static_cast<std::size_t>(threads)) {
            simulate_packet(first + i, buffer[i], returns[static_cast<std::size_t>(w)]);
          }
        });
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      sensor.encode(buffer[i], bytes);
      pcap.write_udp(buffer[i].time_ns + last_firing + std::llround(o.capture_latency_s * 1e9), endpoints, bytes);
    }
    stats.packets += n;
  }
  stats.rays = stats.packets * firings;
  for (const std::uint64_t r : returns) stats.returns += r;
  return stats;
}

}  // namespace adit::sim
