#pragma once
// A spinning multi-beam LiDAR, simulated firing by firing: each beam is cast
// at its own firing time (the decoders' own firing-timing tables) from the
// sensor pose at that instant, at the azimuth the head has turned to, so the
// points carry motion distortion exactly as the real sensor's do. The returns
// are written as the model's data packets (the drivers' encoders) in a pcap at
// the model's packet rate. The model-specific part is a SpinningSensor value
// (velodyne_sensor.cpp, robosense_sensor.cpp, hesai_sensor.cpp,
// ouster_sensor.cpp). A "block" is what shares one azimuth field: a Velodyne,
// RoboSense or Hesai data block of 32 channels, or an Ouster column of 64 pixels.

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "adit/drivers/pcap_writer.hpp"
#include "adit/sim/mesh.hpp"
#include "adit/sim/people.hpp"
#include "adit/sim/ray_caster.hpp"
#include "adit/sim/sensor_effects.hpp"
#include "adit/sim/targets.hpp"
#include "adit/sim/body_track.hpp"

namespace adit::sim {

inline constexpr std::size_t kBlocks = 16;     // at most per packet (Velodyne, RoboSense: 12; XT32: 8; Ouster: 16)
inline constexpr std::size_t kChannels = 64;   // at most per block (Velodyne, RoboSense, Hesai: 32; OS1-64: 64)
inline constexpr std::size_t kFirings = kBlocks * kChannels;

// One beam's geometry as the decoders model it. With a the head azimuth
// (clockwise seen from above, as the sensors count it) and θ = a + azimuth
// offset, the point at range r is
//   r (cos v cos θ, −cos v sin θ, sin v)                                 the beam
//   + vo (−sin v cos θ, sin v sin θ, cos v) + ho (sin θ, cos θ, 0)       Velodyne's offsets
//   + rx (cos a, −sin a, 0)                                              RoboSense's lens offset,
//                                                                        Ouster's beam origin
struct Beam {
  double elevation_rad = 0.0;
  double azimuth_offset_rad = 0.0;
  double vert_offset_m = 0.0;
  double horiz_offset_m = 0.0;
  double lens_offset_m = 0.0;
};

struct SpinningPacket {
  std::uint64_t index = 0;                    // packets since the start
  std::int64_t time_ns = 0;                   // Unix time of the packet's first firing
  std::array<std::uint16_t, kBlocks> azimuth{};  // 0.01° at each block's first firing
  std::array<double, kFirings> range_m{};     // block-major (block × channels + channel); 0: no return
  std::array<std::uint8_t, kFirings> reflectivity{};
};

struct SpinningSensor {
  std::string model;                       // as configs name it, e.g. "VLP-16"
  std::uint16_t port = 0;                  // UDP destination port of data packets
  std::size_t packet_size = 0;
  std::int64_t packet_period_ns = 0;
  std::size_t blocks = 12;                 // per packet
  std::size_t channels = 32;               // per block
  // Every channel of a block cast at the block's azimuth, as the model's point
  // formula has it (Hesai); otherwise each at the head's azimuth at its firing.
  bool block_azimuth = false;
  std::array<std::int64_t, kFirings> firing_ns{};  // after the packet's first firing, block-major
  std::array<std::uint16_t, kFirings> beam{};      // which Beam fires in each slot
  std::vector<Beam> beams;
  // The beams' frame in the sensor frame the decoder reports points in
  // (Ouster: lidar_to_sensor_transform, in metres); identity for the others.
  Eigen::Isometry3d lidar_to_sensor = Eigen::Isometry3d::Identity();
  double fixed_rpm = 0.0;                  // > 0: the model turns at exactly this rate (Ouster 1024x10: 600)
  double max_range_m = 0.0;                // the range field's limit
  std::function<void(const SpinningPacket&, std::span<std::uint8_t>)> encode;
  std::string calibration_file;            // written next to the pcap, e.g. "VLP16.yaml"
  std::string calibration_text;
};

// "VLP-16", "RS-16", "PandarXT32" or "OS1-64" (names as the configs and the
// drivers' registry accept them); throws adit::InputError (key --sensor) otherwise.
SpinningSensor make_spinning_sensor(std::string_view model);
SpinningSensor velodyne_vlp16_sensor();
SpinningSensor robosense_rs16_sensor();
SpinningSensor hesai_xt32_sensor();
SpinningSensor ouster_os1_64_sensor();

struct LidarSimOptions {
  SensorEffects effects;
  double rpm = 600.0;
  std::uint64_t seed = 0;
  std::int64_t start_time_ns = 0;   // Unix time of t = 0 on the common clock
  double capture_latency_s = 1e-4;  // capture time after the packet's last firing
  Eigen::Isometry3d extrinsics = Eigen::Isometry3d::Identity();  // sensor in the body frame
  int threads = 2;                  // outputs do not depend on it
};

// `before_packet`, when given, is called with each data packet's capture time
// (Unix ns) just before the packet is written: the caller writes what it has
// captured until then (the Ouster's IMU packets), so the pcap stays in time order.
struct LidarSimStats {
  std::uint64_t packets = 0;
  std::uint64_t rays = 0;
  std::uint64_t returns = 0;
};

LidarSimStats simulate_spinning_lidar(const SpinningSensor& sensor, const BodyTrack& body, const RayCaster& caster,
                                      const TriangleMesh& mesh, std::span<const Target> targets,
                                      const People& people, const LidarSimOptions& options,
                                      drivers::PcapWriter& pcap,
                                      const std::function<void(std::int64_t)>& before_packet = {});

}  // namespace adit::sim
