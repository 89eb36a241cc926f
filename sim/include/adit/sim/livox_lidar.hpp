#pragma once
// A Livox Mid-360 in the simulator: a non-repetitive scan pattern cast ray by
// ray at each point's own time from the sensor pose at that instant, written
// as the Mid-360's SDK2 point packets (the drivers' encoder: 96 cartesian-high
// points per packet, 5 µs apart, to UDP 56301) in the pcap, and the IMU's SDK2
// packets (to 56401) merged in capture order by the caller.
//
// The pattern is a model, not Livox's proprietary scan path: four lasers 90°
// apart in azimuth turn at 10.07 rev/s (5 000 points per laser per turn) while
// each sweeps the Mid-360's vertical field of view (−7° to +52°, the datasheet's)
// sinusoidally at 37.1 Hz, with its own phase; the two rates are incommensurate,
// so the pattern does not repeat and fills the field of view as time goes, as
// the real sensor's does. 200 000 points/s as the datasheet says.

#include <cstdint>
#include <functional>
#include <span>

#include <Eigen/Geometry>

#include "adit/drivers/pcap_writer.hpp"
#include "adit/sim/body_track.hpp"
#include "adit/sim/mesh.hpp"
#include "adit/sim/people.hpp"
#include "adit/sim/ray_caster.hpp"
#include "adit/sim/sensor_effects.hpp"
#include "adit/sim/targets.hpp"

namespace adit::sim {

struct LivoxPattern {
  int lasers = 4;
  double points_per_s = 200'000.0;
  double turn_hz = 10.07;
  double sweep_hz = 37.1;
  double min_elevation_deg = -7.0;
  double max_elevation_deg = 52.0;
  double max_range_m = 70.0;  // the datasheet's at 80 % reflectivity
};

// Direction of point `index` (of the whole stream) in the sensor frame (x forward, y left, z up).
Eigen::Vector3d livox_direction(const LivoxPattern& pattern, std::uint64_t index);

// The Mid-360's IMU in its point-cloud frame (drivers::livox_imu_position_m:
// the user manual's "IMU position", x 11.0, y 23.29, z −44.12 mm, axes parallel).
Eigen::Isometry3d livox_mid360_imu_in_sensor();

struct LivoxSimOptions {
  SensorEffects effects;
  std::uint64_t seed = 0;
  std::int64_t start_time_ns = 0;   // Unix time of t = 0
  double capture_latency_s = 1e-4;  // capture time after the packet's last point
  Eigen::Isometry3d extrinsics = Eigen::Isometry3d::Identity();  // sensor in the body frame
};

struct LivoxSimStats {
  std::uint64_t packets = 0;
  std::uint64_t rays = 0;
  std::uint64_t returns = 0;
};

// `before_packet`, when given, is called with each point packet's capture
// time just before it is written (the caller writes the IMU packets due by then).
LivoxSimStats simulate_livox_lidar(const LivoxPattern& pattern, const BodyTrack& body, const RayCaster& caster,
                                   const TriangleMesh& mesh, std::span<const Target> targets, const People& people,
                                   const LivoxSimOptions& options, drivers::PcapWriter& pcap,
                                   const std::function<void(std::int64_t)>& before_packet = {});

}  // namespace adit::sim
