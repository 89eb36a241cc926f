#pragma once
// Livox Mid-360 (SDK2 protocol) and Avia (SDK1 protocol): non-repetitive
// scanning LiDARs with per-point times and a built-in IMU (layouts:
// livox_packet.hpp).
//
// They do not spin, so scans are cut by time window, not azimuth: the decoder
// gives each point, as its `azimuth_deg`, the phase of its firing time within
// the frame period (360° × (t mod period) / period), and the ScanAssembler
// cuts where that phase wraps, i.e. at every multiple of the period on the
// sensor clock (the livox_ros_driver2's publish frequency, 10 Hz by default).
// Rings are the point's index modulo the model's line count, as the Livox
// ROS drivers number them (Mid-360 4, Avia 6). IMU packets decode as
// `auxiliary`; last_imu() holds their reading.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "adit/drivers/lidar/decoder.hpp"
#include "adit/drivers/lidar/livox_packet.hpp"

namespace adit::drivers {

enum class LivoxModel : std::uint8_t { mid360, avia };

// "Mid-360"/"MID360"/"Mid360", "Avia" (case-insensitive).
std::optional<LivoxModel> livox_model_from_name(std::string_view name);
std::string_view livox_model_name(LivoxModel model);
LivoxProtocol livox_protocol(LivoxModel model);
std::uint16_t livox_lines(LivoxModel model);
// SDK1 firing period of one record (Avia 4167 ns); SDK2 packets state theirs.
std::uint32_t livox_record_period_ns(LivoxModel model);
// The host port the model's IMU packets go to: the Mid-360's own, 56401
// (livox_ros_driver2 MID360_config.json); 0 for the Avia, whose IMU packets
// come on the data port among its points.
std::uint16_t livox_imu_port(LivoxModel model);
// The built-in IMU's origin in the point frame, metres; its axes are the
// points' (both manuals). Mid-360: (11.0, 23.29, −44.12) mm (Mid-360 user
// manual, "IMU position"). Avia: (−41.65, −23.26, 28.4) mm, the opposite of
// the LiDAR-in-IMU translation FAST-LIO's config/avia.yaml (extrinsic_T) and
// FAST-LIVO's use for it (their mid360.yaml holds the same opposite of the Mid-360's figure).
std::array<double, 3> livox_imu_position_m(LivoxModel model);
// The model whose point or IMU packet this is (protocol header checked against the size), else nullopt.
// SDK2 packets are taken for a Mid-360, SDK1 packets for an Avia (their siblings share the formats).
std::optional<LivoxModel> livox_model_from_packet(std::span<const std::uint8_t> payload);
// Time between point packets like `payload`, 0 when unknown.
std::int64_t livox_packet_period_ns(LivoxModel model, std::span<const std::uint8_t> payload);

struct LivoxDecoderConfig {
  std::int64_t frame_period_ns = 100'000'000;  // scans cut every 100 ms of sensor time
  float min_range_m = 0.1F;   // closer points (the Mid-360's blind zone) are dropped
  float max_range_m = 500.0F;
};

class LivoxDecoder final : public LidarDecoder {
 public:
  explicit LivoxDecoder(LivoxModel model, LivoxDecoderConfig config = {});

  std::string_view model() const override { return livox_model_name(model_); }
  std::uint16_t default_port() const override;
  std::size_t max_points_per_packet() const override { return points_.size(); }
  std::uint64_t sequence_modulus() const override { return 65536; }  // SDK2 udp_cnt
  DecodedPacket decode(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) override;

  // The last IMU packet's reading (nullopt before the first).
  const std::optional<LivoxImuReading>& last_imu() const { return imu_; }

 private:
  LivoxModel model_;
  LivoxProtocol protocol_;
  LivoxDecoderConfig config_;
  std::uint16_t lines_;
  std::uint32_t record_period_ns_;
  std::vector<float> sin_, cos_;  // per 0.01° (spherical formats)
  std::vector<DecodedPoint> points_;
  std::optional<LivoxImuReading> imu_;
};

// Factory for the registry: Livox packets carry Cartesian points, no calibration is needed
// (a calibration path, when given, is not read).
std::unique_ptr<LidarDecoder> make_livox_decoder(std::string_view model);

}  // namespace adit::drivers
