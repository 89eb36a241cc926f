#include "adit/sim/spinning_lidar.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numbers>
#include <numeric>
#include <thread>

#include "adit/common/error.hpp"

namespace adit::sim {
namespace {

constexpr std::size_t kChunk = 256;  // packets simulated between writes

struct BeamTrig {  // Beam with the sines and cosines of its angles
  double cos_v, sin_v, cos_offset, sin_offset, vo, ho, rx;
};

}  // namespace

SpinningSensor make_spinning_sensor(std::string_view model) {
  if (model == "VLP-16") return velodyne_vlp16_sensor();
  if (model == "RS-16") return robosense_rs16_sensor();
  if (model == "PandarXT32") return hesai_xt32_sensor();
  if (model == "OS1-64") return ouster_os1_64_sensor();
  throw InputError("adit sim", "--sensor",
                   "unsupported sensor '" + std::string(model) + "' (VLP-16, RS-16, PandarXT32, OS1-64, Mid-360)");
}

LidarSimStats simulate_spinning_lidar(const SpinningSensor& sensor, const BodyTrack& body, const RayCaster& caster,
                                      const TriangleMesh& mesh, std::span<const Target> targets,
                                      const People& people, const LidarSimOptions& o,
                                      drivers::PcapWriter& pcap,
                                      const std::function<void(std::int64_t)>& before_packet) {
  std::vector<BeamTrig> beams;
  for (const Beam& b : sensor.beams) {
    beams.push_back({std::cos(b.elevation_rad), std::sin(b.elevation_rad), std::cos(b.azimuth_offset_rad),
                     std::sin(b.azimuth_offset_rad), b.vert_offset_m, b.horiz_offset_m, b.lens_offset_m});
  }
  const auto packets = static_cast<std::uint64_t>(body.duration() * 1e9 / static_cast<double>(sensor.packet_period_ns));
  const double turn_per_s = 2.0 * std::numbers::pi * o.rpm / 60.0;  // rad/s, clockwise seen from above
  const auto head = [&](double t) { return std::fmod(t * turn_per_s, 2.0 * std::numbers::pi); };
  const std::size_t channels = sensor.channels;
  const std::size_t firings = sensor.blocks * channels;
  const Eigen::Isometry3d mount = o.extrinsics * sensor.lidar_to_sensor;  // the beams' frame in the body
  // How far the head turns from a block's first firing to each firing (none
  // when the model casts a block at one azimuth), as a cosine and sine: the
  // angle of a firing is the block's turned by it, with no trigonometry per ray.
  std::vector<double> cos_turn(firings, 1.0), sin_turn(firings, 0.0);
  for (std::size_t i = 0; i < firings && !sensor.block_azimuth; ++i) {
    const std::size_t first = i - i % channels;
    const double turn = static_cast<double>(sensor.firing_ns[i] - sensor.firing_ns[first]) * 1e-9 * turn_per_s;
    cos_turn[i] = std::cos(turn);
    sin_turn[i] = std::sin(turn);
  }

  const auto far = static_cast<float>(o.effects.max_range_m + 1.0);
  const SensorNoise noise(o.seed);
  const auto firing_time = [&](std::int64_t packet_ns, std::size_t i) {
    return static_cast<double>(packet_ns + sensor.firing_ns[i]) * 1e-9;
  };

  // The order the rays of a packet are cast in: beam by beam, each beam's
  // firings in time order, so that an Embree ray packet holds one beam's
  // successive firings, a fraction of a degree apart: coherent rays, which
  // traverse the BVH together far faster than a firing's fan of beams.
  std::vector<std::uint16_t> cast_order(firings);
  std::iota(cast_order.begin(), cast_order.end(), std::uint16_t{0});
  std::stable_sort(cast_order.begin(), cast_order.end(),
                   [&](std::uint16_t x, std::uint16_t y) { return sensor.beam[x] < sensor.beam[y]; });

  // Rays, hits and returns of one packet: per thread, reused.
  struct Scratch {
    std::array<Eigen::Vector3f, kFirings> origins, directions;          // in firing order
    std::array<Eigen::Vector3f, kFirings> cast_origins, cast_directions;  // in cast order
    std::array<Hit, kFirings> hits;                                     // in cast order
  };

  // One packet, a pure function of its index: every firing's ray, all of
  // them cast as ray packets, then each one's return.
  const auto simulate_packet = [&](std::uint64_t k, SpinningPacket& packet, Scratch& s, std::uint64_t& returns) {
    const std::int64_t packet_ns = static_cast<std::int64_t>(k) * sensor.packet_period_ns;
    packet.index = k;
    packet.time_ns = o.start_time_ns + packet_ns;
    for (std::size_t block = 0; block < sensor.blocks; ++block) {
      const std::size_t first = block * channels;
      // The sensor pose at the block's first and last firing; each firing's
      // pose is interpolated between them. Within a block (≤ 111 µs) that is
      // the trajectory's own interpolation to ~1e-8 (rotation below 0.01 rad),
      // at a fraction of the cost of evaluating it per ray.
      const double t0 = firing_time(packet_ns, first);
      const double block_head = head(t0);
      packet.azimuth[block] = static_cast<std::uint16_t>(std::lround(block_head * 18000.0 / std::numbers::pi) % 36000);
      const auto block_ns = sensor.firing_ns.begin() + static_cast<std::ptrdiff_t>(first);
      const std::int64_t last_ns = *std::max_element(block_ns, block_ns + static_cast<std::ptrdiff_t>(channels));
      const double t1 = static_cast<double>(packet_ns + last_ns) * 1e-9;
      const double t_span = std::max(t1 - t0, 1e-12);
      const Eigen::Isometry3d pose0 = body.pose(t0) * mount;
      const Eigen::Isometry3d pose1 = body.pose(t1) * mount;
      const Eigen::Matrix3d turn = pose1.linear() - pose0.linear();
      const Eigen::Vector3d move = pose1.translation() - pose0.translation();
      const double cos_block = std::cos(block_head), sin_block = std::sin(block_head);
      for (std::size_t i = first; i < first + channels; ++i) {
        const double t = firing_time(packet_ns, i);
        const BeamTrig& b = beams[sensor.beam[i]];
        // a = the head's azimuth at this firing, θ = a + the beam's azimuth offset.
        const double ca = cos_block * cos_turn[i] - sin_block * sin_turn[i];
        const double sa = sin_block * cos_turn[i] + cos_block * sin_turn[i];
        const double ct = ca * b.cos_offset - sa * b.sin_offset, st = sa * b.cos_offset + ca * b.sin_offset;
        const Eigen::Vector3d direction(b.cos_v * ct, -b.cos_v * st, b.sin_v);
        const Eigen::Vector3d offset(-b.vo * b.sin_v * ct + b.ho * st + b.rx * ca,
                                     b.vo * b.sin_v * st + b.ho * ct - b.rx * sa, b.vo * b.cos_v);
        const double f = (t - t0) / t_span;
        const Eigen::Matrix3d rotation = pose0.linear() + f * turn;
        const Eigen::Vector3d translation = pose0.translation() + f * move;
        s.origins[i] = (rotation * offset + translation).cast<float>();
        s.directions[i] = (rotation * direction).cast<float>();
      }
    }
    for (std::size_t j = 0; j < firings; ++j) {
      s.cast_origins[j] = s.origins[cast_order[j]];
      s.cast_directions[j] = s.directions[cast_order[j]];
    }
    caster.intersect({s.cast_origins.data(), firings}, {s.cast_directions.data(), firings}, 0.0F, far,
                     {s.hits.data(), firings});
    for (std::size_t j = 0; j < firings; ++j) {
      const std::size_t i = cast_order[j];
      Hit& hit = s.hits[j];
      if (!people.empty()) {
        const Hit person = people.intersect(s.origins[i], s.directions[i], 0.0F, hit.valid() ? hit.distance : far,
                                            firing_time(packet_ns, i));
        if (person.valid()) hit = person;
      }
      const Return r = measure(o.effects, noise, k * firings + i, hit, s.origins[i], s.directions[i], mesh, targets);
      const bool kept = r.valid && r.range_m <= sensor.max_range_m;
      packet.range_m[i] = kept ? r.range_m : 0.0;
      packet.reflectivity[i] = kept ? r.reflectivity : 0;
      returns += kept ? 1 : 0;
    }
  };

  LidarSimStats stats;
  const auto threads = static_cast<std::size_t>(std::max(1, o.threads));
  std::vector<Scratch> scratch(threads);
  std::vector<std::uint64_t> returns(threads);
  std::vector<std::uint8_t> bytes(sensor.packet_size);
  drivers::UdpEndpoints endpoints;
  endpoints.src_port = sensor.port;
  endpoints.dst_port = sensor.port;
  const std::int64_t last_firing =
      *std::max_element(sensor.firing_ns.begin(), sensor.firing_ns.begin() + static_cast<std::ptrdiff_t>(firings));
  const auto write = [&](const std::vector<SpinningPacket>& chunk, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      sensor.encode(chunk[i], bytes);
      const std::int64_t capture_ns = chunk[i].time_ns + last_firing + std::llround(o.capture_latency_s * 1e9);
      if (before_packet) before_packet(capture_ns);
      pcap.write_udp(capture_ns, endpoints, bytes);
    }
    stats.packets += n;
  };
  // Two chunks: the workers simulate one while this thread encodes and writes
  // the other. Workers take the next packet as they come free (a busy core
  // does not hold the others up); each packet depends only on its index, so
  // the output does not depend on who simulated it.
  std::array<std::vector<SpinningPacket>, 2> chunks{std::vector<SpinningPacket>(kChunk),
                                                    std::vector<SpinningPacket>(kChunk)};
  std::size_t written_chunk = 0;
  std::size_t pending = 0;  // packets simulated into chunks[written_chunk], not written yet
  for (std::uint64_t first = 0, c = 0; first < packets; first += kChunk, ++c) {
    const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, packets - first));
    std::vector<SpinningPacket>& chunk = chunks[c % 2];
    std::atomic<std::size_t> next{0};
    {
      std::vector<std::jthread> workers;
      for (std::size_t w = 0; w < threads; ++w) {
        workers.emplace_back([&, w] {
          for (std::size_t i = next++; i < n; i = next++) simulate_packet(first + i, chunk[i], scratch[w], returns[w]);
        });
      }
      write(chunks[written_chunk], pending);
    }
    written_chunk = c % 2;
    pending = n;
  }
  write(chunks[written_chunk], pending);
  stats.rays = stats.packets * firings;
  for (const std::uint64_t r : returns) stats.returns += r;
  return stats;
}

}  // namespace adit::sim
