#pragma once
// A spinning Velodyne, simulated firing by firing: each laser is cast at its
// own firing time (the decoder's firing-timing table, velodyne_firing) from
// the sensor pose at that instant, at the azimuth the head has turned to, so
// the points carry motion distortion exactly as the real sensor's do. The
// returns are written as data packets (encode_velodyne_packet) in a pcap at
// the model's packet rate.

#include <cstdint>
#include <span>

#include <Eigen/Geometry>

#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/sim/mesh.hpp"
#include "adit/sim/ray_caster.hpp"
#include "adit/sim/sensor_effects.hpp"
#include "adit/sim/targets.hpp"
#include "adit/sim/trajectory.hpp"

namespace adit::sim {

struct LidarSimOptions {
  SensorEffects effects;
  double rpm = 600.0;                 // head rotation (the VLP-16 allows 300-1200)
  std::uint64_t seed = 0;
  std::int64_t start_time_ns = 0;     // Unix time of t = 0 on the common clock
  double capture_latency_s = 1e-4;    // packet timestamp in the capture after its last firing
  Eigen::Isometry3d extrinsics = Eigen::Isometry3d::Identity();  // sensor in the body frame
  int threads = 2;                    // outputs do not depend on it
};

struct LidarSimStats {
  std::uint64_t packets = 0;
  std::uint64_t rays = 0;
  std::uint64_t returns = 0;
};

LidarSimStats simulate_velodyne(drivers::VelodyneModel model, const drivers::VelodyneCalibration& calibration,
                                const Trajectory& body, const RayCaster& caster, const TriangleMesh& mesh,
                                std::span<const Target> targets, const LidarSimOptions& options,
                                drivers::PcapWriter& pcap);

}  // namespace adit::sim
